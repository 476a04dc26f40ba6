/* ls_rhs.c: the right-hand side of eq. 29 at the active band points,
 *
 *     phi_tau = alpha F_ext |grad phi|_upwind + beta' H |grad phi|_central
 *
 * - F_ext is F at the closest point of the zero level, x - phi grad phi /
 *   |grad phi|^2 (trilinear in F): the speed is extended off the zero level
 *   along the normals, as in a sparse-field method, so the other level sets
 *   move with it and phi stays close to a distance. Without the extension
 *   every level set would settle on F = 0 and phi would steepen into a step.
 * - |grad phi|_upwind: Godunov's first-order upwind scheme (Osher & Sethian
 *   1988) for phi_t = V |grad phi|; for V > 0 the front moves outward and
 *   takes its information from inside.
 * - H: the mean curvature, half the divergence of grad phi / |grad phi|, by
 *   central differences (the 18-point stencil), clamped to a radius of one
 *   cell; beta' = beta l0 / h makes it dimensionless with the particle
 *   spacing (grid units inside).
 * Each brick is copied with a one-point halo into a 10^3 block first, so the
 * stencils are plain offsets. */
#include <math.h>
#include <stdlib.h>

#include "levelset.h"

#define P 10
#define PI(i, j, k) ((i) + 1 + P * ((j) + 1 + P * ((k) + 1)))
/* F is padded with a halo of FH points: the closest point of a band point
 * (|phi| <= width <= FH - 1 cells away) and its interpolation cell are in it. */
#define FH 4
#define FP (LS_B + 2 * FH)
#define FPI(i, j, k) ((i) + FH + FP * ((j) + FH + FP * ((k) + FH)))
#ifndef CURV_BOUND
#define CURV_BOUND 3.0
#endif
#define MIN(a, b) ((a) < (b) ? (a) : (b))
#define MAX(a, b) ((a) > (b) ? (a) : (b))

/* Persistent padded copies: every brick with active points gets a 10^3
 * block (the brick and a one-point halo) filled once per band with the
 * frozen values; each evaluation only scatters the active values to the
 * places they occupy (their own block, and the halos of up to 7
 * neighbours), so the stencils read plain offsets. */
static double pad_value(const ls_band *band, int32_t b, int i, int j, int k)
{
    int dbx = i < 0 ? -1 : (i >= LS_B ? 1 : 0), dby = j < 0 ? -1 : (j >= LS_B ? 1 : 0),
        dbz = k < 0 ? -1 : (k >= LS_B ? 1 : 0);
    int32_t nbk = band->nb[27 * b + (dbx + 1) + 3 * (dby + 1) + 9 * (dbz + 1)];
    if (nbk == LS_NONE)
        return NAN;
    size_t o = (size_t)nbk * LS_B3 + ls_local_index(i & 7, j & 7, k & 7);
    return (band->flag[o] & LS_HAS_PHI) ? band->phi[o] : NAN;
}

int ls_rhs_setup(ls_rhs *r)
{
    const ls_band *band = r->band;
    const size_t nb = band->b.n, na = band->nact;
    r->bstart = malloc((nb + 1) * sizeof *r->bstart);
    r->padof = malloc((nb ? nb : 1) * sizeof *r->padof);
    r->slot_start = malloc((na + 1) * sizeof *r->slot_start);
    if (!r->bstart || !r->padof || !r->slot_start)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the band's stencils");
    size_t a = 0, npad = 0;
    for (size_t b = 0; b <= nb; b++) {
        while (a < na && band->act[a] / LS_B3 < b)
            a++;
        r->bstart[b] = a;
        if (b > 0)
            r->padof[b - 1] = r->bstart[b] > r->bstart[b - 1] ? (int32_t)npad++ : LS_NONE;
    }
    if (npad > (size_t)UINT32_MAX / (P * P * P))
        return MF_ERROR(MF_ERR_MEMORY, "too many band bricks (%zu)", npad);
    r->npad = npad;
    r->pad = malloc((npad ? npad : 1) * P * P * P * sizeof *r->pad);
    if (!r->pad)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu padded bricks (%.1f MB)", npad,
                        npad * P * P * P * 8.0 / 1048576.0);
    r->Fpad = malloc((npad ? npad : 1) * FP * FP * FP * sizeof *r->Fpad);
    if (!r->Fpad)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu padded bricks of F (%.1f MB)", npad,
                        npad * FP * FP * FP * 4.0 / 1048576.0);
    /* the frozen values, and F */
#pragma omp parallel for schedule(dynamic, 8)
    for (size_t b = 0; b < nb; b++) {
        if (r->padof[b] == LS_NONE)
            continue;
        double *pad = r->pad + (size_t)r->padof[b] * P * P * P;
        for (int k = -1; k <= LS_B; k++)
            for (int j = -1; j <= LS_B; j++)
                for (int i = -1; i <= LS_B; i++)
                    pad[PI(i, j, k)] = pad_value(band, (int32_t)b, i, j, k);
        float *fp = r->Fpad + (size_t)r->padof[b] * FP * FP * FP;
        for (int k = -FH; k < LS_B + FH; k++)
            for (int j = -FH; j < LS_B + FH; j++)
                for (int i = -FH; i < LS_B + FH; i++) {
                    int dbx = i < 0 ? -1 : (i >= LS_B ? 1 : 0), dby = j < 0 ? -1 : (j >= LS_B ? 1 : 0),
                        dbz = k < 0 ? -1 : (k >= LS_B ? 1 : 0);
                    int32_t nbk = band->nb[27 * b + (dbx + 1) + 3 * (dby + 1) + 9 * (dbz + 1)];
                    float v = (float)r->far_F; /* beyond the band: no particle reaches */
                    if (nbk != LS_NONE) {
                        size_t o = (size_t)nbk * LS_B3 + ls_local_index(i & 7, j & 7, k & 7);
                        if (band->flag[o] & LS_HAS_F)
                            v = band->F[o];
                    }
                    fp[FPI(i, j, k)] = v;
                }
    }
    /* points whose stencil reaches past the rim */
    r->edge = malloc((na ? na : 1) * sizeof *r->edge);
    if (!r->edge)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the band's stencils");
#pragma omp parallel for schedule(dynamic, 4096)
    for (size_t q = 0; q < na; q++) {
        const int32_t b = (int32_t)(band->act[q] / LS_B3);
        const int l = (int)(band->act[q] % LS_B3);
        const double *c = r->pad + (size_t)r->padof[b] * P * P * P + PI(l & 7, (l >> 3) & 7, l >> 6);
        bool e = false;
        for (int dk = -1; dk <= 1; dk++)
            for (int dj = -1; dj <= 1; dj++)
                for (int di = -1; di <= 1; di++)
                    e = e || isnan(c[di + P * (dj + P * dk)]);
        r->edge[q] = e;
    }
    /* where each active value goes */
    r->slot_start[0] = 0;
    for (size_t q = 0; q < na; q++) {
        const int l = (int)(band->act[q] % LS_B3);
        const int i = l & 7, j = (l >> 3) & 7, k = l >> 6;
        int nx = 1 + (i == 0 || i == 7), ny = 1 + (j == 0 || j == 7), nz = 1 + (k == 0 || k == 7);
        r->slot_start[q + 1] = r->slot_start[q] + (size_t)(nx * ny * nz);
    }
    r->slot = malloc((r->slot_start[na] ? r->slot_start[na] : 1) * sizeof *r->slot);
    if (!r->slot)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the band's stencils");
#pragma omp parallel for schedule(dynamic, 4096)
    for (size_t q = 0; q < na; q++) {
        const int32_t b = (int32_t)(band->act[q] / LS_B3);
        const int l = (int)(band->act[q] % LS_B3);
        const int i = l & 7, j = (l >> 3) & 7, k = l >> 6;
        size_t s0 = r->slot_start[q], m = 0;
        for (int dz = -1; dz <= 1; dz++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    /* the point seen from brick b + d: inside [-1, 8]? */
                    int ii = i - LS_B * dx, jj = j - LS_B * dy, kk = k - LS_B * dz;
                    if (ii < -1 || ii > LS_B || jj < -1 || jj > LS_B || kk < -1 || kk > LS_B)
                        continue;
                    int32_t nbk = band->nb[27 * b + (dx + 1) + 3 * (dy + 1) + 9 * (dz + 1)];
                    uint32_t slot = UINT32_MAX; /* a neighbour without a block */
                    if (nbk != LS_NONE && r->padof[nbk] != LS_NONE)
                        slot = (uint32_t)r->padof[nbk] * P * P * P + (uint32_t)PI(ii, jj, kk);
                    r->slot[s0 + m++] = slot;
                }
    }
    return 0;
}

void ls_rhs_free(ls_rhs *r)
{
    free(r->bstart);
    free(r->padof);
    free(r->slot_start);
    free(r->slot);
    free(r->pad);
    free(r->Fpad);
    free(r->pn);
    free(r->zpad);
    free(r->edge);
    r->edge = NULL;
    r->Fpad = NULL;
    r->pn = NULL;
    r->zpad = NULL;
    r->bstart = r->slot_start = NULL;
    r->padof = NULL;
    r->slot = NULL;
    r->pad = NULL;
}

static void scatter(ls_rhs *r, const double *y)
{
    const size_t na = r->band->nact;
    /* dynamic (here and in the set-up): on a shared machine a thread that
     * is descheduled with a static half of the loop holds up the barrier;
     * at load 4.6 a frame took 17 s wall with 2 threads and 7.6 s with 1 */
#pragma omp parallel for schedule(dynamic, 4096)
    for (size_t q = 0; q < na; q++)
        for (size_t s = r->slot_start[q]; s < r->slot_start[q + 1]; s++)
            if (r->slot[s] != UINT32_MAX)
                r->pad[r->slot[s]] = y[q];
}

static inline double sq(double x) { return x * x; }

/* dphi/dtau at one point; c points at it in its padded block. `checked`:
 * some stencil neighbour lies beyond the band's rim (NaN in the block) and
 * takes the sign of the point with the rim's value. */
static inline double point_rhs(const double *c, const float *fc, double alpha, double beta,
                               int parts, bool checked, double fallback, double *fabs_out)
{
    const double p0 = c[0];
    const double fb = copysign(fallback, p0);
#define V(di, dj, dk)                                                                      \
    (checked && isnan(c[(di) + P * ((dj) + P * (dk))]) ? fb : c[(di) + P * ((dj) + P * (dk))])
    const double xm = V(-1, 0, 0), xp = V(1, 0, 0), ym = V(0, -1, 0), yp = V(0, 1, 0),
                 zm = V(0, 0, -1), zp = V(0, 0, 1);
    const double gx = 0.5 * (xp - xm), gy = 0.5 * (yp - ym), gz = 0.5 * (zp - zm);
    const double g2 = gx * gx + gy * gy + gz * gz + 1e-12, ig2 = 1.0 / g2;
    double out = 0;
    if (parts & LS_RHS_ADVECTION) {
        /* speed extended from the closest point of the zero level */
        const double lim = FH - 1;
        double ox = -p0 * gx * ig2, oy = -p0 * gy * ig2, oz = -p0 * gz * ig2;
        ox = MAX(-lim, MIN(lim, ox));
        oy = MAX(-lim, MIN(lim, oy));
        oz = MAX(-lim, MIN(lim, oz));
        /* floor of a value in [-lim, lim]: truncation of a shifted positive */
        const int ix = (int)(ox + FH) - FH, iy = (int)(oy + FH) - FH, iz = (int)(oz + FH) - FH;
        const double tx = ox - ix, ty = oy - iy, tz = oz - iz;
        const float *f = fc + ix + FP * (iy + FP * iz);
        const double f00 = f[0] + tx * (f[1] - f[0]), f10 = f[FP] + tx * (f[FP + 1] - f[FP]),
                     f01 = f[FP * FP] + tx * (f[FP * FP + 1] - f[FP * FP]),
                     f11 = f[FP * FP + FP] + tx * (f[FP * FP + FP + 1] - f[FP * FP + FP]);
        const double f0 = f00 + ty * (f10 - f00), f1 = f01 + ty * (f11 - f01);
        const double Fe = f0 + tz * (f1 - f0);
        const double vel = alpha * Fe;
        *fabs_out = fabs(Fe);
        const double dmx = p0 - xm, dpx = xp - p0, dmy = p0 - ym, dpy = yp - p0, dmz = p0 - zm,
                     dpz = zp - p0;
        /* vel > 0: the front moves outward and takes its information from
         * inside; both sums are formed and one selected, without a branch
         * (the sign of F changes across the band: a branch mispredicts) */
        const double up_out = sq(MIN(dmx, 0)) + sq(MAX(dpx, 0)) + sq(MIN(dmy, 0)) +
                              sq(MAX(dpy, 0)) + sq(MIN(dmz, 0)) + sq(MAX(dpz, 0));
        const double up_in = sq(MAX(dmx, 0)) + sq(MIN(dpx, 0)) + sq(MAX(dmy, 0)) +
                             sq(MIN(dpy, 0)) + sq(MAX(dmz, 0)) + sq(MIN(dpz, 0));
        out += vel * sqrt(vel > 0 ? up_out : up_in);
    }
    if (parts & LS_RHS_CURVATURE) {
        const double pxx = xp - 2 * p0 + xm, pyy = yp - 2 * p0 + ym, pzz = zp - 2 * p0 + zm;
        const double pxy = 0.25 * (V(1, 1, 0) - V(1, -1, 0) - V(-1, 1, 0) + V(-1, -1, 0));
        const double pxz = 0.25 * (V(1, 0, 1) - V(1, 0, -1) - V(-1, 0, 1) + V(-1, 0, -1));
        const double pyz = 0.25 * (V(0, 1, 1) - V(0, 1, -1) - V(0, -1, 1) + V(0, -1, -1));
        const double num = pxx * (gy * gy + gz * gz) + pyy * (gx * gx + gz * gz) +
                           pzz * (gx * gx + gy * gy) -
                           2 * (gx * gy * pxy + gx * gz * pxz + gy * gz * pyz);
        const double gn = sqrt(g2);
        double H = 0.5 * num * ig2 / gn; /* mean curvature, 1/cells */
        H = H / (1.0 + fabs(H));         /* smooth clamp to a radius of a cell */
        out += beta * H * gn;
    }
#undef V
    return out;
}

void ls_rhs_eval(ls_rhs *r, const double *y, double *ydot, int parts)
{
    const ls_band *band = r->band;
    const double fallback = band->rim + 1;
    const double alpha = r->alpha, beta = r->beta_grid;
    const size_t nb = band->b.n;
    double fbig = 0;
    scatter(r, y);
#pragma omp parallel for schedule(dynamic, 4) reduction(max : fbig)
    for (size_t b = 0; b < nb; b++) {
        const size_t a0 = r->bstart[b], a1 = r->bstart[b + 1];
        if (a0 == a1)
            continue;
        const double *pad = r->pad + (size_t)r->padof[b] * P * P * P;
        const float *fpad = r->Fpad + (size_t)r->padof[b] * FP * FP * FP;
        for (size_t a = a0; a < a1; a++) {
            const int l = (int)(band->act[a] % LS_B3);
            const int i = l & 7, j = (l >> 3) & 7, k = l >> 6;
            double fa = 0;
            ydot[a] = r->edge[a] ? point_rhs(&pad[PI(i, j, k)], &fpad[FPI(i, j, k)], alpha, beta,
                                             parts, true, fallback, &fa)
                                 : point_rhs(&pad[PI(i, j, k)], &fpad[FPI(i, j, k)], alpha, beta,
                                             parts, false, fallback, &fa);
            if (fa > fbig)
                fbig = fa;
        }
    }
    if (parts & LS_RHS_ADVECTION)
        r->fmax = fbig;
    r->evaluations++;
}

/* ---- preconditioner of the implicit (curvature) part ------------------- */

/* For phi close to a distance, |grad phi| H = (lap phi - n.(grad grad phi).n) / 2:
 * a Laplacian without its normal part. P = I - gamma (beta'/2) L with L that
 * operator (normals frozen at the set-up) approximates the Newton matrix
 * I - gamma J; its inverse is approximated by a few Gauss-Seidel sweeps,
 * in-brick (Jacobi between bricks, so the sweeps run in parallel). Points
 * off the active set hold no correction. */
int ls_rhs_precond_setup(ls_rhs *r, const double *y, double gamma)
{
    const ls_band *band = r->band;
    const size_t na = band->nact, nb = band->b.n;
    if (!r->pn) {
        r->pn = malloc((na ? na : 1) * 3 * sizeof *r->pn);
        r->zpad = malloc((r->npad ? r->npad : 1) * P * P * P * sizeof *r->zpad);
        if (!r->pn || !r->zpad)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for the preconditioner");
        for (size_t q = 0; q < r->npad * P * P * P; q++)
            r->zpad[q] = 0;
    }
    scatter(r, y);
#pragma omp parallel for schedule(dynamic, 4)
    for (size_t b = 0; b < nb; b++) {
        if (r->padof[b] == LS_NONE)
            continue;
        const double *pad = r->pad + (size_t)r->padof[b] * P * P * P;
        for (size_t a = r->bstart[b]; a < r->bstart[b + 1]; a++) {
            const int l = (int)(band->act[a] % LS_B3);
            const double *c = &pad[PI(l & 7, (l >> 3) & 7, l >> 6)];
            double g[3] = {0.5 * (c[1] - c[-1]), 0.5 * (c[P] - c[-P]),
                           0.5 * (c[P * P] - c[-P * P])};
            double gn = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
            for (int k = 0; k < 3; k++)
                r->pn[3 * a + k] = (float)(gn > 0 && isfinite(gn) ? g[k] / gn : 0);
        }
    }
    r->pgamma = gamma;
    return 0;
}

void ls_rhs_precond_solve(ls_rhs *r, const double *rhs, double *z)
{
    const ls_band *band = r->band;
    const size_t na = band->nact, nb = band->b.n;
    const double gd = r->pgamma * 0.5 * r->beta_grid, diag = 1 + 4 * gd;
    for (size_t q = 0; q < na; q++)
        z[q] = rhs[q] / diag;
    /* 5 sweeps: on a sphere at l0/h = 8 (tests/test_levelset.c) SPGMR took
     * 215, 145, 106, 88 iterations with 1, 3, 6, 10 sweeps; a sweep costs
     * about a third of a right-hand side */
    for (int sweep = 0; sweep < 5; sweep++) {
#pragma omp parallel for schedule(dynamic, 4096)
        for (size_t q = 0; q < na; q++)
            for (size_t s = r->slot_start[q]; s < r->slot_start[q + 1]; s++)
                if (r->slot[s] != UINT32_MAX)
                    r->zpad[r->slot[s]] = z[q];
#pragma omp parallel for schedule(dynamic, 4)
        for (size_t b = 0; b < nb; b++) {
            if (r->padof[b] == LS_NONE)
                continue;
            double *zp = r->zpad + (size_t)r->padof[b] * P * P * P;
            for (size_t a = r->bstart[b]; a < r->bstart[b + 1]; a++) {
                const int l = (int)(band->act[a] % LS_B3);
                double *c = &zp[PI(l & 7, (l >> 3) & 7, l >> 6)];
                const double nx = r->pn[3 * a], ny = r->pn[3 * a + 1], nz = r->pn[3 * a + 2];
                double off = (1 - nx * nx) * (c[1] + c[-1]) + (1 - ny * ny) * (c[P] + c[-P]) +
                             (1 - nz * nz) * (c[P * P] + c[-P * P]) -
                             0.5 * nx * ny * (c[1 + P] - c[1 - P] - c[-1 + P] + c[-1 - P]) -
                             0.5 * nx * nz *
                                 (c[1 + P * P] - c[1 - P * P] - c[-1 + P * P] + c[-1 - P * P]) -
                             0.5 * ny * nz *
                                 (c[P + P * P] - c[P - P * P] - c[-P + P * P] + c[-P - P * P]);
                double v = (rhs[a] + gd * off) / diag;
                c[0] = v;
                z[a] = v;
            }
        }
    }
    /* the halos of inactive points must stay zero: only active slots were written */
}

double ls_rhs_stable_step(const ls_rhs *r, bool curvature)
{
    /* Forward Euler (and the stability intervals of the low-order RK tables
     * used): upwind advection needs dtau sum_a |V n_a| <= 1, at most
     * sqrt(3) |V|; the curvature term behaves as (beta'/2) times a Laplacian,
     * whose largest eigenvalue is 6 beta' in 3-D, so dtau <= 2 / (6 beta'). */
    double adv = sqrt(3.0) * r->alpha * (r->fmax > 0.1 ? r->fmax : 0.1);
    double curv = curvature ? CURV_BOUND * r->beta_grid : 0.0;
    return 1.0 / (adv + curv);
}

void ls_rhs_spectrum(const ls_rhs *r, double fmax, double *curv, double *adv)
{
    /* as in ls_rhs_stable_step: forward Euler's interval [-2, 0] and disk
     * |z + 1| <= 1 give dtau <= 1 / (adv + curv / 2) */
    *adv = sqrt(3.0) * r->alpha * (fmax > 0.1 ? fmax : 0.1);
    *curv = 2 * CURV_BOUND * r->beta_grid;
}
