/* test_hydrostatic.c: a 2-D water column at rest in a tank open at the top.
 *
 * After it settles, the time-averaged pressure of interior fluid particles
 * must follow rho g (H - y). Also: no particle is lost, none passes the
 * walls, and `mpsflow validate` with the hydrostaticPressure metric reports
 * and writes its files.
 *
 * The resting column is not still: its pressure jitters from step to step
 * (at reNumberDensity 3.1 one snapshot's bottom pressure has an SD of about
 * 6% about the mean, at 2.1 about 25%) and the particles move at up to
 * ~0.3 m/s. Snapshots every 0.01 s over the last second give ~100 nearly
 * independent samples, so the time average is good to ~1%; with 20 samples
 * (writeInterval 0.05) and the noise of re = 2.1, a 5% check would have
 * been decided by chance.
 *
 * argv[1]: the mpsflow executable. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_util.h"
#include "mf_test.h"

#define L0 0.01          /* particle spacing, m */
#define WIDTH 0.2        /* column = tank width, m */
#define HEIGHT 0.4       /* column height, m: the surface of the water body */
#define TANK 0.6         /* tank height, m (open at the top) */
#define RHO 1000.0
#define G 9.81
#define END_TIME 2.0
#define SETTLE 1.0       /* average snapshots from this time on */
#define TOLERANCE 0.05   /* relative, bottom quarter */

static const char *const control =
    "endTime         2.0;\n"
    "deltaT          1e-4;\n"
    "adjustTimeStep  yes;\n"
    "maxCo           0.2;\n"
    "maxDeltaT       1e-3;\n"
    "writeControl    adjustableRunTime;\n"
    "writeInterval   0.01;\n";

/* The stabilised settings of the damBreak2D tutorial. */
static const char *const solver =
    "solver MPS;\n"
    "MPSCoeffs { relaxation 0.2; collision yes; }\n"
    "pressure { solver PCG_BoomerAMG; tolerance 1e-8; }\n"
    "forces { gravity { g (0 -9.81 0); } }\n";

static const char *const fluids = "water { rho 1000; nu 1e-6; }\n";

static const char *const metric =
    "metric hydrostaticPressure;\nrho 1000;\nsurface 0.4;\nbottom 0;\nsettleTime 1.0;\n";

#define NBINS 64 /* bins of height l0 from the floor; the column is 40 */

typedef struct stats {
    /* Interior fluid particles, per bin of height l0, summed over settled snapshots. */
    double psum[NBINS], ysum[NBINS], nsum[NBINS], count[NBINS];
    /* The same binned as driver/post/metric_hydrostatic.c bins them (y in [0, H), h.time >= settle). */
    double mpsum[NBINS], mcount[NBINS];
    double surf_ysum, surf_count;     /* surface-flagged fluid particles in the top region */
    double top_ysum, top_count;       /* the highest fluid particle of each column of width l0 */
    double ke_max_settled, speed_max_settled;
    /* Per snapshot: bottom-quarter p / rho g (H - y) - 1, to see the noise. */
    double rel_sum, rel_sq;
    int settled;
    long outside;
} stats;

static void scan_snapshot(const mf_particles *p, const mf_hdf5_header *h, int index,
                          size_t nfluid0, double n0, stats *s)
{
    const double *pr = tc_field_d(p, "Pressure");
    const double *nd = tc_field_d(p, "NumberDensity");
    const int32_t *flags = tc_field_i(p, "Flags");
    CHECK(pr && nd && flags);
    if (!pr || !nd || !flags)
        return;
    /* (a) every fluid particle is still there. */
    size_t nfluid = tc_count_kind(p, MF_FLUID);
    CHECK_MSG(nfluid == nfluid0, "snapshot %d (t = %g): %zu fluid particles, %zu at the start",
              index, h->time, nfluid, nfluid0);
    CHECK(h->npart[MF_FLUID] == (int64_t)nfluid);
    /* (b) none through a wall: past the wall-particle line, l0/2 outside the
     * box the fluid fills (the watch's throughWall line). The fluid's own
     * edge is no bound: a surface particle at a wall jitters a few hundredths
     * of l0 past it now and then, depending on where within its tolerance
     * each pressure solve lands (main's code crossed it with tolerance 1e-9
     * or strongThreshold 0.3, not with the settings here). */
    for (size_t i = 0; i < p->n; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *x = &p->pos[3 * i];
        bool finite = isfinite(x[0]) && isfinite(x[1]) && isfinite(p->vel[3 * i]) &&
                      isfinite(p->vel[3 * i + 1]) && isfinite(pr[i]);
        const double h0 = 0.5 * L0;
        if (!finite || x[0] < -h0 || x[0] > WIDTH + h0 || x[1] < -h0) {
            if (s->outside < 10)
                fprintf(stderr, "snapshot %d (t = %g): fluid particle id %lld at (%.6g, %.6g) "
                                "is past the walls [%g, %g] x [%g, inf)%s\n",
                        index, h->time, (long long)p->id[i], x[0], x[1], -h0, WIDTH + h0, -h0,
                        finite ? "" : " or not finite");
            s->outside++;
        }
    }
    if (h->time < SETTLE - 1e-9)
        return;
    s->settled++;
    double ke = 0, umax = 0, snap_p = 0, snap_pex = 0;
    double top[NBINS];
    for (int b = 0; b < NBINS; b++)
        top[b] = -1;
    for (size_t i = 0; i < p->n; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double x = p->pos[3 * i], y = p->pos[3 * i + 1];
        const double *v = &p->vel[3 * i];
        double u2 = v[0] * v[0] + v[1] * v[1];
        ke += 0.5 * RHO * L0 * L0 * u2;
        if (sqrt(u2) > umax)
            umax = sqrt(u2);
        int col = (int)(x / L0);
        if (col >= 0 && col < NBINS && y > top[col])
            top[col] = y;
        bool surface = flags[i] & 1;
        if (surface && y > 0.75 * HEIGHT) {
            s->surf_ysum += y;
            s->surf_count += 1;
        }
        if (surface || y < 0)
            continue;
        int b = (int)(y / L0);
        if (y < 0.25 * HEIGHT) {
            snap_p += pr[i];
            snap_pex += RHO * G * (HEIGHT - y);
        }
        if (b < NBINS) {
            s->psum[b] += pr[i];
            s->ysum[b] += y;
            s->nsum[b] += nd[i] / n0;
            s->count[b] += 1;
        }
        if (h->time >= SETTLE && y < HEIGHT) {
            s->mpsum[b] += pr[i];
            s->mcount[b] += 1;
        }
    }
    for (int c = 0; c < (int)lround(WIDTH / L0); c++)
        if (top[c] >= 0) {
            s->top_ysum += top[c];
            s->top_count += 1;
        }
    if (snap_pex > 0) {
        s->rel_sum += snap_p / snap_pex - 1;
        s->rel_sq += (snap_p / snap_pex - 1) * (snap_p / snap_pex - 1);
    }
    if (ke > s->ke_max_settled)
        s->ke_max_settled = ke;
    if (umax > s->speed_max_settled)
        s->speed_max_settled = umax;
}

/* Least-squares line p = a + b y through the bin averages with y in [y0, y1]. */
static void fit_line(const stats *s, double y0, double y1, double *a, double *b)
{
    double n = 0, sy = 0, sp = 0, syy = 0, syp = 0;
    for (int k = 0; k < NBINS; k++) {
        if (s->count[k] == 0)
            continue;
        double y = s->ysum[k] / s->count[k], pv = s->psum[k] / s->count[k];
        if (y < y0 || y > y1)
            continue;
        n++;
        sy += y;
        sp += pv;
        syy += y * y;
        syp += y * pv;
    }
    *b = (n * syp - sy * sp) / (n * syy - sy * sy);
    *a = (sp - *b * sy) / n;
}

/* The RMS of driver/post/metric_hydrostatic.c, recomputed from the snapshots. */
static double metric_rms(const stats *s)
{
    double sum = 0;
    int nb = 0;
    for (int b = 0; b < (int)ceil(HEIGHT / L0); b++) {
        if (s->mcount[b] == 0)
            continue;
        double y = (b + 0.5) * L0;
        double rel = (s->mpsum[b] / s->mcount[b] - RHO * G * (HEIGHT - y)) / (RHO * G * HEIGHT);
        sum += rel * rel;
        nb++;
    }
    return nb ? sqrt(sum / nb) : NAN;
}

static double parse_metric_error(const tc_case *c)
{
    char path[700];
    snprintf(path, sizeof path, "%s/log", c->dir);
    FILE *f = fopen(path, "r");
    double value = NAN;
    char line[512];
    while (f && fgets(line, sizeof line, f)) {
        const char *at = strstr(line, "error hydrostaticPressure = ");
        if (at)
            value = strtod(at + strlen("error hydrostaticPressure = "), NULL);
    }
    if (f)
        fclose(f);
    return value;
}

static bool file_nonempty(const tc_case *c, const char *rel)
{
    char path[700];
    snprintf(path, sizeof path, "%s/%s", c->dir, rel);
    FILE *f = fopen(path, "rb");
    if (!f)
        return false;
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fclose(f);
    return size > 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s MPSFLOW\n", argv[0]);
        return EXIT_FAILURE;
    }
    char geometry[1024];
    snprintf(geometry, sizeof geometry,
             "dimension 2;\nparticleSpacing %g;\n"
             "fluidBlocks { column { type box; min (0 0 0); max (%g %g 0); fluid water; } }\n"
             "walls { tank { type box; min (0 0 0); max (%g %g 0); open (ymax); "
             "wallLayers 1; dummyLayers 2; } }\n",
             L0, WIDTH, HEIGHT, WIDTH, TANK);
    tc_case c;
    if (tc_case_from_strings(&c, argv[1], "hydrostatic", control, solver, fluids, geometry) != 0) {
        tc_case_destroy(&c);
        return EXIT_FAILURE;
    }
    int status = tc_case_run(&c, NULL, (const char *const[]){"-quiet", NULL});
    printf("hydrostatic: run to t = %g s at l0 = %g m: exit %d, %.1f s wall\n", END_TIME, L0,
           status, c.last_wall);
    CHECK_MSG(status == 0, "mpsflow exited with %d", status);
    if (status != 0)
        tc_case_log_tail(&c, 30);

    tc_snapshots snaps;
    CHECK_OK(tc_snapshots_list(c.dir, &snaps));
    stats *s = calloc(1, sizeof *s);
    size_t nfluid0 = 0;
    double last_time = 0;
    /* n0 of the number-density kernel (the radius the run used) on the square lattice. */
    double re = 0, n0 = 0;
    CHECK_OK(tc_resolved_number(c.dir, "solverDict/MPSCoeffs/reNumberDensity", &re));
    for (int i = -10; i <= 10; i++)
        for (int j = -10; j <= 10; j++) {
            double r = sqrt((double)(i * i + j * j));
            if ((i || j) && r < re)
                n0 += re / r - 1;
        }
    for (size_t k = 0; s && k < snaps.n; k++) {
        mf_sim snap;
        mf_hdf5_header h;
        if (tc_snapshot_load(c.dir, snaps.index[k], &snap, &h) != 0) {
            CHECK(!"snapshot readable");
            continue;
        }
        if (k == 0) {
            nfluid0 = tc_count_kind(snap.p, MF_FLUID);
            size_t lattice = (size_t)lround(WIDTH / L0) * (size_t)lround(HEIGHT / L0);
            CHECK_MSG(nfluid0 == lattice, "%zu fluid particles at the start, the block holds %zu",
                      nfluid0, lattice);
        }
        scan_snapshot(snap.p, &h, snaps.index[k], nfluid0, n0, s);
        last_time = h.time;
        tc_sim_free(&snap);
    }
    printf("hydrostatic: %zu snapshots up to t = %g s, %zu fluid particles, %d settled "
           "(t >= %g s); number density radius %g l0\n",
           snaps.n, last_time, nfluid0, s ? s->settled : 0, SETTLE, re);
    CHECK_MSG(last_time >= END_TIME * (1 - 1e-9), "the run stopped at t = %g", last_time);
    CHECK_MSG(s && s->outside == 0, "%ld fluid particle positions past the walls",
              s ? s->outside : -1);
    CHECK(s && s->settled >= 10);
    if (!s || s->settled == 0) {
        free(s);
        tc_snapshots_free(&snaps);
        tc_case_destroy(&c);
        return mf_test_summary("hydrostatic");
    }

    /* The surface: H = 0.4 m is the top of the water body (the top particles sit at
     * H - l0/2). Measured: the mean y of surface particles in the top quarter, and the
     * mean of the highest particle of each column, each + l0/2. */
    double h_surf = s->surf_ysum / s->surf_count + 0.5 * L0;
    double h_top = s->top_ysum / s->top_count + 0.5 * L0;
    printf("hydrostatic: surface height: analytic H = %.4f m; measured %.4f m (surface-flagged "
           "particles + l0/2), %.4f m (top particle of each column + l0/2)\n",
           HEIGHT, h_surf, h_top);
    printf("hydrostatic: settled: max kinetic energy %.3g J/m, max speed %.3g m/s\n",
           s->ke_max_settled, s->speed_max_settled);

    /* (c) the bottom quarter, bin by bin, against rho g (H - y) at the bins' mean y. */
    const double H = HEIGHT;
    double worst = 0, psum = 0, pex_sum = 0;
    int nchecked = 0;
    for (int b = 0; b < NBINS; b++) {
        if (s->count[b] == 0)
            continue;
        double y = s->ysum[b] / s->count[b];
        if (y >= 0.25 * H)
            continue;
        double pavg = s->psum[b] / s->count[b], pex = RHO * G * (H - y);
        double rel = (pavg - pex) / pex;
        if (fabs(rel) > fabs(worst))
            worst = rel;
        psum += s->psum[b];
        pex_sum += RHO * G * (H * s->count[b] - s->ysum[b]);
        nchecked++;
    }
    double overall = (psum - pex_sum) / pex_sum;
    double mean = s->rel_sum / s->settled;
    double sd = sqrt(fmax(0, s->rel_sq / s->settled - mean * mean));
    printf("hydrostatic: one snapshot's bottom-quarter p / rho g (H - y) - 1 varies with SD "
           "%.3f; the mean of %d is %+.4f +- %.4f\n",
           sd, s->settled, mean, sd / sqrt(s->settled));
    printf("hydrostatic: bottom quarter (y < %.3f m), %d bins: mean p / rho g (H - y) - 1 = "
           "%+.4f, worst bin %+.4f (tolerance %.2f)\n",
           0.25 * H, nchecked, overall, worst, TOLERANCE);
    CHECK(nchecked >= 8);
    CHECK_MSG(fabs(overall) <= TOLERANCE && fabs(worst) <= TOLERANCE,
              "time-averaged pressure in the bottom quarter is off rho g (H - y) by %+.2f%% "
              "(mean) / %+.2f%% (worst bin)",
              100 * overall, 100 * worst);

    /* The profile, and what explains a departure: slope and intercept of p(y) in the
     * bulk (between the bottom and the surface layers), and the number density there. */
    double a, bslope;
    fit_line(s, 0.1 * H, 0.8 * H, &a, &bslope);
    printf("hydrostatic: bulk fit p = %.1f %+.1f y: dp/dy = %.4f rho g, p = 0 at y = %.4f m\n", a,
           bslope, -bslope / (RHO * G), -a / bslope);
    printf("hydrostatic: profile (interior particles, time average over %d snapshots):\n",
           s->settled);
    printf("    %8s %10s %10s %8s %8s %7s\n", "y", "p", "rhog(H-y)", "rel", "n/n0", "samples");
    for (int b = 0; b < NBINS; b++) {
        if (s->count[b] == 0)
            continue;
        double y = s->ysum[b] / s->count[b], pavg = s->psum[b] / s->count[b];
        double pex = RHO * G * (H - y);
        printf("    %8.4f %10.1f %10.1f %+8.4f %8.4f %7.0f\n", y, pavg, pex,
               pex > 0 ? (pavg - pex) / pex : NAN, s->nsum[b] / s->count[b], s->count[b]);
    }

    /* `mpsflow validate` with the hydrostaticPressure metric. */
    CHECK_OK(tc_case_write(&c, TC_METRIC, metric));
    status = tc_case_run(&c, "validate", NULL);
    CHECK_MSG(status == 0, "mpsflow validate exited with %d", status);
    if (status != 0)
        tc_case_log_tail(&c, 20);
    CHECK(tc_case_log_contains(&c, "error hydrostaticPressure = "));
    CHECK(file_nonempty(&c, "validation/result.csv"));
    CHECK(file_nonempty(&c, "validation/result.png"));
    double reported = parse_metric_error(&c), recomputed = metric_rms(s);
    printf("hydrostatic: validate: error hydrostaticPressure = %.6g (recomputed here: %.6g)\n",
           reported, recomputed);
    CHECK_NEAR(reported, recomputed, 1e-5 * (1 + fabs(recomputed)));

    free(s);
    tc_snapshots_free(&snaps);
    tc_case_destroy(&c);
    return mf_test_summary("hydrostatic");
}
