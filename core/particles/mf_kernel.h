/* mf_kernel.h: the MPS kernel weight, the constants of a full lattice, and
 * the pair terms of the MPS operators. The physics of one particle pair
 * lives here as small pure inline functions; the loops that call them are
 * the pair engine's (mf_pairs.h), the operators in operators.c. Each term
 * keeps the order of its floating-point operations: the operators' results
 * are the same bit for bit whichever loop runs them. */
#ifndef MF_KERNEL_H
#define MF_KERNEL_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <math.h>

/* eq. 3: w(r) = re/r - 1 for 0 < r < re, else 0 */
static inline double mf_weight(double r, double re)
{
    return (r > 0.0 && r < re) ? re / r - 1.0 : 0.0;
}

/* The pressure gradient's own weight (eq. 5's w, apart from the number
 * density's eq. 3). Eq. 5 is exact for a linear field on the full lattice
 * with any weight w_g if the sum is scaled by d / n0_g, n0_g the lattice
 * sum of w_g (mf_kernel.n0_grad), so the weight's shape is free. The choice
 * matters for the lattice's stability under eq. 5's pair repulsion (f_j -
 * f^_i) w_g r_ij / r^2: Dehnen & Aly (2012, MNRAS 425, 1068-1082) find that
 * SPH pair forces of magnitude -W'(r) keep particle lattices stable when
 * the kernel's Fourier transform is positive, as the Wendland functions'
 * is. MF_GRAD_WEIGHT_WENDLAND makes eq. 5's pair force that: w_g = -r
 * W'(r) for the Wendland C2 kernel W(q) = (1 - q)^4 (1 + 4q), q = r/re
 * (Wendland 1995; Dehnen & Aly's Table 1, the same form in 2-D and 3-D),
 * i.e. w_g = 20 q^2 (1 - q)^3 (its constant cancels in d / n0_g).
 * MF_GRAD_WEIGHT_WENDLAND_W takes W itself as w_g. */
typedef enum {
    MF_GRAD_WEIGHT_PAPER = 0,     /* w = re/r - 1 (eq. 3): the paper's */
    MF_GRAD_WEIGHT_WENDLAND = 1,  /* -r W'(r) of Wendland C2 */
    MF_GRAD_WEIGHT_WENDLAND_W = 2 /* Wendland C2's W(r) */
} mf_grad_weight;

static inline double mf_weight_wendland_drw(double r, double re)
{
    if (!(r > 0.0 && r < re))
        return 0.0;
    const double q = r / re, u = 1.0 - q;
    return 20.0 * q * q * u * u * u;
}

static inline double mf_weight_wendland(double r, double re)
{
    if (!(r > 0.0 && r < re))
        return 0.0;
    const double q = r / re, u = 1.0 - q;
    return u * u * u * u * (1.0 + 4.0 * q);
}

/* The gradient's weight of one pair (mf_weight for the paper's, the same
 * operations: eq. 5 stays bit for bit). */
static inline double mf_weight_gradient(double r, double re, int shape)
{
    return shape == MF_GRAD_WEIGHT_WENDLAND     ? mf_weight_wendland_drw(r, re)
           : shape == MF_GRAD_WEIGHT_WENDLAND_W ? mf_weight_wendland(r, re)
                                                : mf_weight(r, re);
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

/* The higher-order Laplacian of Khayyer & Gotoh (2010, Appl. Ocean Res. 32,
 * 124-131, eq. 20 in 2-D; 2012, Appl. Ocean Res. 37, 120-126, in 3-D): the
 * pair weight d^2w/dr^2 + (d - 3)/r dw/dr of w = re/r - 1, which is
 * (5 - d) re / r^3 for r < re. The papers scale the sum by 1/n0; on the
 * ideal lattice that gives <lap |x|^2> = 2d times 1.86 (2-D) or 1.08 (3-D)
 * at re = 3.1 l0, so here the scale comes from the lattice as lambda does for
 * eq. 7 (mf_kernel.hl_coef): the operator is exact for a quadratic there. */
static inline double mf_weight_hl(double r, double re, int dim)
{
    return (r > 0.0 && r < re) ? (5.0 - dim) * re / (r * r * r) : 0.0;
}

/* The time derivative of one pair's weight, dw/dt = dw/dr (r_ij . u_ij) /
 * |r_ij| = -re (r_ij . u_ij) / |r_ij|^3 (u_ij = u_j - u_i): the pair term of
 * Dn/Dt in the higher-order source term of Khayyer & Gotoh (2009, Coastal
 * Eng. 56, 419-440, eq. 11). */
static inline double mf_weight_rate_term(double r_dot_du, double len, double re)
{
    return (len > 0.0 && len < re) ? -re * r_dot_du / (len * len * len) : 0.0;
}

/* The weight of the least-squares operators (LSMPS, Tamai & Koshizuka 2014,
 * Comp. Part. Mech. 1, 277-305, eq. 15): (1 - r/re)^2 for r < re. */
static inline double mf_weight_ls(double r, double re)
{
    return (r > 0.0 && r < re) ? (1.0 - r / re) * (1.0 - r / re) : 0.0;
}

typedef struct mf_kernel {
    int dim;
    double l0;     /* initial particle spacing */
    double re;     /* interaction radius */
    double n0;     /* number density of a full interior lattice particle */
    double lambda; /* eq. 8, same lattice */
    /* 2d / sum_j |r_ij|^2 mf_weight_hl(|r_ij|) on the same lattice: the
     * scale of the higher-order Laplacian, <lap f>_i = hl_coef sum_j (f_j -
     * f_i) mf_weight_hl(|r_ij|). */
    double hl_coef;
    /* |sum_j r_ij/|r_ij| w_ij| / n0 for a particle on the flat free surface
     * of a half lattice (the neighbours with y <= 0): the scale of the
     * neighbour-asymmetry test of free-surface detection. */
    double asym_flat;
    /* The pressure gradient's weight (mf_grad_weight, mf_weight_gradient)
     * and its lattice sum n0_g: eq. 5 is scaled by d / n0_grad. With the
     * paper's weight n0_grad == n0. Only eq. 5 (mf_gradient_ex) reads
     * them; the divergence, the shifting's gradients and the wall terms
     * keep w = re/r - 1 and n0. */
    int grad_weight;
    double n0_grad;
} mf_kernel;

/* n0, lambda, hl_coef and asym_flat from the ideal full lattice (2-D square,
 * 3-D cubic) of spacing l0, every lattice point within re of the origin. */
int mf_kernel_init(mf_kernel *k, int dim, double l0, double re);
/* The pressure gradient's weight shape (mf_grad_weight) and its n0_grad,
 * summed over the same ideal lattice as n0 (mf_kernel_init first). */
int mf_kernel_set_gradient_weight(mf_kernel *k, int shape);

#pragma GCC visibility pop
#endif
