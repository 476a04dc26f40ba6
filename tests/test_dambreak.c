/* test_dambreak.c: the damBreak2D tutorial at its own (coarse) resolution
 * against Martin & Moyce (1952).
 *
 * The tutorial is copied to a temporary folder and run to t = 0.35 s
 * (T = t sqrt(2 g / a) = 3.1) with snapshots every 0.01 s. The surge front
 * is computed as driver/post/metric_surge_front.c computes it: the largest x
 * (from the back wall) of a fluid particle with at least two fluid
 * neighbours within 2.1 l0; Z = x / a, linear in time between snapshots.
 * At T = 1.5 and 2.5, |Z - Z_ref| <= 0.3, Z_ref interpolated linearly in
 * the experiment's table. `mpsflow validate` must agree with these fronts.
 *
 * argv[1]: the mpsflow executable; argv[2]: tutorials/damBreak2D. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_util.h"
#include "mf_alloc.h"
#include "mf_dictio.h"
#include "mf_pairs.h"
#include "mf_test.h"

#define END_TIME 0.35
#define TOLERANCE 0.3

typedef struct series {
    double *x, *y;
    size_t n, cap;
} series;

static void series_add(series *s, double x, double y)
{
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 64;
        if (mf_resize(&s->x, s->cap, sizeof *s->x) || mf_resize(&s->y, s->cap, sizeof *s->y))
            abort();
    }
    s->x[s->n] = x;
    s->y[s->n] = y;
    s->n++;
}

static void series_free(series *s)
{
    free(s->x);
    free(s->y);
    memset(s, 0, sizeof *s);
}

/* y(xq) by linear interpolation on ascending x; NAN outside. */
static double interp(const series *s, double xq)
{
    if (s->n == 0 || xq < s->x[0] || xq > s->x[s->n - 1])
        return NAN;
    for (size_t i = 1; i < s->n; i++)
        if (xq <= s->x[i]) {
            double t = s->x[i] > s->x[i - 1] ? (xq - s->x[i - 1]) / (s->x[i] - s->x[i - 1]) : 0;
            return s->y[i - 1] + t * (s->y[i] - s->y[i - 1]);
        }
    return s->y[s->n - 1];
}

/* A CSV of numbers: '#' comments, one header line, then "a,b[,c...]"; reads columns
 * ca and cb. */
static int read_csv(const char *path, int ca, int cb, series *s)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "cannot open %s\n", path);
        return -1;
    }
    char line[1024];
    bool header = false;
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#' || line[0] == '\n')
            continue;
        if (!header) {
            header = true;
            continue;
        }
        double v[8];
        int nv = 0;
        char *p = line, *end;
        while (nv < 8) {
            v[nv] = strtod(p, &end);
            if (end == p)
                break;
            nv++;
            p = end;
            if (*p == ',')
                p++;
            else
                break;
        }
        if (nv > ca && nv > cb)
            series_add(s, v[ca], v[cb]);
    }
    fclose(f);
    return s->n > 0 ? 0 : -1;
}

/* Counts a particle's neighbours. */
static inline bool count_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    (void)ctx;
    (void)pr;
    ++*(size_t *)acc;
    return true;
}

/* The front of one snapshot, as metric_surge_front.c: m from the back wall. */
static double front_of(const mf_particles *all, double l0, double back_wall, size_t *counted)
{
    mf_particles *fluid = NULL;
    if (mf_particles_create(all->dim, all->n, &fluid) != 0)
        return NAN;
    for (size_t i = 0; i < all->n; i++)
        if (all->kind[i] == MF_FLUID)
            mf_particles_add(fluid, MF_FLUID, &all->pos[3 * i], &all->vel[3 * i], NULL);
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    const double radius = 2.1 * l0;
    double z = 0;
    *counted = 0;
    if (fluid->n > 0 && mf_grid_build(&g, fluid, radius) == 0 &&
        mf_nlist_build(&nl, &g, fluid, radius) == 0) {
        const mf_pairs v = mf_pairs_of_list(fluid, &nl, radius);
        for (size_t i = 0; i < fluid->n; i++) {
            size_t count = 0;
            mf_pairs_row_r2(&v, i, NULL, count_pair, NULL, &count);
            if (count >= 2) {
                (*counted)++;
                if (fluid->pos[3 * i] - back_wall > z)
                    z = fluid->pos[3 * i] - back_wall;
            }
        }
    } else {
        mf_error_print(stderr);
        z = NAN;
    }
    mf_grid_free(&g);
    mf_nlist_free(&nl);
    mf_particles_destroy(fluid);
    return z;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s MPSFLOW TUTORIAL_DIR\n", argv[0]);
        return EXIT_FAILURE;
    }
    tc_case c;
    if (tc_case_from_dir(&c, argv[1], "dambreak", argv[2]) != 0) {
        tc_case_destroy(&c);
        return EXIT_FAILURE;
    }
    /* The metric's settings, from the tutorial's validation/metric. */
    char path[800];
    snprintf(path, sizeof path, "%s/%s", c.dir, TC_METRIC);
    mf_dict *md = NULL;
    double a = 0, back_wall = 0, g = 9.81;
    const char *reference = NULL;
    CHECK_OK(mf_dict_parse_file(path, &md));
    if (md) {
        CHECK_OK(mf_dict_get_number(md, "columnWidth", &a));
        CHECK_OK(mf_dict_get_number_or(md, "backWall", 0, &back_wall));
        CHECK_OK(mf_dict_get_number_or(md, "gravity", 9.81, &g));
        CHECK_OK(mf_dict_get_word(md, "reference", &reference));
    }
    series ref = {0};
    if (reference) {
        snprintf(path, sizeof path, "%s/validation/%s", c.dir, reference);
        CHECK(read_csv(path, 0, 1, &ref) == 0);
    }
    mf_dict_free(md);
    if (!(a > 0) || ref.n < 2) {
        CHECK(!"metric settings and reference read");
        tc_case_destroy(&c);
        return mf_test_summary("dambreak");
    }

    char end_time[32];
    snprintf(end_time, sizeof end_time, "%.17g", END_TIME);
    int status = tc_case_run(&c, NULL, (const char *const[]){"-endTime", end_time, "-quiet", NULL});
    const double tscale = sqrt(2 * g / a);
    printf("dambreak: damBreak2D to t = %g s (T = %.2f): exit %d, %.1f s wall\n", END_TIME,
           END_TIME * tscale, status, c.last_wall);
    CHECK_MSG(status == 0, "mpsflow exited with %d", status);
    if (status != 0)
        tc_case_log_tail(&c, 25);

    /* Z(T) from every snapshot. */
    tc_snapshots snaps;
    CHECK_OK(tc_snapshots_list(c.dir, &snaps));
    series run = {0};
    double l0 = 0, last_dt_write = 0, prev_t = -1;
    for (size_t k = 0; k < snaps.n; k++) {
        mf_sim snap;
        mf_hdf5_header h;
        if (tc_snapshot_load(c.dir, snaps.index[k], &snap, &h) != 0) {
            CHECK(!"snapshot readable");
            continue;
        }
        l0 = h.l0;
        size_t counted = 0;
        double z = front_of(snap.p, h.l0, back_wall, &counted);
        CHECK(isfinite(z));
        if (run.n == 0 || h.time * tscale > run.x[run.n - 1])
            series_add(&run, h.time * tscale, z / a);
        if (prev_t >= 0 && h.time - prev_t > last_dt_write)
            last_dt_write = h.time - prev_t;
        prev_t = h.time;
        tc_sim_free(&snap);
    }
    printf("dambreak: %zu snapshots at l0 = %g m (at most %.3g s apart), last T = %.3f\n",
           snaps.n, l0, last_dt_write, run.n ? run.x[run.n - 1] : 0.0);
    CHECK(snaps.n >= 30);
    CHECK(last_dt_write <= 0.01 + 1e-9);

    const double Tq[2] = {1.5, 2.5};
    for (int q = 0; q < 2; q++) {
        double zsim = interp(&run, Tq[q]), zref = interp(&ref, Tq[q]);
        printf("dambreak: T = %.2f: Z = %.4f (mpsflow), %.4f (Martin & Moyce), difference %+.4f "
               "(tolerance %.2f)\n",
               Tq[q], zsim, zref, zsim - zref, TOLERANCE);
        CHECK_MSG(fabs(zsim - zref) <= TOLERANCE, "front at T = %.2f: Z = %.4f, reference %.4f",
                  Tq[q], zsim, zref);
    }

    /* `mpsflow validate` computes the same fronts: its Z at the reference times. */
    status = tc_case_run(&c, "validate", NULL);
    CHECK_MSG(status == 0, "mpsflow validate exited with %d", status);
    series vz = {0};
    snprintf(path, sizeof path, "%s/validation/result.csv", c.dir);
    if (status == 0 && read_csv(path, 0, 2, &vz) == 0) {
        int compared = 0;
        double worst = 0;
        for (size_t i = 0; i < vz.n; i++) {
            double mine = interp(&run, vz.x[i]);
            if (isnan(mine) && isnan(vz.y[i]))
                continue;
            compared++;
            if (!(fabs(mine - vz.y[i]) <= worst))
                worst = fabs(mine - vz.y[i]);
        }
        printf("dambreak: validate's Z at %d reference times agrees with this test's within "
               "%.2g\n",
               compared, worst);
        CHECK(compared >= 4);
        CHECK(worst <= 1e-6);
    } else {
        tc_case_log_tail(&c, 10);
        CHECK(!"validation/result.csv readable");
    }
    series_free(&vz);
    series_free(&run);
    series_free(&ref);
    tc_snapshots_free(&snaps);
    tc_case_destroy(&c);
    return mf_test_summary("dambreak");
}
