/* test_wall_lsmps.c: the least-squares Laplacian (LSMPS, Tamai & Koshizuka
 * 2014) with a plane wall's virtual points in each fit (mf_lsmps.h's extra
 * points, on the lattice of mf_wall_points_each), as `wall wallWeight;
 * laplacian leastSquares;` takes it (solvers/solver/mps/mps_wall.c).
 *
 * A wall at y = 0 (a tank with only its ymin face closed) and a few layers
 * of fluid particles on the lattice above it, their first layer l0/2 from
 * the face (2-D and 3-D):
 *   1. a quadratic field, the virtual points carrying its values: the
 *      Laplacian is exact at every particle (first layer included); with
 *      two layers of fluid and no wall points the fit is singular (every
 *      neighbour within one l0 in y: y and y^2 cannot be told apart), so
 *      the wall points are what makes it exact;
 *   2. a shear flow u = u_w + G y (Couette's), the virtual points carrying
 *      the solver's no-slip rule (mf_wall_noslip_factor: u_v = u_w -
 *      (s/d)(u_i - u_w)): the Laplacian is zero to round-off; with u_v = u_w
 *      (the wall's velocity itself) it is not;
 *   3. a box obstacle in a block of fluid on the lattice: the signed points
 *      of its faces, edges and corners (the box's expansion, walls_sums.c)
 *      add up, moment by moment (w, w r, w r r^T), to the box's own lattice
 *      points within re, the particle wall they stand for (a sign or an
 *      axis wrong fails here: measured, all signs +1 gives 0.68); and the
 *      quadratic field on them gives the exact Laplacian at every particle
 *      beside the box, corners included (that any points carrying the
 *      field's own values give, where the fit is regular: it checks the
 *      fits' regularity and the points' way into them, not the geometry).
 * The box is 2 l0 wide, so that its far faces' terms reach the particles. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_kernel.h"
#include "mf_lsmps.h"
#include "mf_neighbours.h"
#include "mf_test.h"
#include "mf_wall_terms.h"
#include "mf_walls.h"

#define L0 0.01
#define RE (3.1 * L0)
#define NX 16 /* particles along each free axis */

/* The quadratic field (3 components) and its Laplacian. */
static void quad(const double x[3], double u[3])
{
    u[0] = 0.3 + 2.0 * x[1] - 40.0 * x[1] * x[1] + 5.0 * x[0] * x[0] - 7.0 * x[0] * x[1] +
           3.0 * x[2] * x[2];
    u[1] = -1.0 + x[0] + 11.0 * x[1] * x[1] - 2.0 * x[1] * x[2];
    u[2] = 4.0 * x[0] * x[2] - 9.0 * x[2] * x[2];
}

static void quad_lap(int dim, double lap[3])
{
    lap[0] = 2.0 * (5.0 - 40.0) + (dim == 3 ? 6.0 : 0.0);
    lap[1] = 22.0;
    lap[2] = dim == 3 ? -18.0 : 0.0;
}

#define U_W 0.02
#define SHEAR 1.5

static void shear(const double x[3], double u[3])
{
    u[0] = U_W + SHEAR * x[1];
    u[1] = u[2] = 0;
}

enum { VALUES_FIELD, VALUES_NOSLIP, VALUES_WALL_VELOCITY };

typedef struct wall_ctx {
    const mf_wall *wall;
    const mf_wall_tables *tables;
    const mf_particles *p;
    const double *u;
    int dim, values;
    bool quadratic;
} wall_ctx;

typedef struct point_ctx {
    const wall_ctx *w;
    const double *x, *ui;
    mf_lsmps_point_fn add;
    void *acc;
} point_ctx;

static void point(void *ctx, const double r[3], double depth, double dist, double sign)
{
    const point_ctx *pc = ctx;
    double df[3];
    if (pc->w->values == VALUES_FIELD) {
        const double xv[3] = {pc->x[0] + r[0], pc->x[1] + r[1], pc->x[2] + r[2]};
        double uv[3];
        (pc->w->quadratic ? quad : shear)(xv, uv);
        for (int a = 0; a < 3; a++)
            df[a] = uv[a] - pc->ui[a];
    } else {
        const double phi = pc->w->values == VALUES_NOSLIP
                               ? mf_wall_noslip_factor(depth, dist, 0.25 * L0)
                               : 1.0;
        const double uw[3] = {U_W, 0, 0};
        for (int a = 0; a < 3; a++)
            df[a] = phi * (uw[a] - pc->ui[a]);
    }
    pc->add(pc->acc, r, df, sign);
}

static void extra(const void *ctx, size_t i, mf_lsmps_point_fn add, void *acc)
{
    const wall_ctx *w = ctx;
    point_ctx pc = {w, &w->p->pos[3 * i], &w->u[3 * i], add, acc};
    mf_wall_points_each(w->wall, w->tables, w->dim, L0, RE, pc.x, point, &pc);
}

static void count_point(void *ctx, const double r[3], double depth, double dist, double sign)
{
    (void)r, (void)depth, (void)dist, (void)sign;
    (*(size_t *)ctx)++;
}

/* layers of fluid above the wall; the largest error of <lap u> over the
 * particles at least re from the free axes' ends (into *err) and the number
 * of failed fits among them. */
static size_t run(int dim, int layers, bool quadratic, int values, bool with_wall, double *err)
{
    mf_particles *p = NULL;
    CHECK_OK(mf_particles_create(dim, 1024, &p));
    const int nz = dim == 3 ? NX : 1;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < layers; j++)
            for (int i = 0; i < NX; i++) {
                const double x[3] = {i * L0, (j + 0.5) * L0, dim == 3 ? k * L0 : 0};
                const double v[3] = {0, 0, 0};
                mf_particles_add(p, MF_FLUID, x, v, NULL);
            }
    const size_t n = p->n;
    double *u = malloc(3 * n * sizeof *u), *out = calloc(3 * n, sizeof *out);
    uint8_t *failed = calloc(n, 1);
    for (size_t i = 0; i < n; i++)
        (quadratic ? quad : shear)(&p->pos[3 * i], &u[3 * i]);
    mf_kernel k;
    CHECK_OK(mf_kernel_init(&k, dim, L0, RE));
    mf_wall_tables *t = NULL;
    CHECK_OK(mf_wall_tables_create(dim, L0, 2.1 * L0, 2.1 * L0, RE, &t));
    mf_wall tank;
    memset(&tank, 0, sizeof tank);
    tank.shape = MF_SOLID_TANK;
    tank.dim = dim;
    tank.min[0] = tank.min[2] = -1;
    tank.max[0] = tank.max[1] = tank.max[2] = 1;
    tank.open[0][0] = tank.open[0][1] = tank.open[1][1] = true;
    tank.open[2][0] = tank.open[2][1] = true;
    mf_motion_state(&tank.motion, 0, &tank.state);
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    CHECK_OK(mf_grid_build(&g, p, RE));
    CHECK_OK(mf_nlist_build(&nl, &g, p, RE));
    const mf_pairs v = mf_pairs_of_list(p, &nl, RE);
    /* a plane-faced solid gives its points (extra() runs on the engine's
     * threads, where CHECK's counter is not safe) */
    size_t npts = 0;
    CHECK(mf_wall_points_each(&tank, t, dim, L0, RE, &p->pos[0], count_point, &npts));
    CHECK(npts > 0);
    const wall_ctx w = {&tank, t, p, u, dim, values, quadratic};
    mf_lsmps_laplacian_add_extra(&v, &k, u, 1.0, NULL, NULL, with_wall ? extra : NULL, &w, out,
                                 failed);
    double lap[3] = {0, 0, 0};
    if (quadratic)
        quad_lap(dim, lap);
    const double scale = quadratic ? 80.0 : SHEAR / L0; /* the largest second derivative */
    size_t nfailed = 0;
    *err = 0;
    for (size_t i = 0; i < n; i++) {
        const double *x = &p->pos[3 * i];
        bool inner = x[0] > RE && x[0] < (NX - 1) * L0 - RE;
        if (dim == 3)
            inner = inner && x[2] > RE && x[2] < (NX - 1) * L0 - RE;
        if (!inner)
            continue;
        if (failed[i]) {
            nfailed++;
            continue;
        }
        for (int a = 0; a < dim; a++)
            *err = fmax(*err, fabs(out[3 * i + a] - lap[a]) / scale);
    }
    mf_grid_free(&g);
    mf_nlist_free(&nl);
    mf_wall_tables_destroy(t);
    mf_particles_destroy(p);
    free(u);
    free(out);
    free(failed);
    return nfailed;
}

/* The moments sum sign w(|r|) (1, r, r r^T) of a point set (case 3). */
typedef struct moments {
    double m[13];
} moments;

static void moments_add(moments *mo, const double r[3], double sign)
{
    const double len = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    const double w = sign * mf_weight_ls(len, RE);
    mo->m[0] += w;
    for (int a = 0; a < 3; a++) {
        mo->m[1 + a] += w * r[a] / L0;
        for (int b = 0; b < 3; b++)
            mo->m[4 + 3 * a + b] += w * r[a] * r[b] / (L0 * L0);
    }
}

static void moment_point(void *ctx, const double r[3], double depth, double dist, double sign)
{
    (void)depth, (void)dist;
    moments_add(ctx, r, sign);
}

/* Case 3: a box obstacle [0.05, 0.07]^dim in a block of fluid on the
 * lattice (i + 1/2) l0, i = 0..13; the largest error at the particles
 * within 2.5 l0 of the box and re inside the block, and the number of
 * failed fits there. */
static size_t run_box(int dim, double *err, size_t *counted)
{
    const double lo = 0.05, hi = 0.07; /* 2 l0 wide: its far faces within reach */
    mf_particles *p = NULL;
    CHECK_OK(mf_particles_create(dim, 4096, &p));
    const int m = 14, nz = dim == 3 ? m : 1;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < m; j++)
            for (int i = 0; i < m; i++) {
                const double x[3] = {(i + 0.5) * L0, (j + 0.5) * L0,
                                     dim == 3 ? (k + 0.5) * L0 : 0};
                bool inside = true;
                for (int a = 0; a < dim; a++)
                    inside = inside && x[a] > lo && x[a] < hi;
                const double v[3] = {0, 0, 0};
                if (!inside)
                    mf_particles_add(p, MF_FLUID, x, v, NULL);
            }
    const size_t n = p->n;
    double *u = malloc(3 * n * sizeof *u), *out = calloc(3 * n, sizeof *out);
    uint8_t *failed = calloc(n, 1);
    for (size_t i = 0; i < n; i++)
        quad(&p->pos[3 * i], &u[3 * i]);
    mf_kernel k;
    CHECK_OK(mf_kernel_init(&k, dim, L0, RE));
    mf_wall_tables *t = NULL;
    CHECK_OK(mf_wall_tables_create(dim, L0, 2.1 * L0, 2.1 * L0, RE, &t));
    mf_wall box;
    memset(&box, 0, sizeof box);
    box.shape = MF_SOLID_BOX;
    box.dim = dim;
    box.obstacle = true;
    for (int a = 0; a < dim; a++) {
        box.min[a] = lo;
        box.max[a] = hi;
    }
    mf_motion_state(&box.motion, 0, &box.state);
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    CHECK_OK(mf_grid_build(&g, p, RE));
    CHECK_OK(mf_nlist_build(&nl, &g, p, RE));
    const mf_pairs v = mf_pairs_of_list(p, &nl, RE);
    /* the signed points against the box's lattice, at every particle */
    double worst_m = 0;
    const int nb = (int)lround((hi - lo) / L0), nbz = dim == 3 ? nb : 1;
    for (size_t i = 0; i < n; i++) {
        const double *x = &p->pos[3 * i];
        moments got = {{0}}, want = {{0}};
        mf_wall_points_each(&box, t, dim, L0, RE, x, moment_point, &got);
        for (int kk = 0; kk < nbz; kk++)
            for (int jj = 0; jj < nb; jj++)
                for (int ii = 0; ii < nb; ii++) {
                    const double y[3] = {lo + (ii + 0.5) * L0, lo + (jj + 0.5) * L0,
                                         dim == 3 ? lo + (kk + 0.5) * L0 : 0};
                    const double r[3] = {y[0] - x[0], y[1] - x[1], y[2] - x[2]};
                    moments_add(&want, r, 1.0);
                }
        for (int q = 0; q < 13; q++)
            worst_m = fmax(worst_m, fabs(got.m[q] - want.m[q]));
    }
    printf("%d-D box obstacle: the signed points' moments against the box's lattice, largest "
           "difference %.2e\n", dim, worst_m);
    CHECK_MSG(worst_m < 1e-12, "%d-D box: the points' moments differ by %g", dim, worst_m);
    const wall_ctx w = {&box, t, p, u, dim, VALUES_FIELD, true};
    mf_lsmps_laplacian_add_extra(&v, &k, u, 1.0, NULL, NULL, extra, &w, out, failed);
    double lap[3];
    quad_lap(dim, lap);
    size_t nfailed = 0;
    *err = 0;
    *counted = 0;
    for (size_t i = 0; i < n; i++) {
        const double *x = &p->pos[3 * i];
        bool near = mf_wall_distance(&box, x, NULL) < 2.5 * L0, inner = true;
        for (int a = 0; a < dim; a++)
            inner = inner && x[a] > RE && x[a] < m * L0 - RE;
        if (!near || !inner)
            continue;
        (*counted)++;
        if (failed[i]) {
            nfailed++;
            continue;
        }
        for (int a = 0; a < dim; a++)
            *err = fmax(*err, fabs(out[3 * i + a] - lap[a]) / 80.0);
    }
    mf_grid_free(&g);
    mf_nlist_free(&nl);
    mf_wall_tables_destroy(t);
    mf_particles_destroy(p);
    free(u);
    free(out);
    free(failed);
    return nfailed;
}

int main(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        double e;
        size_t nf = run(dim, 6, true, VALUES_FIELD, true, &e);
        printf("%d-D, 6 layers, quadratic field on the wall points: %zu failed, max error "
               "%.2e\n", dim, nf, e);
        CHECK(nf == 0);
        CHECK_MSG(e < 1e-9, "%d-D quadratic, 6 layers: %g", dim, e);
        nf = run(dim, 2, true, VALUES_FIELD, true, &e);
        printf("%d-D, 2 layers, quadratic field on the wall points: %zu failed, max error "
               "%.2e\n", dim, nf, e);
        CHECK(nf == 0);
        CHECK_MSG(e < 1e-9, "%d-D quadratic, 2 layers: %g", dim, e);
        nf = run(dim, 2, true, VALUES_FIELD, false, &e);
        printf("%d-D, 2 layers, no wall points: %zu failed\n", dim, nf);
        CHECK_MSG(nf > 0 || e > 1e-3, "%d-D: two layers without the wall fit (error %g)", dim,
                  e);
        nf = run(dim, 6, false, VALUES_NOSLIP, true, &e);
        printf("%d-D, shear flow, no-slip rule: %zu failed, max error %.2e\n", dim, nf, e);
        CHECK(nf == 0);
        CHECK_MSG(e < 1e-9, "%d-D shear, no-slip rule: %g", dim, e);
        double ew;
        nf = run(dim, 6, false, VALUES_WALL_VELOCITY, true, &ew);
        printf("%d-D, shear flow, u_v = u_w: %zu failed, max error %.2e\n", dim, nf, ew);
        CHECK_MSG(ew > 1e-2, "%d-D shear, u_v = u_w is exact (%g): the test sees nothing",
                  dim, ew);
    }
    for (int dim = 2; dim <= 3; dim++) {
        double e;
        size_t counted;
        const size_t nf = run_box(dim, &e, &counted);
        printf("%d-D box obstacle, quadratic field on its faces', edges' and corners' points: "
               "%zu particles beside it, %zu failed, max error %.2e\n", dim, counted, nf, e);
        CHECK(counted > 0);
        CHECK(nf == 0);
        CHECK_MSG(e < 1e-9, "%d-D box obstacle: %g", dim, e);
    }
    return mf_test_summary("wall_lsmps");
}
