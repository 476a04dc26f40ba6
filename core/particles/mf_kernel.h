/* mf_kernel.h: the MPS kernel weight, the constants of a full lattice, and
 * the pair terms of the MPS operators. The physics of one particle pair
 * lives here as small pure inline functions; the loops that call them are
 * the pair engine's (mf_pairs.h), the operators in operators.c. Each term
 * keeps the order of its floating-point operations: the operators' results
 * are the same bit for bit whichever loop runs them. */
#ifndef MF_KERNEL_H
#define MF_KERNEL_H

#include <math.h>

/* eq. 3: w(r) = re/r - 1 for 0 < r < re, else 0 */
static inline double mf_weight(double r, double re)
{
    return (r > 0.0 && r < re) ? re / r - 1.0 : 0.0;
}

/* Pair averages (eq. 27 with unlike neighbours; the variable-density PPE).
 * Density: 1/rho_ij = 1/rho_bar_ij with rho_bar the arithmetic mean
 * (rho_i + rho_j)/2 (the default: the series coefficient of a flux across
 * an interface, as a finite-volume face would take it) or the harmonic
 * mean 2 rho_i rho_j/(rho_i + rho_j), i.e. 1/rho_ij = (1/rho_i + 1/rho_j)/2.
 * Viscosity: mu_ij harmonic (default) or arithmetic mean of mu = rho nu. */
typedef enum { MF_AVERAGE_ARITHMETIC = 0, MF_AVERAGE_HARMONIC = 1 } mf_average;

static inline double mf_inv_rho_pair(double rho_i, double rho_j, int average)
{
    return average == MF_AVERAGE_HARMONIC ? 0.5 * (1.0 / rho_i + 1.0 / rho_j)
                                          : 2.0 / (rho_i + rho_j);
}

static inline double mf_mu_pair(double mu_i, double mu_j, int average)
{
    if (average == MF_AVERAGE_ARITHMETIC)
        return 0.5 * (mu_i + mu_j);
    return mu_i + mu_j > 0.0 ? 2.0 * mu_i * mu_j / (mu_i + mu_j) : 0.0;
}

/* ---- pair terms (r_ij = r_j - r_i, len = |r_ij|, w = mf_weight(len, re)) */

/* eq. 5: the scalar s of the gradient term s r_ij, (f_j - f^_i) c_ij w /
 * |r_ij|^2 (c_ij = 1 without a pair coefficient). */
static inline double mf_gradient_term(double df, double c, double w, double len)
{
    return df * c * w / (len * len);
}

/* eq. 7 (eq. 27 with c = mu_ij): c_ij (f_j - f_i) w. */
static inline double mf_laplacian_term(double c, double df, double w)
{
    return c * df * w;
}

/* eq. 6: (u_j - u_i).r_ij w / |r_ij|^2, du.r given. */
static inline double mf_divergence_term(double du_dot_r, double w, double len)
{
    return du_dot_r * w / (len * len);
}

typedef struct mf_kernel {
    int dim;
    double l0;     /* initial particle spacing */
    double re;     /* interaction radius */
    double n0;     /* number density of a full interior lattice particle */
    double lambda; /* eq. 8, same lattice */
} mf_kernel;

/* n0 and lambda from the ideal full lattice (2-D square, 3-D cubic) of
 * spacing l0, every lattice point within re of the origin. */
int mf_kernel_init(mf_kernel *k, int dim, double l0, double re);

#endif
