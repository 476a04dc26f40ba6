/* mps_shift.c: particle shifting (Lind, Xu, Stansby & Rogers 2012, J.
 * Comput. Phys. 231, 1499-1523), in its MPS form.
 *
 * After the correction each fluid particle moves down the gradient of the
 * particle concentration (Fick's law, Lind et al. eq. 9-10),
 *   dr_i = -A l0^2 <grad C>_i,  <grad C>_i = (d/n0) sum_j r_ij w_ij / |r_ij|^2
 * (mf_concentration_gradient: eq. 5 on C = 1; walls and dummies count, so
 * a particle is pushed off a wall it crowds), which evens out the particle
 * arrangement where the flow has strained it (the clustering and voids
 * that make the number-density source noisy). A particle displaced by e
 * from its lattice site returns by about 1.9 A e a step (2-D, re 2.1 l0).
 *
 * Free surface (Lind et al. section 3.2; Khayyer, Gotoh & Shimizu 2017, J.
 * Comput. Phys. 332, 236-256, eq. 27): at a free-surface particle and at
 * the particles beside one (within the gradient's radius) the shift keeps
 * only its part along the surface, dr - (dr . n) n, n the outward normal
 * (minus the neighbour asymmetry, mf_neighbour_asymmetry): there the
 * concentration gradient is that of the surface itself, and following it
 * would carry surface particles off the surface into the air.
 *
 * Each shift is at most shiftMax l0. The velocity moves with the particle
 * to first order, u_i += <grad u>_i . dr_i (Lind et al. eq. 11).
 */
#include <math.h>

#include "mf_error.h"
#include "mf_operators.h"
#include "mf_run.h"
#include "mps.h"

/* Does a neighbour lie on the free surface (the first ends the row)? */
static inline bool surface_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const uint8_t *dirichlet = ctx;
    if (dirichlet[pr->j]) {
        *(bool *)acc = true;
        return false;
    }
    return true;
}

int mps_shift(mps_data *d, mf_sim *sim)
{
    d->shifted = 0;
    d->shift_largest = 0;
    if (d->sc.shifting == MPS_SHIFT_NONE)
        return 0;
    double t0 = mf_wall_seconds();
    mf_particles *p = sim->p;
    MF_CALL(mps_scheme_reserve(d, p->n));
    const size_t n = p->n;
    double *dr = d->work, *normal = d->work + 3 * n, *G = d->work + 6 * n; /* 3 + 3 + 9 */
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_nd, &v));
    mf_neighbour_asymmetry(&v, &d->k_nd, d->is_fluid, NULL, normal);
    MF_CALL(mps_pairs(d, sim, d->h_grad, &v));
    mf_concentration_gradient(&v, &d->k_grad, d->is_fluid, NULL, dr);
    const double A = d->s.shift_coefficient * sim->l0 * sim->l0;
    const double cap = d->s.shift_max * sim->l0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->is_fluid[i])
            continue;
        double *s = &dr[3 * i];
        for (int c = 0; c < 3; c++)
            s[c] *= -A;
        bool near = d->dirichlet[i];
        if (!near)
            mf_pairs_row_r2(&v, i, d->is_fluid, surface_pair, d->dirichlet, &near);
        if (near) { /* along the surface only */
            const double *f = &normal[3 * i];
            const double len = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
            if (len > 0) {
                const double dot = (s[0] * f[0] + s[1] * f[1] + s[2] * f[2]) / (len * len);
                for (int c = 0; c < 3; c++)
                    s[c] -= dot * f[c];
            }
        }
        const double len = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
        if (len > cap)
            for (int c = 0; c < 3; c++)
                s[c] *= cap / len;
    }
    /* u follows the shift to first order: <grad u> at the positions before it */
    mf_velocity_gradient(&v, &d->k_grad, p->vel, d->is_fluid, d->not_dummy, G);
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->is_fluid[i])
            continue;
        const double *s = &dr[3 * i], *g = &G[9 * i];
        for (int a = 0; a < 3; a++) {
            p->vel[3 * i + a] += g[3 * a] * s[0] + g[3 * a + 1] * s[1] + g[3 * a + 2] * s[2];
            p->pos[3 * i + a] += s[a];
        }
        const double len = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
        if (len > 0)
            d->shifted++;
        if (len / sim->l0 > d->shift_largest)
            d->shift_largest = len / sim->l0;
    }
    d->t_correction += mf_wall_seconds() - t0;
    return 0;
}
