/* mf_wall_terms.h: a wall's part of each MPS operator at one fluid particle,
 * from the wall weight sums of mf_wall_weight.h (the sums a particle wall's
 * virtual points would give, tabulated against the distances to the faces).
 * Small pure functions, one per operator; the solver adds each to what the
 * pair engine summed over the particles.
 *
 * The wall's virtual points v (offsets from the particle i) carry
 *   velocity  u_v = u_w in the divergence (the source's wall term), and
 *             u_v = u_w - (s_v/d)(u_i - u_w) in the viscous term (no slip
 *             on the face: Morris, Fox & Zhu 1997, as mf_wall_sums.visc),
 *   pressure  p_v = p_i in the pressure equation's Laplacian (the wall's
 *             flux is the divergence's wall term: a second, hydrostatic one
 *             would count it twice), and p_v = p_i + rho a.v in the
 *             gradient, the particle's pressure continued into the wall
 *             (Harada, Koshizuka & Shimazaki 2008, Trans. JSCES 20080006,
 *             continue it hydrostatically; a is the solver's choice, the
 *             force acceleration at rest),
 * so that each operator's sum over the virtual points is a combination of
 * the tabulated zn, g, t and visc. */
#ifndef MF_WALL_TERMS_H
#define MF_WALL_TERMS_H

#include <stdbool.h>

#include "mf_kernel.h"
#include "mf_wall_weight.h"

/* eq. 4: the wall's number density, n_i += zn (the number density's radius). */
static inline double mf_wall_number_density(const mf_wall_sums *s) { return s->zn; }

/* eq. 6: d/n0 sum_v (u_v - u_i).v/|v|^2 w = d/n0 (u_w - u_i).g, with u_w the
 * wall's velocity (k: the gradient's kernel). */
static inline double mf_wall_divergence(const mf_wall_sums *s, const mf_kernel *k,
                                        const double u_i[3], const double u_w[3])
{
    double dot = 0;
    for (int a = 0; a < 3; a++)
        dot += (u_w[a] - u_i[a]) * s->g[a];
    return k->dim / k->n0 * dot;
}

/* eq. 5 on the continued pressure: d/n0 sum_v (p_v - p^_i) v/|v|^2 w
 *   = d/n0 [(p_i - p^_i) g + rho t a]
 * added to grad (k: the gradient's kernel). The first term is the wall's
 * repulsion where the particle's pressure exceeds its neighbourhood's
 * minimum, the second the wall's share of the pressure gradient rho a (at
 * rest the hydrostatic one: with p^ from a full lattice the two add up to
 * rho f exactly). */
static inline void mf_wall_gradient_add(const mf_wall_sums *s, const mf_kernel *k, double p_i,
                                        double phat_i, double rho, const double a[3],
                                        double grad[3])
{
    const double T[3][3] = {{s->t[0], s->t[3], s->t[4]},
                            {s->t[3], s->t[1], s->t[5]},
                            {s->t[4], s->t[5], s->t[2]}};
    const double c = k->dim / k->n0;
    for (int q = 0; q < 3; q++) {
        const double ta = T[q][0] * a[0] + T[q][1] * a[1] + T[q][2] * a[2];
        grad[q] += c * ((p_i - phat_i) * s->g[q] + rho * ta);
    }
}

/* eq. 7 on the no-slip velocity: nu 2d/(lambda n0) sum_v (u_v - u_i) w
 *   = nu 2d/(lambda n0) (visc_u - visc u_i)
 * (visc_u = sum over solids of visc_w u_w); added to acc (k: the
 * Laplacian's kernel). */
static inline void mf_wall_viscous_add(const mf_wall_sums *s, const mf_kernel *k, double nu,
                                       const double u_i[3], const double visc_u[3],
                                       double acc[3])
{
    const double c = nu * 2.0 * k->dim / (k->lambda * k->n0);
    for (int a = 0; a < 3; a++)
        acc[a] += c * (visc_u[a] - s->visc * u_i[a]);
}

/* The no-slip velocity continued through the face at a virtual point s_v =
 * depth behind it, for a particle d = dist from it (d at least d_min, as
 * mf_wall_sums.visc): u_v = u_w - (s_v/d)(u_i - u_w) (Morris, Fox & Zhu
 * 1997), i.e. 2 u_w - u_m with u_m the velocity at the point's mirror image
 * interpolated linearly between the face and the particle; exact for a
 * field linear in the distance to the face. Returns the factor phi of
 * u_v - u_i = phi (u_w - u_i). */
static inline double mf_wall_noslip_factor(double depth, double dist, double d_min)
{
    const double d = dist > d_min ? dist : d_min;
    return 1.0 + depth / d;
}

/* The collision model against the face: a particle closer than `distance`
 * to the face (dist, normal into the fluid) that approaches it (relative to
 * the wall's velocity u_w) leaves with its normal velocity reversed times
 * the restitution e (the wall infinitely heavy, as mf_collision's fixed
 * walls). du: the velocity change. Returns true when it collided. */
static inline bool mf_wall_collision(double dist, const double normal[3], const double u_w[3],
                                     double distance, double e, const double u_i[3],
                                     double du[3])
{
    double un = 0;
    for (int a = 0; a < 3; a++)
        un += (u_i[a] - u_w[a]) * normal[a];
    if (!(dist < distance) || !(un < 0)) {
        du[0] = du[1] = du[2] = 0;
        return false;
    }
    for (int a = 0; a < 3; a++)
        du[a] = -(1.0 + e) * un * normal[a];
    return true;
}

#endif
