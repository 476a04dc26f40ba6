/* mf_operators.h: the MPS differential operators (section 3.1) and the
 * collision model, on the pair engine (mf_pairs.h).
 *
 * Each operator runs over the owned particles i in imask (NULL: all) and
 * their neighbours j in a view (mf_neighbours_pairs) and in jmask (NULL:
 * all); the view's radius is the operator's re. The pair terms are the
 * inline kernels of mf_kernel.h. Particles outside imask are left untouched
 * in the output. Loops run in parallel (OpenMP); each particle's sum runs
 * over its neighbours in the view's order, so results do not depend on the
 * thread count.
 */
#ifndef MF_OPERATORS_H
#define MF_OPERATORS_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stdint.h>

#include "mf_kernel.h"
#include "mf_pairs.h"
#include "mf_particles.h"

/* n_i = sum_j w(|r_ij|) with the view's radius as re. */
void mf_number_density(const mf_pairs *v, const uint8_t *imask, const uint8_t *jmask,
                       double *n);

/* eq. 5: <grad f>_i = d/n0 sum_j c_ij (f_j - f^_i) r_ij/|r_ij|^2 w(|r_ij|),
 * with the kernel's gradient weight as w and its n0_grad as n0
 * (mf_kernel_set_gradient_weight; the paper's w and n0 by default). */
typedef struct mf_gradient_opts {
    const double *f;
    /* f^_i: f_i, or with use_min the minimum of f over i and its (jmask)
     * neighbours (Koshizuka et al. 1998: keeps the pressure force
     * repulsive), except for the particles of own_reference (NULL: none). */
    bool use_min;
    const uint8_t *own_reference;
    /* c_ij: 1/rho_ij, the pair average of rho (mf_inv_rho_pair), or the
     * constant coef when rho is NULL. */
    const double *rho;
    int rho_average;
    double coef;
    /* Not NULL: the corrected gradient of Khayyer & Gotoh (2008, CMPS): the
     * pair term ((f_i + f_j) - (f^_i + f^_j)) instead of (f_j - f^_i), with
     * f^ these values for every particle (mf_neighbour_min); use_min and
     * own_reference are then unused. */
    const double *fhat;
} mf_gradient_opts;
void mf_gradient_ex(const mf_pairs *v, const mf_kernel *k, const mf_gradient_opts *o,
                    const uint8_t *imask, const uint8_t *jmask, double *out);
/* The plain gradient: c_ij = 1. out has 3 entries per particle. */
void mf_gradient(const mf_pairs *v, const mf_kernel *k, const double *f, bool use_min,
                 const uint8_t *imask, const uint8_t *jmask, double *out);

/* f^_i for the particles in imask: f_i, or with use_min the minimum of f
 * over i and its (jmask) neighbours, f_i for the particles of own_reference. */
void mf_neighbour_min(const mf_pairs *v, const double *f, bool use_min,
                      const uint8_t *own_reference, const uint8_t *imask, const uint8_t *jmask,
                      double *fhat);

/* eq. 7: <lap f>_i = 2d/(lambda n0) sum_j (f_j - f_i) w(|r_ij|) for a field
 * of ncomp interleaved components (1 or 3): out = <lap f>. */
void mf_laplacian(const mf_pairs *v, const mf_kernel *k, const double *f, int ncomp,
                  const uint8_t *imask, const uint8_t *jmask, double *out);
/* out += scale <lap f> (3 components): the viscous term nu <lap u> of eq. 9. */
void mf_laplacian_add(const mf_pairs *v, const mf_kernel *k, const double *f, double scale,
                      const uint8_t *imask, const uint8_t *jmask, double *out);
/* mf_number_density(v, imask, NULL, n) and, for the rows also in lmask,
 * mf_laplacian_add(v, k, f, scale, lmask, NULL, out), in one pass over the
 * pairs (the same sums, bit for bit); lmask within imask. */
void mf_laplacian_add_number_density(const mf_pairs *v, const mf_kernel *k, const double *f,
                                     double scale, const uint8_t *imask, const uint8_t *lmask,
                                     double *out, double *n);
/* eq. 27's viscous term with a pair viscosity: out_i += 2d/(lambda n0)
 * (1/rho_i) sum_j mu_ij (u_j - u_i) w_ij, mu_ij the pair average of mu
 * (mf_mu_pair) where j is in mu_mask, mu_i where it is not (3 components). */
void mf_laplacian_mu(const mf_pairs *v, const mf_kernel *k, const double *f, const double *mu,
                     int mu_average, const uint8_t *mu_mask, const double *rho,
                     const uint8_t *imask, double *out);

/* The higher-order Laplacian (Khayyer & Gotoh 2010, 2012; mf_weight_hl):
 * <lap f>_i = hl_coef sum_j (f_j - f_i) mf_weight_hl(|r_ij|), and its forms
 * for the viscous term as above (out = , out += scale, the pair viscosity). */
void mf_laplacian_hl(const mf_pairs *v, const mf_kernel *k, const double *f, int ncomp,
                     const uint8_t *imask, const uint8_t *jmask, double *out);
void mf_laplacian_hl_add(const mf_pairs *v, const mf_kernel *k, const double *f, double scale,
                         const uint8_t *imask, const uint8_t *jmask, double *out);
void mf_laplacian_hl_mu(const mf_pairs *v, const mf_kernel *k, const double *f, const double *mu,
                        int mu_average, const uint8_t *mu_mask, const double *rho,
                        const uint8_t *imask, double *out);

/* Dn/Dt_i = sum_j dw_ij/dt = sum_j -re (r_ij . u_ij) / |r_ij|^3 (Khayyer &
 * Gotoh 2009, the higher-order source term), re the view's radius. */
void mf_number_density_rate(const mf_pairs *v, const double *u, const uint8_t *imask,
                            const uint8_t *jmask, double *out);

/* (1/n0) sum_j r_ij/|r_ij| w_ij (3 per particle): zero inside a full
 * neighbourhood, about k->asym_flat on a flat free surface, pointing into
 * the fluid (free-surface detection by neighbour asymmetry). */
void mf_neighbour_asymmetry(const mf_pairs *v, const mf_kernel *k, const uint8_t *imask,
                            const uint8_t *jmask, double *out);
/* mf_number_density(v, imask, NULL, n) and, for the rows also in amask,
 * mf_neighbour_asymmetry(v, k, amask, NULL, asym), in one pass over the
 * pairs (the same sums, bit for bit); amask within imask. */
void mf_number_density_asymmetry(const mf_pairs *v, const mf_kernel *k, const uint8_t *imask,
                                 const uint8_t *amask, double *n, double *asym);
/* (d/n0) sum_j r_ij w_ij/|r_ij|^2 (3 per particle): the gradient of the
 * particle concentration in MPS form (eq. 5 on C = 1 without the f_i term),
 * pointing to where neighbours crowd (particle shifting). */
void mf_concentration_gradient(const mf_pairs *v, const mf_kernel *k, const uint8_t *imask,
                               const uint8_t *jmask, double *out);
/* eq. 5 on each velocity component: out[9 i + 3 a + b] = d u_a / d x_b. */
void mf_velocity_gradient(const mf_pairs *v, const mf_kernel *k, const double *u,
                          const uint8_t *imask, const uint8_t *jmask, double *out);

/* eq. 6: <div u>_i = d/n0 sum_j (u_j - u_i).r_ij/|r_ij|^2 w(|r_ij|). */
void mf_divergence(const mf_pairs *v, const mf_kernel *k, const double *u,
                   const uint8_t *imask, const uint8_t *jmask, double *out);

/* Collision model (Koshizuka lab's MPS codes): particle i (in movable)
 * and each neighbour j closer than the view's radius that it approaches
 * exchange momentum with restitution e, j taking the share rho_j/(rho_i +
 * rho_j) (rho NULL: 1/2), or all of it when j is not movable (a fixed wall
 * is infinitely heavy). Neighbours one after another in the view's order,
 * from vel_i; the new velocity of i into out (3 per particle; the movable
 * particles only). */
void mf_collision(const mf_pairs *v, const uint8_t *movable, const double *rho, double e,
                  const double *vel, double *out);

/* eq. 18: flag[i] = 1 where n[i] < beta n0 (free surface), else 0. */
void mf_free_surface(const double *n, size_t count, double beta, double n0, uint8_t *flag);

#pragma GCC visibility pop
#endif
