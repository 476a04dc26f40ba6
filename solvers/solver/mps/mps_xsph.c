/* mps_xsph.c: the XSPH velocity filter in the explicit phase (Monaghan 1989,
 * "On the problem of penetration in particle methods", J. Comput. Phys. 82,
 * 1-15, eq. 2.6; MPSCoeffs `velocityFilter`, docs/notes/mps.md "rest").
 *
 * Each fluid particle's velocity moves towards its fluid neighbours' by
 *   du_i = eps (1/n0) sum_j (u_j - u_i) w(|r_ij|)   (j fluid, r_ij < reGradient),
 * read at u^n and added to it before the explicit update u* = u^n + dt a,
 * r* = r^n + dt u* (one Jacobi pass; the positions follow through u*), so
 * the pressure step after it still stops what approaches a wall (applied
 * after the correction instead, it undid that stop and blew up the dam
 * break at its impact: docs/notes/mps.md, "rest"). Monaghan applies the sum to the velocity that moves the
 * particles only; here it changes the velocity too, so it is a pairwise
 * exchange (w_ij = w_ji: the fluid's momentum is kept) that takes kinetic
 * energy from the particle-scale relative motion: by eq. 7 it is an
 * explicit viscosity eps lambda / (2 d dt), strongest on the shortest
 * waves, which is what the resting lattice's column mode is. */
#include "mf_error.h"
#include "mf_kernel.h"
#include "mf_pairs.h"
#include "mps.h"

typedef struct {
    const mf_pairs *v;
    const double *vel;
    double eps_over_n0;
    double *out; /* 3 per particle: du */
} xsph_ctx;

static inline bool xsph_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const xsph_ctx *c = ctx;
    const double w = mf_weight(pr->len, c->v->radius);
    const double *ui = c->vel + 3 * pr->i, *uj = c->vel + 3 * pr->j;
    double *du = acc;
    for (int q = 0; q < 3; q++)
        du[q] += w * (uj[q] - ui[q]);
    return true;
}

typedef struct {
    xsph_ctx x;
    const uint8_t *fluid;
} xsph_fluid_ctx;

static void xsph_row_fluid(const void *ctx, size_t i)
{
    const xsph_fluid_ctx *c = ctx;
    double du[3] = {0, 0, 0};
    mf_pairs_row(c->x.v, i, c->fluid, xsph_pair, &c->x, du);
    for (int q = 0; q < 3; q++)
        c->x.out[3 * i + q] = c->x.eps_over_n0 * du[q];
}

int mps_velocity_filter(mps_data *d, mf_sim *sim)
{
    if (!(d->s.velocity_filter > 0))
        return 0;
    mf_particles *p = sim->p;
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_grad, &v));
    double *du = d->grad; /* scratch: free in the explicit phase */
    const xsph_fluid_ctx c = {{&v, p->vel, d->s.velocity_filter / d->k_grad.n0, du}, d->is_fluid};
    mf_pairs_each(&v, d->is_fluid, xsph_row_fluid, &c);
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->is_fluid[i])
            continue;
        for (int q = 0; q < 3; q++)
            p->vel[3 * i + q] += du[3 * i + q];
    }
    return 0;
}
