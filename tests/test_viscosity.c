/* test_viscosity.c: implicit viscosity (solvers/solver/mps/mps_viscosity.c) and the
 * periodic x axis (solvers/solver/mps/mps_periodic.c), through the mpsflow
 * executable on the start-up of plane Poiseuille flow (a viscous liquid,
 * nu = 1e-3 m^2/s, between plates 0.1 m apart, periodic channel 0.08 m long,
 * l0 = 0.01 m, body force 0.008 m/s^2; tutorials/poiseuille2D).
 *
 * part "viscosity":
 *   (a) at a small fixed step (nu dt / l0^2 = 0.01) the implicit and the
 *       explicit runs agree: max |u_imp - u_exp| below 2% of the centre-line
 *       speed after 0.5 s (the two differ by O(dt));
 *   (b) the explicit term is stable here up to nu dt / l0^2 of about 1;
 *       the implicit run at 150 (dt = 15 s) reaches the steady state
 *       (t = 45 s) with the spatial error of the explicit run at 0.5
 *       (metric `poiseuille`), and the explicit scheme at 2 is stopped by
 *       the run's watch;
 *   (c) conformance with `viscosity implicit`: a partly filled closed box
 *       without forces stays at rest; under gravity no particle is lost,
 *       nothing is NaN and no fluid leaves the box;
 *   (d) the viscous solver is the one solverDict's `viscosity { solver
 *       NAME; }` names: PCG_diagonal at the same tolerance gives the run of
 *       (a) within 1e-6 of its centre-line speed, and the run's resolved
 *       parameters name it; the dictionary with explicit viscosity is
 *       refused.
 * part "periodic":
 *   particles are conserved, every fluid x stays in [0, 0.08), the flow is
 *   the same at every x (the spread of u along each particle row is below
 *   1% of the centre-line speed: no seam at the periodic faces), and the
 *   profile is symmetric about the centre line.
 *
 * argv[1]: mpsflow; argv[2]: the part. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_util.h"
#include "mf_test.h"

#define L0 0.01
#define LX 0.08
#define GAP 0.1

static const char *const fluids = "liquid { rho 1000; nu 1e-3; }\n";
static double force = 0.008; /* m/s^2; the periodic part drives harder */
static const char *viscous_solver = ""; /* a `viscosity { ... }` for solverDict */

static void geometry(char *buf, size_t len)
{
    snprintf(buf, len,
             "dimension 2;\nparticleSpacing %g;\n"
             "fluidBlocks { channel { type box; min (0 0 0); max (%g %g 0); fluid liquid; } }\n"
             "walls { plates { type box; min (0 0 0); max (%g %g 0); open (xmin xmax); } }\n",
             L0, LX, GAP, LX, GAP);
}

static void solver(char *buf, size_t len, const char *viscosity)
{
    snprintf(buf, len,
             "solver MPS;\nMPSCoeffs { relaxation 0.2; collision yes; viscosity %s; "
             "periodicLength %g; periodicOrigin 0; }\n"
             "pressure { solver PCG_BoomerAMG; tolerance 1e-8; }\n"
             "forces { gravity { g (%g 0 0); } }\n%s",
             viscosity, LX, force, viscous_solver);
}

/* Run the channel with a fixed step; returns the exit status. */
static double write_every = 0; /* 0: only at the end */

static int run_channel(tc_case *c, const char *exe, const char *tag, const char *viscosity,
                       double dt, double end_time, const char *extra_control)
{
    char control[512], solv[512], geo[1024], metric[256];
    snprintf(metric, sizeof metric,
             "metric poiseuille;\nbodyForce %g;\nnu 1e-3;\ngap %g;\nbottom 0;\n", force, GAP);
    snprintf(control, sizeof control,
             "endTime %.17g;\nadjustTimeStep no;\ndeltaT %.17g;\nwriteInterval %.17g;\n%s",
             end_time, dt, write_every > 0 ? write_every : end_time,
             extra_control ? extra_control : "");
    solver(solv, sizeof solv, viscosity);
    geometry(geo, sizeof geo);
    if (tc_case_from_strings(c, exe, tag, control, solv, fluids, geo) != 0 ||
        tc_case_write(c, TC_METRIC, metric) != 0) {
        CHECK(!"case created");
        return -1;
    }
    return tc_case_run(c, NULL, (const char *const[]){"-quiet", NULL});
}

/* True if the case's file rel contains text. */
static bool file_contains(const char *dir, const char *rel, const char *text)
{
    char path[1024], buf[65536];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    FILE *f = fopen(path, "r");
    if (!f)
        return false;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    return strstr(buf, text) != NULL;
}

/* The last snapshot of a case (sim zeroed first). */
static int load_last(const tc_case *c, mf_sim *sim)
{
    tc_snapshots s;
    memset(sim, 0, sizeof *sim);
    if (tc_snapshots_list(c->dir, &s) != 0 || s.n == 0)
        return -1;
    int rc = tc_snapshot_load(c->dir, s.index[s.n - 1], sim, NULL);
    tc_snapshots_free(&s);
    return rc;
}

/* u_x of the particle with each id (ids < cap), NAN where absent. */
static void velocity_by_id(const mf_particles *p, double *u, size_t cap)
{
    for (size_t k = 0; k < cap; k++)
        u[k] = NAN;
    for (size_t i = 0; i < p->n; i++)
        if (p->kind[i] == MF_FLUID && p->id[i] >= 0 && (size_t)p->id[i] < cap)
            u[p->id[i]] = p->vel[3 * i];
}

static double validate(tc_case *c)
{
    if (tc_case_run(c, "validate", NULL) != 0)
        return NAN;
    char path[700];
    snprintf(path, sizeof path, "%s/log", c->dir);
    FILE *f = fopen(path, "r");
    double e = NAN;
    char line[512];
    while (f && fgets(line, sizeof line, f))
        sscanf(line, "error poiseuille = %lf", &e);
    if (f)
        fclose(f);
    return e;
}

static void part_viscosity(const char *exe)
{
    /* (a) small step: implicit against explicit. */
    const double dt_small = 0.01 * L0 * L0 / 1e-3, t_a = 0.5;
    tc_case ce, ci;
    int se = run_channel(&ce, exe, "visc-exp", "explicit", dt_small, t_a, NULL);
    int si = run_channel(&ci, exe, "visc-imp", "implicit", dt_small, t_a, NULL);
    CHECK_MSG(se == 0 && si == 0, "small step: explicit exit %d, implicit exit %d", se, si);
    mf_sim a, b;
    if (se == 0 && si == 0 && load_last(&ce, &a) == 0 && load_last(&ci, &b) == 0) {
        enum { CAP = 4096 };
        static double ua[CAP], ub[CAP];
        velocity_by_id(a.p, ua, CAP);
        velocity_by_id(b.p, ub, CAP);
        double diff = 0, umax = 0;
        size_t n = 0;
        for (size_t k = 0; k < CAP; k++) {
            if (isnan(ua[k]) && isnan(ub[k]))
                continue;
            n++;
            double d = fabs(ua[k] - ub[k]);
            if (!(d <= diff))
                diff = d; /* NaN (a particle missing in one run) sticks */
            if (fabs(ua[k]) > umax)
                umax = fabs(ua[k]);
        }
        printf("small step (nu dt/l0^2 = 0.01, t = %g s): %zu particles, centre-line %.5g m/s, "
               "max |u_implicit - u_explicit| = %.3g m/s (%.3g%%)\n",
               t_a, n, umax, diff, 100 * diff / umax);
        CHECK(n > 0);
        CHECK_MSG(diff < 0.02 * umax, "implicit and explicit differ by %g of the centre-line "
                  "speed", diff / umax);
        double ee = validate(&ce), ei = validate(&ci);
        printf("  metric poiseuille at t = %g s: explicit %.4g, implicit %.4g\n", t_a, ee, ei);
        CHECK(ee < 0.3 && ei < 0.3);

        /* (d) the viscous solver by name. */
        tc_case cd, cr;
        viscous_solver = "viscosity { solver PCG_diagonal; tolerance 1e-10; }\n";
        int sd = run_channel(&cd, exe, "visc-diag", "implicit", dt_small, t_a, NULL);
        int sr = run_channel(&cr, exe, "visc-refused", "explicit", dt_small, t_a, NULL);
        viscous_solver = "";
        mf_sim c;
        CHECK_MSG(sd == 0, "implicit with PCG_diagonal: exit %d", sd);
        if (sd == 0 && load_last(&cd, &c) == 0) {
            static double uc[CAP];
            velocity_by_id(c.p, uc, CAP);
            double dd = 0;
            for (size_t k = 0; k < CAP; k++)
                if (!(isnan(ub[k]) && isnan(uc[k])) && !(fabs(ub[k] - uc[k]) <= dd))
                    dd = fabs(ub[k] - uc[k]);
            printf("viscosity { solver PCG_diagonal; }: max |u - u_PCG_BoomerAMG| = %.3g m/s "
                   "(%.3g of the centre-line speed)\n", dd, dd / umax);
            CHECK_MSG(dd <= 1e-6 * umax, "PCG_diagonal and PCG_BoomerAMG differ by %g", dd);
            CHECK(file_contains(cd.dir, "output/resolvedParameters", "PCG_diagonal"));
            tc_sim_free(&c);
        }
        CHECK_MSG(sr == 1 && tc_case_log_contains(&cr, "but the viscosity is explicit"),
                  "a viscosity dictionary with explicit viscosity: exit %d", sr);
        tc_case_destroy(&cd);
        tc_case_destroy(&cr);
        tc_sim_free(&a);
        tc_sim_free(&b);
    } else {
        tc_case_log_tail(&ce, 15);
        tc_case_log_tail(&ci, 15);
    }
    tc_case_destroy(&ce);
    tc_case_destroy(&ci);

    /* (b) Far beyond the explicit limit. The explicit eq. 7 term on this
     * case is stable up to nu dt / l0^2 of about 1 (measured: 1 runs, 1.25
     * is stopped by the watch); maxDi's default allows 0.1. The implicit
     * run takes nu dt / l0^2 = 150 (dt = 15 s, three steps to the steady
     * state) and must match the explicit run's steady error. */
    const double dt_big = 150 * L0 * L0 / 1e-3, t_b = 45, dt_exp = 0.5 * L0 * L0 / 1e-3;
    tc_case cb, cx, cs;
    int sb = run_channel(&cb, exe, "visc-big", "implicit", dt_big, t_b, NULL);
    CHECK_MSG(sb == 0, "implicit at nu dt/l0^2 = 150: exit %d", sb);
    if (sb != 0)
        tc_case_log_tail(&cb, 20);
    double eb = sb == 0 ? validate(&cb) : NAN;
    int ss = run_channel(&cs, exe, "visc-steady", "explicit", dt_exp, t_b, NULL);
    double es = ss == 0 ? validate(&cs) : NAN;
    printf("steady state (t = %g s): implicit at nu dt/l0^2 = 150 (dt = %g s) error %.4g; "
           "explicit at nu dt/l0^2 = 0.5 error %.4g\n",
           t_b, dt_big, eb, es);
    CHECK_MSG(eb < 1.2 * es + 0.01, "implicit big-step error %g against the explicit %g", eb, es);
    /* The explicit scheme at nu dt/l0^2 = 2: the watch stops it (no retries). */
    int sx = run_channel(&cx, exe, "visc-bigexp", "explicit", 2 * L0 * L0 / 1e-3, t_b,
                         "maxRetries 0;\n");
    bool stopped = sx == 1 && tc_case_log_contains(&cx, "unstable (");
    printf("explicit at nu dt/l0^2 = 2: exit %d%s\n", sx, stopped ? ", stopped by the watch" : "");
    CHECK_MSG(stopped, "the explicit scheme at nu dt/l0^2 = 2 was not stopped by the watch");
    tc_case_destroy(&cb);
    tc_case_destroy(&cs);
    tc_case_destroy(&cx);

    /* (c) conformance with viscosity implicit: rest and gravity in a closed box. */
    static const char *const geo_box =
        "dimension 2;\nparticleSpacing 0.01;\n"
        "fluidBlocks { water { type box; min (0 0 0); max (0.2 0.12 0); fluid water; } }\n"
        "walls { box { type box; min (0 0 0); max (0.2 0.2 0); } }\n";
    static const char *const water = "water { rho 1000; nu 1e-6; }\n";
    for (int gravity = 0; gravity < 2; gravity++) {
        tc_case c;
        char solv[512];
        snprintf(solv, sizeof solv,
                 "solver MPS;\nMPSCoeffs { viscosity implicit; relaxation 0.2; collision yes; }\n%s",
                 gravity ? "forces { gravity { g (0 -9.81 0); } }\n" : "");
        const char *control =
            gravity ? "endTime 0.2;\nadjustTimeStep yes;\ndeltaT 1e-4;\nmaxCo 0.2;\nmaxDeltaT "
                      "1e-3;\nwriteInterval 0.2;\n"
                    : "endTime 0.05;\nadjustTimeStep no;\ndeltaT 1e-3;\nwriteInterval 0.05;\n";
        if (tc_case_from_strings(&c, exe, gravity ? "visc-gravity" : "visc-rest", control, solv,
                                 water, geo_box) != 0) {
            CHECK(!"case created");
            continue;
        }
        int st = tc_case_run(&c, NULL, (const char *const[]){"-quiet", NULL});
        CHECK_MSG(st == 0, "conformance (%s): exit %d", gravity ? "gravity" : "rest", st);
        mf_sim first, last;
        tc_snapshots s;
        if (st == 0 && tc_snapshots_list(c.dir, &s) == 0 && s.n >= 2 &&
            tc_snapshot_load(c.dir, s.index[0], &first, NULL) == 0 &&
            tc_snapshot_load(c.dir, s.index[s.n - 1], &last, NULL) == 0) {
            double umax = 0;
            size_t outside = 0, nonfinite = 0;
            for (size_t i = 0; i < last.p->n; i++) {
                const double *x = &last.p->pos[3 * i], *v = &last.p->vel[3 * i];
                double u = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
                if (!isfinite(u) || !isfinite(x[0]) || !isfinite(x[1]))
                    nonfinite++;
                if (last.p->kind[i] == MF_FLUID) {
                    if (!(u <= umax))
                        umax = u;
                    if (x[0] < 0 || x[0] > 0.2 || x[1] < 0 || x[1] > 0.2)
                        outside++;
                }
            }
            printf("conformance, %s: %zu -> %zu fluid particles, max |u| %.3g m/s, %zu outside, "
                   "%zu not finite\n",
                   gravity ? "gravity 0.2 s" : "rest 50 steps", tc_count_kind(first.p, MF_FLUID),
                   tc_count_kind(last.p, MF_FLUID), umax, outside, nonfinite);
            CHECK(tc_count_kind(first.p, MF_FLUID) == tc_count_kind(last.p, MF_FLUID));
            CHECK(outside == 0 && nonfinite == 0);
            if (!gravity)
                CHECK_MSG(umax < 1e-6, "a particle moves at %g m/s in a box at rest", umax);
            tc_sim_free(&first);
            tc_sim_free(&last);
            tc_snapshots_free(&s);
        } else {
            CHECK(!"conformance snapshots readable");
            tc_case_log_tail(&c, 15);
        }
        tc_case_destroy(&c);
    }
}

static int by_y(const void *a, const void *b)
{
    const double *p = a, *q = b;
    return (p[0] > q[0]) - (p[0] < q[0]);
}

static void part_periodic(const char *exe)
{
    tc_case c;
    const double dt = 0.1 * L0 * L0 / 1e-3, t_end = 2.0;
    force = 0.08; /* u_centre -> 0.1 m/s: the middle rows cross the period about twice */
    write_every = 0.05; /* shorter than the time to cross half a period */
    int st = run_channel(&c, exe, "periodic", "explicit", dt, t_end, NULL);
    CHECK_MSG(st == 0, "periodic channel: exit %d", st);
    tc_snapshots s;
    if (st != 0 || tc_snapshots_list(c.dir, &s) != 0) {
        tc_case_log_tail(&c, 20);
        tc_case_destroy(&c);
        return;
    }
    size_t n0 = 0, outside = 0;
    double xmin = INFINITY, xmax = -INFINITY, travel = 0;
    mf_sim last;
    memset(&last, 0, sizeof last);
    enum { CAP = 4096 };
    static double prev_x[CAP], dist[CAP];
    for (size_t k = 0; k < s.n; k++) {
        mf_sim snap;
        if (tc_snapshot_load(c.dir, s.index[k], &snap, NULL) != 0) {
            CHECK(!"snapshot readable");
            continue;
        }
        size_t nf = tc_count_kind(snap.p, MF_FLUID);
        if (k == 0)
            n0 = nf;
        CHECK_MSG(nf == n0, "snapshot %zu: %zu fluid particles, %zu at the start", k, nf, n0);
        for (size_t i = 0; i < snap.p->n; i++) {
            if (snap.p->kind[i] != MF_FLUID)
                continue;
            double x = snap.p->pos[3 * i];
            int64_t id = snap.p->id[i];
            if (id >= 0 && id < CAP) { /* unwrapped travel along x */
                double dx = k == 0 ? 0 : x - prev_x[id];
                dx -= LX * round(dx / LX);
                dist[id] += dx;
                prev_x[id] = x;
                travel = dist[id] > travel ? dist[id] : travel;
            }
            xmin = x < xmin ? x : xmin;
            xmax = x > xmax ? x : xmax;
            if (!(x >= 0 && x < LX))
                outside++;
        }
        if (k + 1 == s.n)
            last = snap;
        else
            tc_sim_free(&snap);
    }
    CHECK(outside == 0);
    /* Rows of particles (same starting y): spread of u along x. */
    const mf_particles *p = last.p;
    double (*row)[2] = p ? malloc(p->n * sizeof *row) : NULL;
    size_t n = 0;
    for (size_t i = 0; row && i < p->n; i++)
        if (p->kind[i] == MF_FLUID) {
            row[n][0] = p->pos[3 * i + 1];
            row[n][1] = p->vel[3 * i];
            n++;
        }
    double umax = 0, spread = 0, asym = 0;
    if (row && n > 0) {
        qsort(row, n, sizeof *row, by_y);
        /* Group by y within l0/4. */
        double means[64], ys[64];
        size_t nrows = 0;
        for (size_t a = 0; a < n && nrows < 64;) {
            size_t b = a;
            double lo = INFINITY, hi = -INFINITY, sum = 0, ysum = 0;
            while (b < n && row[b][0] - row[a][0] < 0.25 * L0) {
                lo = row[b][1] < lo ? row[b][1] : lo;
                hi = row[b][1] > hi ? row[b][1] : hi;
                sum += row[b][1];
                ysum += row[b][0];
                b++;
            }
            means[nrows] = sum / (double)(b - a);
            ys[nrows++] = ysum / (double)(b - a);
            spread = hi - lo > spread ? hi - lo : spread;
            umax = means[nrows - 1] > umax ? means[nrows - 1] : umax;
            a = b;
        }
        for (size_t r = 0; r < nrows; r++)
            asym = fmax(asym, fabs(means[r] - means[nrows - 1 - r]));
        printf("periodic channel, t = %g s: %zu fluid particles kept, x in [%.4g, %.4g), "
               "%zu rows, centre-line %.4g m/s, largest spread of u along a row %.3g m/s "
               "(%.3g%%), asymmetry %.3g m/s; the fastest particle travelled %.3g m (%.2g "
               "periods)\n",
               t_end, n, xmin, xmax, nrows, umax, spread, 100 * spread / umax, asym, travel,
               travel / LX);
        CHECK_MSG(travel > LX, "the fastest particle travelled only %g m", travel);
        CHECK(nrows == (size_t)(GAP / L0 + 0.5));
        (void)ys;
    }
    CHECK(umax > 0);
    CHECK_MSG(spread < 0.01 * umax, "u varies by %g of the centre-line speed along a row",
              spread / umax);
    CHECK_MSG(asym < 0.01 * umax, "profile asymmetric by %g of the centre-line speed",
              asym / umax);
    free(row);
    tc_sim_free(&last);
    tc_snapshots_free(&s);
    tc_case_destroy(&c);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s MPSFLOW viscosity|periodic\n", argv[0]);
        return 2;
    }
    if (strcmp(argv[2], "viscosity") == 0)
        part_viscosity(argv[1]);
    else if (strcmp(argv[2], "periodic") == 0)
        part_periodic(argv[1]);
    else {
        fprintf(stderr, "unknown part %s\n", argv[2]);
        return 2;
    }
    return mf_test_summary(argv[2]);
}
