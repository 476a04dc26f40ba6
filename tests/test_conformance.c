/* test_conformance.c: what every registered solver must do, run through
 * the mpsflow executable with -solver NAME and the solver's defaults (no
 * <NAME>Coeffs dictionary):
 *
 *   (i)   a closed box partly filled, no forces, fixed step: the fluid stays
 *         exactly at rest (|u| < 1e-6 m/s, displacement < 1e-6 l0);
 *   (ii)  the same box under gravity (adjustable step): no particle lost, no
 *         NaN in any field, no fluid particle outside the box;
 *   (iii) the same under gravity with a fixed step: every snapshot's
 *         TimeStep is deltaT and Step * deltaT is its Time.
 *
 * argv[1]: the mpsflow executable. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_util.h"
#include "mf_solvers.h"
#include "mf_test.h"

#define L0 0.01
#define BOX 0.2          /* closed square box, m */
#define FILL 0.6         /* fluid fills the bottom 60% */
#define DT 1e-3          /* the fixed step of (i) and (iii) */
#define REST_STEPS 50
#define GRAVITY_TIME 0.2 /* (ii), s */
#define FIXED_TIME 0.1   /* (iii), s */

static const char *const fluids = "water { rho 1000; nu 1e-6; }\n";

static void geometry_text(char *buf, size_t len)
{
    snprintf(buf, len,
             "dimension 2;\nparticleSpacing %g;\n"
             "fluidBlocks { water { type box; min (0 0 0); max (%g %g 0); fluid water; } }\n"
             "walls { box { type box; min (0 0 0); max (%g %g 0); wallLayers 1; "
             "dummyLayers 2; } }\n",
             L0, BOX, FILL * BOX, BOX, BOX);
}

static void solver_text(char *buf, size_t len, const char *name, bool gravity)
{
    snprintf(buf, len, "solver %s;\n%s", name,
             gravity ? "forces { gravity { g (0 -9.81 0); } }\n" : "");
}

static void control_text(char *buf, size_t len, bool fixed, double end_time,
                         double write_interval)
{
    if (fixed)
        snprintf(buf, len,
                 "endTime %.17g;\nadjustTimeStep no;\ndeltaT %.17g;\nwriteInterval %.17g;\n",
                 end_time, DT, write_interval);
    else
        snprintf(buf, len,
                 "endTime %.17g;\nadjustTimeStep yes;\ndeltaT 1e-4;\nmaxCo 0.2;\nmaxDeltaT "
                 "1e-3;\nwriteInterval %.17g;\n",
                 end_time, write_interval);
}

/* Make and run one case; returns the case (dir set) or an empty dir on failure. */
static bool run_case(tc_case *c, const char *exe, const char *tag, const char *name,
                     bool gravity, bool fixed, double end_time, double write_interval)
{
    char control[512], solver[512], geometry[1024];
    control_text(control, sizeof control, fixed, end_time, write_interval);
    solver_text(solver, sizeof solver, name, gravity);
    geometry_text(geometry, sizeof geometry);
    if (tc_case_from_strings(c, exe, tag, control, solver, fluids, geometry) != 0) {
        CHECK(!"case created");
        return false;
    }
    int status = tc_case_run(c, NULL, (const char *const[]){"-solver", name, "-quiet", NULL});
    CHECK_MSG(status == 0, "solver %s, case %s: mpsflow exited with %d", name, tag, status);
    if (status != 0) {
        tc_case_log_tail(c, 25);
        return false;
    }
    return true;
}

/* Index of each id in a snapshot (ids are small: the scene numbers them from 0). */
static long *index_by_id(const mf_particles *p, int64_t *max_id)
{
    int64_t mx = 0;
    for (size_t i = 0; i < p->n; i++)
        if (p->id[i] > mx)
            mx = p->id[i];
    long *map = malloc((size_t)(mx + 1) * sizeof *map);
    if (!map)
        return NULL;
    for (int64_t k = 0; k <= mx; k++)
        map[k] = -1;
    for (size_t i = 0; i < p->n; i++)
        if (p->id[i] >= 0)
            map[p->id[i]] = (long)i;
    *max_id = mx;
    return map;
}

/* (i): at rest without forces. */
static void check_rest(const char *exe, const char *name, char *summary, size_t len)
{
    tc_case c;
    if (!run_case(&c, exe, "rest", name, false, true, REST_STEPS * DT, 10 * DT)) {
        tc_case_destroy(&c);
        snprintf(summary, len, "rest: run failed");
        return;
    }
    tc_snapshots s;
    CHECK_OK(tc_snapshots_list(c.dir, &s));
    mf_sim first;
    mf_hdf5_header h0;
    double umax = 0, dmax = 0;
    long last_step = 0;
    if (s.n == 0 || tc_snapshot_load(c.dir, s.index[0], &first, &h0) != 0) {
        CHECK(!"first snapshot readable");
        tc_snapshots_free(&s);
        tc_case_destroy(&c);
        return;
    }
    int64_t max_id = 0;
    long *where = index_by_id(first.p, &max_id);
    for (size_t k = 1; where && k < s.n; k++) {
        mf_sim snap;
        mf_hdf5_header h;
        if (tc_snapshot_load(c.dir, s.index[k], &snap, &h) != 0) {
            CHECK(!"snapshot readable");
            continue;
        }
        const mf_particles *p = snap.p;
        CHECK(p->n == first.p->n);
        for (size_t i = 0; i < p->n; i++) {
            long j = p->id[i] >= 0 && p->id[i] <= max_id ? where[p->id[i]] : -1;
            CHECK_MSG(j >= 0, "solver %s: particle id %lld is new", name, (long long)p->id[i]);
            if (j < 0)
                continue;
            const double *v = &p->vel[3 * i];
            double u = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            double d = 0;
            for (int a = 0; a < 3; a++)
                d += (p->pos[3 * i + a] - first.p->pos[3 * j + a]) *
                     (p->pos[3 * i + a] - first.p->pos[3 * j + a]);
            d = sqrt(d) / L0;
            if (!(u <= umax))
                umax = u; /* NaN sticks */
            if (!(d <= dmax))
                dmax = d;
        }
        last_step = h.step;
        tc_sim_free(&snap);
    }
    CHECK_MSG(last_step == REST_STEPS, "solver %s: rest run ended at step %ld, not %d", name,
              last_step, REST_STEPS);
    CHECK_MSG(umax < 1e-6, "solver %s: a fluid particle moves at %g m/s in a box at rest", name,
              umax);
    CHECK_MSG(dmax < 1e-6, "solver %s: a particle moved %g l0 in a box at rest", name, dmax);
    snprintf(summary, len, "rest: %ld steps, max |u| %.3g m/s, max displacement %.3g l0",
             last_step, umax, dmax);
    free(where);
    tc_sim_free(&first);
    tc_snapshots_free(&s);
    tc_case_destroy(&c);
}

static bool all_finite(const mf_particles *p)
{
    for (size_t i = 0; i < 3 * p->n; i++)
        if (!isfinite(p->pos[i]) || !isfinite(p->vel[i]))
            return false;
    for (int f = 0; f < p->nfields; f++) {
        if (p->field[f].type != MF_FIELD_DOUBLE)
            continue;
        const double *x = mf_particles_fd(p, f);
        for (size_t i = 0; i < p->n * (size_t)p->field[f].ncomp; i++)
            if (!isfinite(x[i]))
                return false;
    }
    return true;
}

/* (ii): under gravity, adjustable step. */
static void check_gravity(const char *exe, const char *name, char *summary, size_t len)
{
    tc_case c;
    if (!run_case(&c, exe, "gravity", name, true, false, GRAVITY_TIME, 0.02)) {
        tc_case_destroy(&c);
        snprintf(summary, len, "gravity: run failed");
        return;
    }
    tc_snapshots s;
    CHECK_OK(tc_snapshots_list(c.dir, &s));
    size_t nfluid0 = 0, nall0 = 0, outside = 0, nonfinite = 0;
    double t_last = 0, umax = 0;
    for (size_t k = 0; k < s.n; k++) {
        mf_sim snap;
        mf_hdf5_header h;
        if (tc_snapshot_load(c.dir, s.index[k], &snap, &h) != 0) {
            CHECK(!"snapshot readable");
            continue;
        }
        const mf_particles *p = snap.p;
        size_t nfluid = tc_count_kind(p, MF_FLUID);
        if (k == 0) {
            nfluid0 = nfluid;
            nall0 = p->n;
        }
        CHECK_MSG(nfluid == nfluid0 && p->n == nall0,
                  "solver %s: snapshot %d (t = %g) has %zu fluid / %zu particles, the start "
                  "%zu / %zu",
                  name, s.index[k], h.time, nfluid, p->n, nfluid0, nall0);
        if (!all_finite(p)) {
            nonfinite++;
            fprintf(stderr, "solver %s: snapshot %d (t = %g) holds a NaN or Inf\n", name,
                    s.index[k], h.time);
        }
        for (size_t i = 0; i < p->n; i++) {
            if (p->kind[i] != MF_FLUID)
                continue;
            const double *x = &p->pos[3 * i], *v = &p->vel[3 * i];
            double u = sqrt(v[0] * v[0] + v[1] * v[1]);
            if (u > umax)
                umax = u;
            if (!(x[0] >= 0 && x[0] <= BOX && x[1] >= 0 && x[1] <= BOX)) {
                if (outside < 10)
                    fprintf(stderr, "solver %s: snapshot %d (t = %g): fluid particle id %lld at "
                                    "(%g, %g) is outside the box\n",
                            name, s.index[k], h.time, (long long)p->id[i], x[0], x[1]);
                outside++;
            }
        }
        t_last = h.time;
        tc_sim_free(&snap);
    }
    CHECK_MSG(nfluid0 == (size_t)lround(BOX / L0) * (size_t)lround(FILL * BOX / L0),
              "solver %s: %zu fluid particles at the start", name, nfluid0);
    CHECK_MSG(fabs(t_last - GRAVITY_TIME) < 1e-9, "solver %s: the run ended at t = %g", name,
              t_last);
    CHECK(nonfinite == 0);
    CHECK(outside == 0);
    snprintf(summary, len,
             "gravity: %zu snapshots to t = %g, %zu fluid kept, max |u| %.3g m/s, %zu outside, "
             "%zu with NaN",
             s.n, t_last, nfluid0, umax, outside, nonfinite);
    tc_snapshots_free(&s);
    tc_case_destroy(&c);
}

/* (iii): fixed step under gravity. */
static void check_fixed_dt(const char *exe, const char *name, char *summary, size_t len)
{
    tc_case c;
    const double write_interval = 0.01;
    if (!run_case(&c, exe, "fixeddt", name, true, true, FIXED_TIME, write_interval)) {
        tc_case_destroy(&c);
        snprintf(summary, len, "fixed dt: run failed");
        return;
    }
    tc_snapshots s;
    CHECK_OK(tc_snapshots_list(c.dir, &s));
    double worst = 0;
    long prev_step = -1;
    const long steps_per_write = lround(write_interval / DT);
    for (size_t k = 0; k < s.n; k++) {
        char path[800];
        tc_snapshot_path(c.dir, s.index[k], path, sizeof path);
        mf_hdf5_header h;
        if (mf_hdf5_read_header(path, &h) != 0) {
            mf_error_print(stderr);
            CHECK(!"header readable");
            continue;
        }
        if (h.step > 0)
            CHECK_MSG(h.dt == DT, "solver %s: snapshot %d: TimeStep %.17g, deltaT %.17g", name,
                      s.index[k], h.dt, DT);
        double err = fabs(h.step * DT - h.time);
        CHECK_MSG(err <= 1e-12 * fmax(h.time, DT),
                  "solver %s: snapshot %d: Step %ld * deltaT = %.17g but Time = %.17g", name,
                  s.index[k], h.step, h.step * DT, h.time);
        if (err > worst)
            worst = err;
        if (prev_step >= 0)
            CHECK_MSG(h.step - prev_step == steps_per_write,
                      "solver %s: snapshot %d at step %ld follows step %ld (writeInterval is %ld "
                      "steps)",
                      name, s.index[k], h.step, prev_step, steps_per_write);
        prev_step = h.step;
    }
    CHECK_MSG(prev_step == lround(FIXED_TIME / DT), "solver %s: fixed-step run ended at step %ld",
              name, prev_step);
    snprintf(summary, len, "fixed dt: %zu snapshots, last step %ld, max |Step dt - Time| %.2g s",
             s.n, prev_step, worst);
    tc_snapshots_free(&s);
    tc_case_destroy(&c);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s MPSFLOW\n", argv[0]);
        return EXIT_FAILURE;
    }
    mf_registry *reg = NULL;
    CHECK_OK(mf_registry_create(&reg));
    CHECK_OK(mf_solvers_register_all(reg));
    size_t nsolvers = reg ? mf_registry_count(reg, MF_KIND_SOLVER) : 0;
    CHECK(nsolvers >= 1);
    printf("conformance: %zu registered solver(s)\n", nsolvers);
    for (size_t k = 0; k < nsolvers; k++) {
        const char *name = mf_registry_at(reg, MF_KIND_SOLVER, k)->name;
        int before = mf_test_failures;
        char rest[256] = "", gravity[256] = "", fixed[256] = "";
        check_rest(argv[1], name, rest, sizeof rest);
        check_gravity(argv[1], name, gravity, sizeof gravity);
        check_fixed_dt(argv[1], name, fixed, sizeof fixed);
        printf("conformance %-12s %s\n    %s; %s; %s\n", name,
               mf_test_failures == before ? "ok" : "FAILED", rest, gravity, fixed);
    }
    mf_registry_destroy(reg);
    return mf_test_summary("conformance");
}
