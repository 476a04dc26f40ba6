/* test_restart.c: a run restarted from a snapshot (-latestTime) ends
 * bit-identical to the same run made in one go.
 *
 * A small dam break (the damBreak2D geometry at l0 = 0.02) goes straight to
 * t = 0.1 s; a second copy goes to 0.05 s, then restarts with -latestTime
 * -endTime 0.1. The final snapshots are compared particle by particle at
 * equal StorageIndex (where the reader puts them): ids, positions,
 * velocities and every stored field must be equal to the bit. Done with a
 * fixed time step and with the adjustable one.
 *
 * argv[1]: the mpsflow executable. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_util.h"
#include "mf_test.h"

#define SPLIT_TIME 0.05
#define END_TIME 0.1

static const char *const control_fixed =
    "endTime 0.1;\nadjustTimeStep no;\ndeltaT 1e-3;\n"
    "writeControl adjustableRunTime;\nwriteInterval 0.05;\n";
static const char *const control_adaptive =
    "endTime 0.1;\nadjustTimeStep yes;\ndeltaT 1e-4;\nmaxCo 0.2;\nmaxDeltaT 1e-3;\n"
    "writeControl adjustableRunTime;\nwriteInterval 0.05;\n";
/* The same with deltaT (the step the adjustable step grows from) set. */
static const char *const control_adaptive_seeded =
    "endTime 0.1;\nadjustTimeStep yes;\ndeltaT %.17g;\nmaxCo 0.2;\nmaxDeltaT 1e-3;\n"
    "writeControl adjustableRunTime;\nwriteInterval 0.05;\n";

/* The damBreak2D tutorial's scheme. */
static const char *const solver =
    "solver MPS;\n"
    "MPSCoeffs { relaxation 0.2; collision yes; }\n"
    "pressure { solver PCG_BoomerAMG; tolerance 1e-8; }\n"
    "forces { gravity { g (0 -9.81 0); } }\n";
static const char *const fluids = "water { rho 1000; nu 1e-6; }\n";
/* damBreak2D (a = 0.25 m, column 2a high, tank 2 m long), at l0 = 0.02. */
static const char *const geometry =
    "dimension 2;\nparticleSpacing 0.02;\n"
    "fluidBlocks { column { type box; min (0 0 0); max (0.25 0.5 0); fluid water; } }\n"
    "walls { tank { type box; min (0 0 0); max (2.0 0.6 0); open (ymax); "
    "wallLayers 1; dummyLayers 2; } }\n";

/* The steps a log shows: "deltaT = x" then "Time = t" (t at the end of the step). */
typedef struct step_log {
    double dt[4096], t_end[4096];
    size_t n;
    size_t restart_at; /* first step after "Restarting from time" (n if none) */
} step_log;

static void read_steps(const tc_case *c, step_log *s)
{
    char path[700], line[512];
    snprintf(path, sizeof path, "%s/log", c->dir);
    s->n = 0;
    s->restart_at = (size_t)-1;
    FILE *f = fopen(path, "r");
    double dt = NAN;
    while (f && fgets(line, sizeof line, f)) {
        if (strncmp(line, "Restarting from time", 20) == 0)
            s->restart_at = s->n;
        else if (sscanf(line, "deltaT = %lf", &dt) == 1)
            continue;
        else if (strncmp(line, "Time = ", 7) == 0 && s->n < 4096) {
            s->dt[s->n] = dt;
            s->t_end[s->n] = strtod(line + 7, NULL);
            s->n++;
        }
    }
    if (f)
        fclose(f);
    if (s->restart_at == (size_t)-1)
        s->restart_at = s->n;
}

/* Compare two snapshots slot by slot; print what differs. Returns the
 * number of differing arrays. */
static int compare(const mf_particles *a, const mf_particles *b, const char *label)
{
    int differing = 0;
    if (a->n != b->n) {
        printf("restart %s: %zu particles against %zu\n", label, a->n, b->n);
        return 1;
    }
    size_t n = a->n, ids = 0, pos = 0, vel = 0;
    double dpos = 0, dvel = 0;
    for (size_t i = 0; i < n; i++) {
        ids += a->id[i] != b->id[i] || a->kind[i] != b->kind[i];
        if (memcmp(&a->pos[3 * i], &b->pos[3 * i], 3 * sizeof(double)) != 0)
            pos++;
        if (memcmp(&a->vel[3 * i], &b->vel[3 * i], 3 * sizeof(double)) != 0)
            vel++;
        for (int c = 0; c < 3; c++) {
            dpos = fmax(dpos, fabs(a->pos[3 * i + c] - b->pos[3 * i + c]));
            dvel = fmax(dvel, fabs(a->vel[3 * i + c] - b->vel[3 * i + c]));
        }
    }
    printf("restart %s: %zu particles; differing: ids %zu, positions %zu (max %.3g m), "
           "velocities %zu (max %.3g m/s)",
           label, n, ids, pos, dpos, vel, dvel);
    differing += (ids > 0) + (pos > 0) + (vel > 0);
    for (int f = 0; f < a->nfields; f++) {
        const mf_field *fa = &a->field[f];
        int g = mf_particles_field_index(b, fa->name);
        if (g < 0) {
            printf(", %s missing", fa->name);
            differing++;
            continue;
        }
        const mf_field *fb = &b->field[g];
        size_t elem = fa->type == MF_FIELD_DOUBLE ? sizeof(double) : sizeof(int32_t);
        size_t count = 0;
        for (size_t i = 0; i < n; i++)
            count += memcmp((const char *)fa->data + i * fa->ncomp * elem,
                            (const char *)fb->data + i * fb->ncomp * elem, fa->ncomp * elem) != 0;
        printf(", %s %zu", fa->name, count);
        differing += count > 0;
    }
    printf("\n");
    if (ids > 0) {
        /* Storage orders parted (particles are re-sorted along cells every few steps):
         * the same particles, matched by id. */
        int64_t max_id = 0;
        for (size_t i = 0; i < n; i++)
            max_id = a->id[i] > max_id ? a->id[i] : max_id;
        long *where = malloc((size_t)(max_id + 1) * sizeof *where);
        double dp = 0, dv = 0;
        size_t unmatched = 0;
        for (int64_t k = 0; where && k <= max_id; k++)
            where[k] = -1;
        for (size_t i = 0; where && i < n; i++)
            where[a->id[i]] = (long)i;
        for (size_t i = 0; where && i < n; i++) {
            long j = b->id[i] >= 0 && b->id[i] <= max_id ? where[b->id[i]] : -1;
            if (j < 0) {
                unmatched++;
                continue;
            }
            for (int c = 0; c < 3; c++) {
                dp = fmax(dp, fabs(b->pos[3 * i + c] - a->pos[3 * j + c]));
                dv = fmax(dv, fabs(b->vel[3 * i + c] - a->vel[3 * j + c]));
            }
        }
        printf("restart %s: matched by id: max position difference %.3g m, velocity %.3g m/s, "
               "%zu ids unmatched\n",
               label, dp, dv, unmatched);
        free(where);
    }
    return differing;
}

static bool final_snapshot(const tc_case *c, mf_sim *sim, mf_hdf5_header *h)
{
    tc_snapshots s;
    if (tc_snapshots_list(c->dir, &s) != 0 || s.n == 0) {
        tc_snapshots_free(&s);
        return false;
    }
    int rc = tc_snapshot_load(c->dir, s.index[s.n - 1], sim, h);
    tc_snapshots_free(&s);
    return rc == 0;
}

/* Run a case to the split time, then restart it (-latestTime) to the end.
 * restart_control, if not NULL, replaces the controlDict before the restart. */
static bool split_run(tc_case *c, const char *exe, const char *tag, const char *control,
                      const char *restart_control)
{
    if (tc_case_from_strings(c, exe, tag, control, solver, fluids, geometry) != 0) {
        CHECK(!"case created");
        return false;
    }
    char split_time[32], end_time[32];
    snprintf(split_time, sizeof split_time, "%.17g", SPLIT_TIME);
    snprintf(end_time, sizeof end_time, "%.17g", END_TIME);
    int s1 = tc_case_run(c, NULL, (const char *const[]){"-endTime", split_time, NULL});
    if (s1 == 0 && restart_control)
        CHECK_OK(tc_case_write(c, TC_CONTROL, restart_control));
    int s2 = s1 == 0 ? tc_case_run(c, NULL, (const char *const[]){"-latestTime", "-endTime",
                                                                   end_time, NULL})
                     : -1;
    CHECK_MSG(s1 == 0 && s2 == 0, "%s: exit statuses %d, %d", tag, s1, s2);
    CHECK(tc_case_log_contains(c, "Restarting from time"));
    if (s1 != 0 || s2 != 0) {
        tc_case_log_tail(c, 20);
        return false;
    }
    return true;
}

/* The end time the final snapshots must show. */
static double expected_end = END_TIME;

/* Compare the final snapshots of two runs; true if bit-identical. */
static bool same_end(const tc_case *x, const tc_case *y, const char *label)
{
    mf_sim a, b;
    mf_hdf5_header ha, hb;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    bool same = false;
    if (final_snapshot(x, &a, &ha) && final_snapshot(y, &b, &hb)) {
        printf("restart %s: one run ends at t = %.17g (step %ld), the restarted one at t = %.17g "
               "(step %ld)\n",
               label, ha.time, ha.step, hb.time, hb.step);
        CHECK_NEAR(ha.time, expected_end, 1e-9);
        int differing = compare(a.p, b.p, label);
        same = differing == 0 && ha.time == hb.time && ha.step == hb.step;
    } else {
        CHECK(!"final snapshots readable");
    }
    tc_sim_free(&a);
    tc_sim_free(&b);
    return same;
}

/* Where the runs part: the time steps after the split, from the logs. Returns the
 * straight run's first step after the split. */
static double explain(const tc_case *whole, const tc_case *split, const char *label)
{
    step_log *la = malloc(sizeof *la), *lb = malloc(sizeof *lb);
    double first_after = NAN;
    if (la && lb) {
        read_steps(whole, la);
        read_steps(split, lb);
        size_t ka = 0;
        while (ka < la->n && la->t_end[ka] <= SPLIT_TIME * (1 + 1e-9))
            ka++;
        printf("restart %s: deltaT of the steps after t = %g (from the logs):\n", label,
               SPLIT_TIME);
        for (size_t k = 0; k < 4; k++)
            printf("    straight run %-12.6g restarted run %-12.6g\n",
                   ka + k < la->n ? la->dt[ka + k] : NAN,
                   lb->restart_at + k < lb->n ? lb->dt[lb->restart_at + k] : NAN);
        char path[800];
        tc_snapshot_path(split->dir, 1, path, sizeof path);
        mf_hdf5_header hs;
        memset(&hs, 0, sizeof hs);
        if (mf_hdf5_read_header(path, &hs) != 0)
            mf_error_clear();
        printf("restart %s: the straight run's last steps before t = %g: %.6g, %.6g, %.6g; "
               "the snapshot there stores TimeStep %.6g\n",
               label, SPLIT_TIME, ka > 2 ? la->dt[ka - 3] : NAN, ka > 1 ? la->dt[ka - 2] : NAN,
               ka > 0 ? la->dt[ka - 1] : NAN, hs.dt);
        first_after = ka < la->n ? la->dt[ka] : NAN;
    }
    free(la);
    free(lb);
    return first_after;
}

static void run_pair(const char *exe, const char *label, const char *control,
                     const char *control_seeded_fmt)
{
    tc_case whole, split;
    memset(&split, 0, sizeof split);
    if (tc_case_from_strings(&whole, exe, "restart-whole", control, solver, fluids, geometry) !=
        0) {
        CHECK(!"case created");
        tc_case_destroy(&whole);
        return;
    }
    int status = tc_case_run(&whole, NULL, NULL);
    CHECK_MSG(status == 0, "%s: the straight run exited with %d", label, status);
    if (status != 0)
        tc_case_log_tail(&whole, 20);
    if (status == 0 && split_run(&split, exe, "restart-split", control, NULL)) {
        bool same = same_end(&whole, &split, label);
        printf("restart %s: %s\n", label, same ? "bit-identical" : "DIFFERENT");
        CHECK_MSG(same, "%s: the restarted run is not bit-identical to the straight one", label);
        if (!same) {
            double next = explain(&whole, &split, label);
            /* The adjustable step grows from the last natural step (core/run/run.c,
             * natural_dt), which a snapshot does not hold: a restart grows from deltaT
             * again. Seed deltaT with the straight run's step after the split and see
             * whether that was all. */
            if (control_seeded_fmt && isfinite(next)) {
                char seeded[512];
                snprintf(seeded, sizeof seeded, control_seeded_fmt, next);
                tc_case again;
                char what[128];
                snprintf(what, sizeof what, "%s, restart with deltaT %.6g", label, next);
                if (split_run(&again, exe, "restart-seeded", control, seeded))
                    printf("restart %s: %s\n", what,
                           same_end(&whole, &again, what) ? "bit-identical" : "DIFFERENT");
                tc_case_destroy(&again);
            }
        }
    }
    tc_case_destroy(&whole);
    tc_case_destroy(&split);
}

/* From any snapshot: a straight adjustable-dt run to 0.03 s writing every
 * 0.002 s, then restarts from its snapshots at 0.012, 0.018 and 0.024 s (the
 * output folder holding those up to it) and one stopped by -endTime 0.018 and
 * restarted: every one must end bit-identical to the straight run, header
 * included (write times are k x 0.002, not sums of 0.002, and an endTime
 * that is a write time ends on it: issue 16). */
static const char *const control_often =
    "endTime 0.03;\nadjustTimeStep yes;\ndeltaT 1e-4;\nmaxCo 0.2;\nmaxDeltaT 1e-3;\n"
    "writeControl adjustableRunTime;\nwriteInterval 0.002;\n";

static bool same_header(const tc_case *x, const tc_case *y, const char *label)
{
    tc_snapshots sx, sy;
    bool same = false;
    if (tc_snapshots_list(x->dir, &sx) == 0 && tc_snapshots_list(y->dir, &sy) == 0 && sx.n &&
        sy.n) {
        char px[800], py[800];
        tc_snapshot_path(x->dir, sx.index[sx.n - 1], px, sizeof px);
        tc_snapshot_path(y->dir, sy.index[sy.n - 1], py, sizeof py);
        mf_hdf5_header a, b;
        if (mf_hdf5_read_header(px, &a) == 0 && mf_hdf5_read_header(py, &b) == 0)
            same = a.time == b.time && a.step == b.step && a.dt == b.dt &&
                   a.dt_natural == b.dt_natural && a.next_id == b.next_id;
        if (!same)
            printf("restart %s: headers differ (Time %.17g/%.17g, TimeStep %.17g/%.17g, "
                   "NaturalTimeStep %.17g/%.17g)\n",
                   label, a.time, b.time, a.dt, b.dt, a.dt_natural, b.dt_natural);
    }
    tc_snapshots_free(&sx);
    tc_snapshots_free(&sy);
    return same;
}

static void restart_from_any(const char *exe)
{
    expected_end = 0.03;
    tc_case whole;
    if (tc_case_from_strings(&whole, exe, "restart-often", control_often, solver, fluids,
                             geometry) != 0) {
        CHECK(!"case created");
        return;
    }
    int status = tc_case_run(&whole, NULL, NULL);
    CHECK_MSG(status == 0, "the straight run exited with %d", status);
    static const int from[] = {6, 9, 12}; /* snapshot k is at t = 0.002 k */
    for (size_t k = 0; status == 0 && k < sizeof from / sizeof from[0]; k++) {
        tc_case again;
        char label[64], cmd[2000];
        snprintf(label, sizeof label, "from snapshot %d (t = %g)", from[k], 0.002 * from[k]);
        if (tc_case_from_strings(&again, exe, "restart-from", control_often, solver, fluids,
                                 geometry) != 0) {
            CHECK(!"case created");
            continue;
        }
        snprintf(cmd, sizeof cmd, "mkdir -p '%s/output' && for i in $(seq 0 %d); do cp \"%s/output/"
                 "$(printf snapshot_%%06d.h5 $i)\" '%s/output/'; done", again.dir, from[k],
                 whole.dir, again.dir);
        CHECK_MSG(system(cmd) == 0, "%s: snapshots copied", label);
        int s = tc_case_run(&again, NULL, (const char *const[]){"-latestTime", NULL});
        CHECK_MSG(s == 0, "%s: exit status %d", label, s);
        bool same = s == 0 && same_end(&whole, &again, label) && same_header(&whole, &again, label);
        printf("restart %s: %s\n", label, same ? "bit-identical" : "DIFFERENT");
        CHECK_MSG(same, "restart %s is not bit-identical to the straight run", label);
        tc_case_destroy(&again);
    }
    /* Stopped by -endTime at a write time, then restarted. */
    tc_case split;
    if (status == 0 &&
        tc_case_from_strings(&split, exe, "restart-stop", control_often, solver, fluids,
                             geometry) == 0) {
        int s1 = tc_case_run(&split, NULL, (const char *const[]){"-endTime", "0.018", NULL});
        int s2 = s1 == 0 ? tc_case_run(&split, NULL, (const char *const[]){"-latestTime", NULL})
                         : -1;
        CHECK_MSG(s1 == 0 && s2 == 0, "stop at 0.018: exit statuses %d, %d", s1, s2);
        bool same = s2 == 0 && same_end(&whole, &split, "stopped at 0.018") &&
                    same_header(&whole, &split, "stopped at 0.018");
        printf("restart stopped at 0.018 by -endTime: %s\n", same ? "bit-identical" : "DIFFERENT");
        CHECK_MSG(same, "a run stopped at 0.018 and restarted is not bit-identical");
        tc_case_destroy(&split);
    }
    tc_case_destroy(&whole);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s MPSFLOW\n", argv[0]);
        return EXIT_FAILURE;
    }
    run_pair(argv[1], "fixed dt", control_fixed, NULL);
    run_pair(argv[1], "adjustable dt", control_adaptive, control_adaptive_seeded);
    restart_from_any(argv[1]);
    return mf_test_summary("restart");
}
