/* test_surface_tension_drop.c: surface tension in motion, the droplet
 * tutorials at l0 = 1.5 mm (the tutorials' 1 mm costs 2-3 times more)
 * through the mpsflow executable and `mpsflow validate`
 * (driver/post/metric_droplet.c). Both tutorials use surfaceTension
 * `freeSurface pressure`: the free-surface particles hold the Laplace
 * pressure sigma kappa (README, "Multi-fluid").
 *
 *   squareDroplet (a 0.04 m square of water, sigma 0.07 N/m, no gravity),
 *   to t = 1 s: the square relaxes toward a circle (the roundness, std/mean
 *   of the outer radius in 36 sectors, falls from 0.12 to under half of
 *   it); the pressure jump p_in - p_out (p_in over r < R/2), time-averaged
 *   after 0.3 s, is within 10% of Laplace's sigma/R (R = s/sqrt(pi), s^2 the
 *   area the lattice square fills); fewer than 2% of the particles are shed
 *   (farther than 1.5 R from the centroid at the end).
 *   dropletOscillation (an ellipse, semi-axes 1.08 R and R/1.08): the
 *   mode-2 period from the zero crossings of the quadrupole moment Q, over
 *   two periods, is within 10% of Rayleigh's; the period from the x and y
 *   extents is printed; fewer than 2% of the particles are shed.
 *
 * Measured (README, "Multi-fluid"): with the paper's force on the free
 * surface instead (freeSurface force) the jump is 0.57-0.59 sigma/R and
 * fails; its period is 4.5% short at this spacing but 16-18% long at 1 and
 * 2 mm, and its oscillation is damped far faster than viscosity damps it.
 * With the pressure and nu 1e-5, 5-11% of the particles were shed.
 *
 * argv[1]: mpsflow; argv[2]: the tutorials folder. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_util.h"
#include "mf_test.h"

/* Columns of validation/result.csv (after the # comments and the header). */
typedef struct csv {
    size_t n, ncols;
    double *v; /* n x ncols */
} csv;

static bool read_csv(const char *dir, csv *c)
{
    char path[700], line[4096];
    snprintf(path, sizeof path, "%s/validation/result.csv", dir);
    FILE *f = fopen(path, "r");
    memset(c, 0, sizeof *c);
    if (!f)
        return false;
    bool header = false;
    size_t cap = 0;
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#')
            continue;
        if (!header) {
            header = true;
            c->ncols = 1;
            for (const char *s = line; *s; s++)
                c->ncols += *s == ',';
            continue;
        }
        if (c->n == cap) {
            cap = cap ? 2 * cap : 64;
            double *g = realloc(c->v, cap * c->ncols * sizeof *g);
            if (!g)
                break;
            c->v = g;
        }
        char *s = line;
        for (size_t k = 0; k < c->ncols; k++) {
            c->v[c->n * c->ncols + k] = strtod(s, &s);
            if (*s == ',')
                s++;
        }
        c->n++;
    }
    fclose(f);
    return c->n > 0;
}

static double at(const csv *c, size_t row, size_t col) { return c->v[row * c->ncols + col]; }

#define L0 "0.0015"

/* The number after `key` in the # comments of validation/result.csv. */
static double comment_number(const char *dir, const char *key)
{
    char path[700], line[4096];
    snprintf(path, sizeof path, "%s/validation/result.csv", dir);
    FILE *f = fopen(path, "r");
    double v = NAN;
    while (f && isnan(v) && fgets(line, sizeof line, f) && line[0] == '#') {
        const char *k = strstr(line, key);
        if (k)
            v = strtod(k + strlen(key), NULL);
    }
    if (f)
        fclose(f);
    return v;
}

/* Fluid particles of the last snapshot farther than `far` from their
 * centroid (shed), and the count of all. */
static void shed_particles(const char *dir, double far, size_t *shed, size_t *all)
{
    tc_snapshots s;
    *shed = *all = 0;
    if (tc_snapshots_list(dir, &s) != 0 || s.n == 0) {
        CHECK(!"snapshots listed");
        return;
    }
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    if (tc_snapshot_load(dir, s.index[s.n - 1], &sim, NULL) == 0) {
        const mf_particles *p = sim.p;
        double c[2] = {0, 0};
        for (size_t i = 0; i < p->n; i++)
            if (p->kind[i] == MF_FLUID) {
                c[0] += p->pos[3 * i];
                c[1] += p->pos[3 * i + 1];
                (*all)++;
            }
        for (int a = 0; a < 2 && *all; a++)
            c[a] /= (double)*all;
        for (size_t i = 0; i < p->n; i++)
            if (p->kind[i] == MF_FLUID &&
                hypot(p->pos[3 * i] - c[0], p->pos[3 * i + 1] - c[1]) > far)
                (*shed)++;
        tc_sim_free(&sim);
    } else {
        CHECK(!"last snapshot read");
    }
    tc_snapshots_free(&s);
}

static bool run_case(tc_case *c, const char *exe, const char *tutorials, const char *name,
                     const char *tag)
{
    char src[700];
    snprintf(src, sizeof src, "%s/%s", tutorials, name);
    if (tc_case_from_dir(c, exe, tag, src) != 0) {
        CHECK(!"case copied");
        return false;
    }
    int status = tc_case_run(c, NULL, (const char *const[]){"-l0", L0, "-quiet", NULL});
    CHECK_MSG(status == 0, "%s: mpsflow exited with %d", name, status);
    if (status == 0) {
        status = tc_case_run(c, "validate", NULL);
        CHECK_MSG(status == 0, "%s: mpsflow validate exited with %d", name, status);
    }
    if (status != 0)
        tc_case_log_tail(c, 20);
    return status == 0;
}

static void check_square(const char *exe, const char *tutorials)
{
    const double settle = 0.3;
    tc_case c;
    csv t;
    if (run_case(&c, exe, tutorials, "squareDroplet", "square") && read_csv(c.dir, &t)) {
        CHECK(t.ncols == 6);
        /* sigma/R of the metric: R from the area the particles fill */
        const double laplace = comment_number(c.dir, "sigma / R = ");
        double dp = 0;
        size_t used = 0;
        for (size_t r = 0; r < t.n; r++)
            if (at(&t, r, 0) >= settle) {
                dp += at(&t, r, 1);
                used++;
            }
        dp /= used ? (double)used : 1;
        double round0 = at(&t, 0, 4), round1 = at(&t, t.n - 1, 4);
        size_t shed = 0, all = 0;
        shed_particles(c.dir, 1.5 * 0.04 / sqrt(M_PI), &shed, &all);
        printf("squareDroplet (l0 = %s m): roundness %.3f -> %.3f; after t = %g s: p_in - p_out "
               "%.4g Pa, %.3f of sigma/R = %.4g Pa; %zu of %zu particles shed\n",
               L0, round0, round1, settle, dp, dp / laplace, laplace, shed, all);
        CHECK(round0 > 0.1);
        CHECK(round1 < 0.5 * round0);
        CHECK_MSG(fabs(dp / laplace - 1) <= 0.1, "pressure jump %.3f of sigma/R", dp / laplace);
        CHECK_MSG(shed < 0.02 * (double)all, "%zu of %zu particles shed", shed, all);
        free(t.v);
    }
    tc_case_destroy(&c);
}

/* The period from the zero crossings of column `col` (minus column `sub`,
 * if >= 0), as the metric takes them: 2 (t_last - t_first)/(n - 1). */
static double crossing_period(const csv *t, size_t col, int sub, int *n)
{
    double first = NAN, last = NAN;
    *n = 0;
    for (size_t r = 1; r < t->n; r++) {
        double a = at(t, r - 1, col) - (sub >= 0 ? at(t, r - 1, (size_t)sub) : 0);
        double b = at(t, r, col) - (sub >= 0 ? at(t, r, (size_t)sub) : 0);
        if ((a < 0 && b >= 0) || (a > 0 && b <= 0)) {
            double tc = at(t, r - 1, 0) + (at(t, r, 0) - at(t, r - 1, 0)) * (-a) / (b - a);
            if (*n == 0)
                first = tc;
            last = tc;
            (*n)++;
        }
    }
    return *n >= 2 ? 2 * (last - first) / (*n - 1) : NAN;
}

static void check_oscillation(const char *exe, const char *tutorials)
{
    const double sigma = 0.07, rho = 1000, R = 0.0222;
    const double period_ref = 2 * M_PI / sqrt(6 * sigma / (rho * R * R * R));
    tc_case c;
    csv t;
    if (run_case(&c, exe, tutorials, "dropletOscillation", "oscillation") &&
        read_csv(c.dir, &t)) {
        CHECK(t.ncols == 4);
        int n = 0, ne = 0;
        double period = crossing_period(&t, 1, -1, &n);
        double period_ext = crossing_period(&t, 2, 3, &ne);
        size_t shed = 0, all = 0;
        shed_particles(c.dir, 1.5 * R, &shed, &all);
        printf("dropletOscillation (l0 = %s m): period %.4g s from %d zero crossings of Q (%.4g "
               "s from %d of the extents), Rayleigh %.4g s: %+.1f%%; %zu of %zu particles "
               "shed\n",
               L0, period, n, period_ext, ne, period_ref, 100 * (period / period_ref - 1), shed,
               all);
        CHECK(n >= 4); /* two periods */
        CHECK_MSG(fabs(period / period_ref - 1) <= 0.1, "period %.4g s, Rayleigh %.4g s",
                  period, period_ref);
        CHECK_MSG(shed < 0.02 * (double)all, "%zu of %zu particles shed", shed, all);
        free(t.v);
    }
    tc_case_destroy(&c);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s MPSFLOW TUTORIALS\n", argv[0]);
        return EXIT_FAILURE;
    }
    check_square(argv[1], argv[2]);
    check_oscillation(argv[1], argv[2]);
    return mf_test_summary("surface_tension_drop");
}
