/* mafl_separation.c: moving points apart that came too close, part of the
 * reconfiguration (section 3.3).
 *
 * The reconfiguration may put a computation point anywhere (Premoze et al.
 * 2003, section 3.3: "the computation point r^{n+1} at the new time step is
 * determined arbitrarily"; Yoon, Koshizuka & Oka 1999), the Eulerian phase
 * then carrying the values there. With the MPS source (n* - n0)/n0 every
 * fluid point stands for l0^dim of fluid, so the other remedy for a close
 * pair, the merge at removeDistance (mafl_points.c), removes that volume:
 * on a resting box with a free surface (bench/cases/maflRestingBox) the
 * merges of pairs the noisy Lagrangian phase brings together took 23% of
 * the points in 2 s, the free surface falling with them (notes/mafl.md).
 * Moving the pair apart instead keeps the count and the volume.
 * d_s = 0.6 l0 by default: at 0.7 the row under the free surface stayed
 * pressed against the surface layer, its upward velocity undone by the
 * separation every step, until the run's watch stopped the box at l0 =
 * 0.02 (1.97 s); at 0.6 it completes 5 s.
 *
 * For every fluid point i at r^{n+1}, each neighbour j closer than
 * d_s = separation l0 gives (the pair's pure function below)
 *     dx_i = -share (d_s - |r_ij|) r_ij/|r_ij|,
 * share 1/2 for a fluid neighbour (both move: the pair ends at d_s) and 1
 * for a wall or dummy particle, which stays; inlet and outlet points are
 * left out (pushed from the inlet's points, the fluid left a gap that new
 * points filled: the channel of tests/test_mafl.c gained 3.2% instead of
 * 1.2% at d_s = 0.7 l0, fewer points leaving through the outlet). The sum is clamped
 * at MAX_SEPARATION l0 a step. All shifts are computed from the positions
 * before any is applied (order-independent, and parallel). */
#include <math.h>
#include <string.h>

#include "mafl.h"
#include "mf_error.h"

/* Largest separation shift of one step, in l0. */
#define MAX_SEPARATION 0.2

/* The shift of i away from j: r_ij = r_j - r_i at distance dist < d_s. */
static inline void pair_separation(const double r_ij[3], double dist, double d_s, double share,
                                   double dx[3])
{
    const double s = -share * (d_s - dist) / dist;
    for (int a = 0; a < 3; a++)
        dx[a] += s * r_ij[a];
}

typedef struct sep_ctx {
    size_t i;
    const int32_t *kind0;
    const double *xnew; /* r^{n+1} of every point */
    double d_s;
} sep_ctx;

/* The grid holds r^L; the pair's distance is taken at r^{n+1}, which is
 * within 0.4 l0 of r^L (less than the grid's cell of at least 1.5 l0 less
 * d_s). */
static inline bool separation_point(void *acc, const void *ctx, size_t j, const double r[3],
                                    double d2)
{
    (void)r;
    (void)d2;
    const sep_ctx *c = ctx;
    if (j == c->i || c->kind0[j] == MF_INLET || c->kind0[j] == MF_OUTLET)
        return true;
    const double *xi = &c->xnew[3 * c->i], *xj = &c->xnew[3 * j];
    const double r_ij[3] = {xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]};
    const double dist2 = r_ij[0] * r_ij[0] + r_ij[1] * r_ij[1] + r_ij[2] * r_ij[2];
    if (!(dist2 < c->d_s * c->d_s) || !(dist2 > 0))
        return true;
    const double share = c->kind0[j] == MF_FLUID ? 0.5 : 1.0;
    pair_separation(r_ij, sqrt(dist2), c->d_s, share, acc);
    return true;
}

int mafl_separate(mafl_data *d, mf_sim *sim, double *shift)
{
    const mf_particles *p = sim->p;
    const long n = (long)p->n;
    const int32_t *kind0 = mf_particles_fi(p, d->f_kind);
    const double l0 = sim->l0, limit = MAX_SEPARATION * l0;
    const double *xl = d->pos_l;
    double *xnew = d->pos_new;
    size_t moved = 0;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : moved)
    for (long i = 0; i < n; i++) {
        double *dx = &shift[3 * i];
        memset(dx, 0, 3 * sizeof *dx);
        if (kind0[i] != MF_FLUID)
            continue;
        const sep_ctx c = {(size_t)i, kind0, xnew, d->s.separation * l0};
        mf_grid_near(d->grid, &xl[3 * i], separation_point, &c, dx);
        if (sim->dim == 2)
            dx[2] = 0;
        double len = sqrt(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
        if (len > limit)
            for (int a = 0; a < 3; a++)
                dx[a] *= limit / len;
        moved += len > 0;
    }
    for (long i = 0; i < n; i++)
        for (int a = 0; a < 3; a++)
            xnew[3 * i + a] += shift[3 * i + a];
    d->last_separated = moved;
    return 0;
}
