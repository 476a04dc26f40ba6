/* mps_source.c: the source term of the pressure equation, per scheme.
 *
 * mps_ppe.c solves -<lap p> = rho s_i (s_i / 1 with a density per particle,
 * where the operator carries 1/rho). With `source density` s_i is eq. 14 as
 * printed, computed in mps_ppe.c itself:
 *   s_i = relaxation (n*_i - n0) / (n0 dt^2).
 * The others are computed here into d->src:
 *
 * mixed (Tanaka & Masunaga 2010, J. Comput. Phys. 229, 4279-4290, eq. 21;
 * Kondo & Koshizuka 2011, Int. J. Numer. Meth. Fluids 65, 638-654): the
 * velocity divergence of u* (eq. 6, projected to zero by the correction)
 * plus a small share gamma (densityFactor) of the density deviation at the
 * start of the step, which keeps the volume from drifting:
 *   s_i = -<div u*>_i / dt + gamma (n^k_i - n0) / (n0 dt^2).
 * Its main term grows as 1/dt, not 1/dt^2: a shorter step does not amplify
 * the particle-scale noise of n*.
 *
 * mixedHigherOrder: the mixed source with its divergence in the
 * higher-order form of Khayyer & Gotoh 2009 (below), -<div u*>_i =
 * (Dn/Dt)*_i / n0 by continuity:
 *   s_i = (Dn/Dt)*_i / (n0 dt) + gamma (n^k_i - n0) / (n0 dt^2).
 * Eq. 6 at the gradient's radius (2.1 l0) sees a particle's nearest ring
 * only, and projecting its particle-scale noise away with the PPE's wider
 * Laplacian (3.1 l0) fed the noise back: on damBreak2D at l0 0.005 and a
 * fixed dt 4e-4 the RMS of that term over the interior grew from 2.4e3 to
 * 1.8e4 s^-2 between t = 0.10 and 0.14 s, the pressure flipped sign from
 * step to step, and the run blew up at 0.18 s; the Dn/Dt form, a sum over
 * the number density's radius, did not. But it resists a particle's close
 * approach to a wall less (more weight on distant pairs): the obstacle dam
 * break stops at l0 0.00487 and 0.00365 with throughWall at the far wall,
 * where `mixed` completes (docs/notes/mps.md, 2026-12-02 robust).
 *
 * higherOrder (Khayyer & Gotoh 2009, Coastal Eng. 56, 419-440, eqs. 11-13):
 * the rate of the number density from the pair velocities,
 *   s_i = (Dn/Dt)*_i / (n0 dt),  Dn/Dt_i = sum_j -re (r_ij . u_ij) / |r_ij|^3
 * (mf_number_density_rate, at r* with u*, the number density's radius).
 *
 * errorCompensating (Khayyer & Gotoh 2011, J. Comput. Phys. 230, 3093-3118,
 * eqs. 16-19): the higher-order source plus terms that compensate the
 * error of the last step with coefficients set by that error itself,
 *   s_i += alpha (Dn/Dt)^k_i / (n0 dt) + beta (n^k_i - n0) / (n0 dt^2),
 *   alpha = |n^k_i - n0| / n0,  beta = |dt (Dn/Dt)^k_i| / n0
 * (k: the start of the step, r^n and u^n).
 *
 * The density terms are multiplied by d->density_scale, 1 except when the
 * time loop retries a step with a shorter dt (mps_step.c): a density error
 * corrected in one step needs a velocity of (n - n0)/n0 l / dt, which the
 * retry's halving would double each time.
 */
#include <math.h>

#include "mf_error.h"
#include "mf_operators.h"
#include "mps.h"

int mps_source_start(mps_data *d, mf_sim *sim)
{
    const mps_source_kind src = d->sc.source;
    if (!mps_source_mixed(src) && src != MPS_SOURCE_ERROR_COMPENSATING)
        return 0;
    MF_CALL(mps_scheme_reserve(d, sim->p->n));
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_nd, &v));
    mf_number_density(&v, d->not_dummy, NULL, d->n_start);
    if (d->wall) /* the walls' share at r^n (mps_wall.c) */
        mps_wall_number_density(d, sim, d->n_start);
    if (src == MPS_SOURCE_ERROR_COMPENSATING)
        mf_number_density_rate(&v, sim->p->vel, d->not_dummy, NULL, d->rate_start);
    return 0;
}

/* The two mixed sources: the velocity term rate / divisor (-div u* over
 * -dt, or (Dn/Dt)* over n0 dt) plus the density term gamma (n^k - n0) /
 * (n0 dt^2), gamma densityFactor times the retry's scale. */
static void mixed_source(mps_data *d, size_t n_owned, const double *rate, double divisor,
                         double n0, double dt2)
{
    const double gamma = d->s.density_factor * d->density_scale;
    for (size_t i = 0; i < n_owned; i++)
        if (d->in_ppe[i])
            d->src[i] = rate[i] / divisor + gamma * (d->n_start[i] - n0) / (n0 * dt2);
}

int mps_source_terms(mps_data *d, const mf_sim *sim, double dt)
{
    const mps_source_kind src = d->sc.source;
    if (src == MPS_SOURCE_DENSITY)
        return 0;
    const mf_particles *p = sim->p;
    MF_CALL(mps_scheme_reserve(d, p->n));
    const double n0 = d->k_nd.n0, dt2 = dt * dt, scale = d->density_scale;
    double *rate = d->work; /* the divergence or Dn/Dt at r* */
    mf_pairs v;
    if (src == MPS_SOURCE_MIXED) {
        /* eq. 6 at the gradient's radius over the particles the gradient sees */
        MF_CALL(mps_pairs(d, sim, d->h_grad, &v));
        mf_divergence(&v, &d->k_grad, p->vel, d->in_ppe, d->not_dummy, rate);
        if (d->wall) /* the walls' velocity */
            mps_wall_divergence(d, sim, d->in_ppe, rate);
        mixed_source(d, p->n_owned, rate, -dt, n0, dt2); /* -div u* / dt */
        return 0;
    }
    MF_CALL(mps_pairs(d, sim, d->h_nd, &v));
    mf_number_density_rate(&v, p->vel, d->in_ppe, NULL, rate);
    if (src == MPS_SOURCE_MIXED_HIGHER_ORDER) {
        mixed_source(d, p->n_owned, rate, n0 * dt, n0, dt2); /* (Dn/Dt)* / (n0 dt) */
        return 0;
    }
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->in_ppe[i])
            continue;
        double s = rate[i] / (n0 * dt);
        if (src == MPS_SOURCE_ERROR_COMPENSATING) {
            const double dn = (d->n_start[i] - n0) / n0;
            const double alpha = fabs(dn), beta = fabs(dt * d->rate_start[i]) / n0;
            s += alpha * d->rate_start[i] / (n0 * dt) + scale * beta * dn / dt2;
        }
        d->src[i] = s;
    }
    return 0;
}
