/* mps_xsph.c: the XSPH velocity filter in the explicit phase (Monaghan 1989,
 * "On the problem of penetration in particle methods", J. Comput. Phys. 82,
 * 1-15, eq. 2.6; MPSCoeffs `velocityFilter`, docs/notes/mps.md "rest").
 *
 * Each fluid particle's velocity moves towards its fluid neighbours' by
 *   du_i = eps sum_j c_ij (u_j - u_i)   (j fluid, r_ij < reGradient),
 * with c_ij = w_ij / max(n0, s_i, s_j), s_i the sum of w_ij over i's fluid
 * neighbours (c_ij = w_ij / n0 where the fluid is not compressed; bounded
 * where pairs are close, so that eps sum_j c_ij <= eps <= 1: eq. 3's w,
 * unbounded as r -> 0, would let the filter overshoot). It is read at u^n
 * and added to it before the explicit update u* = u^n + dt a, r* = r^n +
 * dt u* (one Jacobi pass; the positions follow through u*), so that the
 * pressure step comes after it. Monaghan applies the sum to the velocity
 * that moves the
 * particles only; here it changes the velocity too, so it is a pairwise
 * exchange (c_ij = c_ji: the fluid's momentum is kept) that takes kinetic
 * energy from the particle-scale relative motion: by eq. 7 it is an
 * explicit viscosity eps lambda / (2 d dt), strongest on the shortest
 * waves, which is what the resting lattice's column mode is. */
#include <stdlib.h>

#include "mf_error.h"
#include "mf_kernel.h"
#include "mf_pairs.h"
#include "mps.h"

typedef struct {
    const mf_pairs *v;
    const uint8_t *fluid;
    const double *vel;
    double *sum;       /* s_i = sum over fluid j of w_ij */
    double n0, eps;
    double *out;       /* 3 per particle: du */
} xsph_ctx;

/* s_i: the fluid neighbours' weights. */
static inline bool xsph_sum_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const xsph_ctx *c = ctx;
    *(double *)acc += mf_weight(pr->len, c->v->radius);
    return true;
}

static void xsph_sum_row(const void *ctx, size_t i)
{
    const xsph_ctx *c = ctx;
    double s = 0;
    mf_pairs_row(c->v, i, c->fluid, xsph_sum_pair, c, &s);
    c->sum[i] = s;
}

/* One pair: c_ij (u_j - u_i), c_ij = w_ij / max(n0, s_i, s_j) = c_ji. */
static inline bool xsph_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const xsph_ctx *c = ctx;
    double scale = c->n0;
    if (c->sum[pr->i] > scale) scale = c->sum[pr->i];
    if (c->sum[pr->j] > scale) scale = c->sum[pr->j];
    const double w = mf_weight(pr->len, c->v->radius) / scale;
    const double *ui = c->vel + 3 * pr->i, *uj = c->vel + 3 * pr->j;
    double *du = acc;
    for (int q = 0; q < 3; q++)
        du[q] += w * (uj[q] - ui[q]);
    return true;
}

static void xsph_row(const void *ctx, size_t i)
{
    const xsph_ctx *c = ctx;
    double du[3] = {0, 0, 0};
    mf_pairs_row(c->v, i, c->fluid, xsph_pair, c, du);
    for (int q = 0; q < 3; q++)
        c->out[3 * i + q] = c->eps * du[q];
}

int mps_velocity_filter(mps_data *d, mf_sim *sim)
{
    if (!(d->s.velocity_filter > 0))
        return 0;
    mf_particles *p = sim->p;
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_grad, &v));
    double *sum = malloc((p->n ? p->n : 1) * sizeof *sum);
    if (!sum)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the velocity filter");
    double *du = d->grad; /* scratch: free in the explicit phase */
    const xsph_ctx c = {&v, d->is_fluid, p->vel, sum, d->k_grad.n0, d->s.velocity_filter, du};
    for (size_t i = p->n_owned; i < p->n; i++)
        sum[i] = 0;
    mf_pairs_each(&v, d->is_fluid, xsph_sum_row, &c);
    /* the copies' s_j from their owners (the pair coefficient reads s_j) */
    int rc = mps_halo_sync(d, sim, sum, sizeof *sum);
    if (rc == 0)
        mf_pairs_each(&v, d->is_fluid, xsph_row, &c);
    free(sum);
    MF_CALL(rc);
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->is_fluid[i])
            continue;
        for (int q = 0; q < 3; q++)
            p->vel[3 * i + q] += du[3 * i + q];
    }
    return 0;
}
