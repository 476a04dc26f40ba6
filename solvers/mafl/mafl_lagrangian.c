/* mafl_lagrangian.c: the Lagrangian phase of MPS-MAFL, the MPS module's
 * own step.
 *
 * densityReference n0 (the default): mps_lagrangian_step as it is; the
 * source of the pressure equation (eq. 14) is (n* - n0)/n0.
 *
 * densityReference startOfStep: the same phases of the MPS module in the
 * same order, with a source that measures only the compression of this
 * step's motion:
 *   n_eff = n0 + sum_{j moving} [w(|r*_ij|) - w(|r^n_ij|)]
 *              + (pairs with a wall or dummy particle: w linearised at r^n),
 * "moving" being fluid, inlet and outlet points. Why:
 *  - a fixed point's Lagrangian displacement slides it along the wall
 *    lattice by the same u dt every step; the wall part of n* changes with
 *    the phase of the lattice (about 5e-4 n0 at Courant number 0.2), a
 *    steady false source. With n0 it is positive beside the walls and
 *    negative one row further in, and only the clipping of negative
 *    pressures keeps a uniform channel flow uniform; linearised, the wall
 *    part changes only by motion toward or away from the wall, so a uniform
 *    flow gives no source at all;
 *  - MPS particles are material, MAFL points are not: an uneven placement
 *    of fixed points (where Lagrangian surface points meet fixed interior
 *    points) is no compression of the fluid, but with n0 it drives a
 *    spurious velocity every step.
 * The price: nothing pulls the free surface back to its volume. On a resting
 * box under gravity (rule fixed) startOfStep loses 40% of the fluid points
 * to merging in 2 s while n0 keeps them all (its spurious velocity levels
 * off near 0.17 m/s, pure MPS about 0.07 m/s). So startOfStep is for flows
 * without a free surface (channels: the tutorials scalarAdvection and
 * channelInflow use it), n0 for the rest. README (MPS-MAFL) has the numbers.
 *
 * The hook that would let this call mps_lagrangian_step unchanged: a
 * per-particle source offset in mps_data, rhs_i ~ (n_i - n0 - offset_i)/n0
 * (NULL: none). Until the MPS module has one, mafl_lagrangian mirrors the
 * sequence of mps_lagrangian_step and changes the NumberDensity values that
 * mps_assemble_ppe reads, restoring them after. */
#include <math.h>
#include <string.h>

#include "mafl.h"
#include "mf_error.h"

static const mf_nlist *nd_list(const mps_data *m)
{
    return m->k_nd.re >= m->nl_max.radius ? &m->nl_max : &m->nl_nd;
}

/* d/dr w(r) / r for w = re/r - 1 (0 outside (0, re)). */
static inline double dw_over_r(double r, double re)
{
    return (r > 0.0 && r < re) ? -re / (r * r * r) : 0.0;
}

/* n_eff at r* (lists at r*, r^n from the field xn): pairs of moving points
 * exactly, pairs with a fixed particle linearised at r^n. */
static void effective_density(const mps_data *m, const mf_particles *p, const double *xn,
                              double *eff)
{
    const mf_nlist *nl = nd_list(m);
    const double re = m->k_nd.re, n0 = m->k_nd.n0;
    const long n = (long)p->n_owned;
#pragma omp parallel for schedule(static)
    for (long ii = 0; ii < n; ii++) {
        const size_t i = (size_t)ii;
        double sum = n0;
        const double *xi = &p->pos[3 * i], *xi0 = &xn[3 * i];
        const bool mi = m->is_fluid[i];
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            const size_t j = nl->j[k];
            const bool mj = m->is_fluid[j];
            if (!mi && !mj)
                continue;
            const double *xj = &p->pos[3 * j], *xj0 = &xn[3 * j];
            double r0[3] = {xi0[0] - xj0[0], xi0[1] - xj0[1], xi0[2] - xj0[2]};
            double d0 = sqrt(r0[0] * r0[0] + r0[1] * r0[1] + r0[2] * r0[2]);
            if (mi && mj) {
                double r[3] = {xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]};
                double d1 = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
                sum += mf_weight(d1, re) - mf_weight(d0, re);
            } else {
                /* The moving one's displacement along the gradient of w. */
                const double *x = mi ? xi : xj, *x0 = mi ? xi0 : xj0;
                double g = dw_over_r(d0, re) * (mi ? 1.0 : -1.0);
                for (int a = 0; a < 3; a++)
                    sum += g * r0[a] * (x[a] - x0[a]);
            }
        }
        eff[i] = sum;
    }
}

int mafl_lagrangian(mafl_data *d, mf_sim *sim, double dt)
{
    if (!d->incremental)
        return mps_lagrangian_step(d->mps, sim, dt);
    mps_data *m = d->mps;
    mf_particles *p = sim->p;
    MF_CALL(mps_reserve(m, p->n));
    MF_CALL(mps_build_neighbours(m, sim, true)); /* at r^n; may reorder */
    mps_set_masks(m, p);
    MF_CALL(mps_explicit_phase(m, sim, dt));
    MF_CALL(mps_build_neighbours(m, sim, false)); /* at r* */
    MF_CALL(mps_surface_phase(m, sim));           /* free surface from the true n* */
    double *n = mf_particles_fd(p, m->f_number_density);
    const double *xn = mf_particles_fd(p, d->f_pos_n); /* r^n, reordered with the rest */
    effective_density(m, p, xn, d->n_eff);
    for (size_t i = 0; i < p->n_owned; i++) {
        d->n_offset[i] = n[i] - d->n_eff[i]; /* kept to restore n* */
        if (m->in_ppe[i])
            n[i] = d->n_eff[i];
    }
    int rc = mps_assemble_ppe(m, sim, dt);
    for (size_t i = 0; i < p->n_owned; i++) /* NumberDensity stays n*, as written */
        if (m->in_ppe[i])
            n[i] += d->n_offset[i];
    MF_CALL(rc);
    MF_CALL(mps_solve_ppe(m, sim));
    MF_CALL(mps_correction_phase(m, sim, dt));
    return 0;
}
