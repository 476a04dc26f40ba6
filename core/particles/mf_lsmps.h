/* mf_lsmps.h: the least-squares MPS operators (LSMPS type A, Tamai &
 * Koshizuka 2014, Comp. Part. Mech. 1, 277-305), on the pair engine.
 *
 * For particle i the neighbours' differences f_j - f_i are fitted by a
 * quadratic Taylor polynomial in the scaled relative position r_ij / l0,
 * weighted by mf_weight_ls: the moment matrix M_i = sum_j w_ij p_ij p_ij^T
 * and b_i = sum_j w_ij p_ij (f_j - f_i) (eqs. 17-20), M_i a_i = b_i, and the
 * derivatives are the coefficients a_i (eq. 21). The quadratic fit makes the
 * gradient and the Laplacian exact for a quadratic field on any particle
 * arrangement where M_i is regular (second order on a disordered one).
 *
 * Where M_i is singular (fewer neighbours than unknowns, all on a line: a
 * splash, a thin sheet, a free-surface corner) the fit falls back to the
 * linear polynomial (gradient only) and, where that fails too, the particle
 * is marked in `failed` for the caller's standard operator (eqs. 5, 7).
 */
#ifndef MF_LSMPS_H
#define MF_LSMPS_H

#include <stddef.h>
#include <stdint.h>

#include "mf_kernel.h"
#include "mf_pairs.h"

/* <grad f>_i for the particles in imask (3 per particle) from the
 * neighbours in jmask closer than the view's radius; failed[i] = 1 where
 * neither fit was regular (out is then untouched), else 0. Returns the
 * number of failed particles. */
size_t mf_lsmps_gradient(const mf_pairs *v, const mf_kernel *k, const double *f,
                         const uint8_t *imask, const uint8_t *jmask, double *out,
                         uint8_t *failed);

/* out_i += scale <lap u>_i for a field of 3 interleaved components (the
 * viscous term), failed[i] = 1 where the quadratic fit is singular (out
 * untouched there). Returns the number of failed particles. */
size_t mf_lsmps_laplacian_add(const mf_pairs *v, const mf_kernel *k, const double *u,
                              double scale, const uint8_t *imask, const uint8_t *jmask,
                              double *out, uint8_t *failed);

/* Points beyond the particles in a fit: a wall's virtual points (mps_wall.c,
 * on the lattice of mf_wall_lattice.h). The caller's extra(ctx, i, add, acc)
 * calls add(acc, r, df, sign) once per point of particle i: r its offset
 * from the particle (m), df = f_v - f_i its field difference (3
 * components), sign +1 or -1 (the inclusion-exclusion of a box's faces,
 * edges and corners, mf_wall_weight.h); the point enters M_i and b_i with
 * the weight of a particle at r, times sign. extra is called from the pair
 * engine's threads: it must only read shared data. */
typedef void (*mf_lsmps_point_fn)(void *acc, const double r[3], const double df[3],
                                  double sign);
typedef void (*mf_lsmps_extra_fn)(const void *ctx, size_t i, mf_lsmps_point_fn add, void *acc);

/* mf_lsmps_laplacian_add with each particle's extra points in its fit
 * (extra NULL: the same as mf_lsmps_laplacian_add). */
size_t mf_lsmps_laplacian_add_extra(const mf_pairs *v, const mf_kernel *k, const double *u,
                                    double scale, const uint8_t *imask, const uint8_t *jmask,
                                    mf_lsmps_extra_fn extra, const void *extra_ctx, double *out,
                                    uint8_t *failed);

#endif
