/* multifluid.h: the multi-fluid MPS solver (the paper's section 3.4).
 *
 * Particles carry a fluid id (the FluidId field, which exists only with
 * more than one fluid in constant/fluids); each fluid has its density,
 * viscosity and surface tension. The solver composes the MPS module:
 *
 *   explicit phase   eq. 27, u* = u + dt (nu_x <lap u> + f_st/rho_x + g),
 *                    unlike pairs through the pair viscosity mu_ij
 *                    (harmonic mean by default);
 *   pressure         the variable-density PPE div((1/rho) grad p) =
 *                    (1/dt^2)(n* - n0)/n0 with a symmetric pair average
 *                    1/rho_ij (1/rho_bar, rho_bar the arithmetic mean by
 *                    default), then u' = -dt (1/rho_ij) <grad p>;
 *                    - density ratio below densityRatioThreshold: one solve;
 *                    - above: the paper's iterative two-step computation
 *                      (multifluid_pressure.c): solve as if every particle
 *                      were the light fluid, hold that pressure on the
 *                      heavy fluid's interface and solve the heavy fluid,
 *                      correct both, and repeat at the corrected positions
 *                      until they move by less than outerTolerance l0.
 *
 * With surfaceTension's `freeSurface pressure` (one solve per step) the
 * free-surface particles hold the Laplace pressure sigma kappa instead of 0
 * (multifluid_surface.c).
 *
 * With one fluid there is no FluidId field and a step is mps_lagrangian_step
 * itself: the MPS result, bit for bit (with freeSurface pressure, its phases
 * with the surface pressure and correction of multifluid_surface.c).
 */
#ifndef MULTIFLUID_H
#define MULTIFLUID_H

#include <stdbool.h>
#include <stdint.h>

#include "mf_modules.h"
#include "solver/mps/mps.h"

typedef struct multifluid_settings {
    mps_settings mps;          /* first: the MPS entries of the table use its offsets */
    double ratio_threshold;    /* densityRatioThreshold */
    const char *density_average;   /* arithmetic | harmonic (of rho, in 1/rho_ij) */
    const char *viscosity_average; /* harmonic | arithmetic (of mu = rho nu) */
    long max_outer;            /* maxOuterIterations */
    double outer_tolerance;    /* in l0: converged when max |dr| of an iteration is below */
} multifluid_settings;

typedef struct multifluid_data {
    multifluid_settings s;
    mps_data *mps;
    int f_fluid;               /* FluidId, or -1 with one fluid */
    int f_light_pressure;      /* LightPressure (iterative mode), or -1 */
    bool iterative;
    bool surface_pressure;     /* surfaceTension freeSurface pressure: p = sigma kappa, eq. 18 */
    double ratio;              /* largest / smallest density */
    double rho_min, rho_max;
    bool heavy[MF_MAX_FLUIDS]; /* fluids solved in the heavy step (rho >= threshold rho_min) */
    /* Per particle, refreshed every step (particles are reordered). */
    size_t cap;
    double *rho, *rho_light, *mu;
    double *p_dirichlet, *p_prev, *grad_prev;
    uint8_t *in_all, *light_mask, *heavy_mask, *heavy_rows;
    /* Statistics. */
    long outer_total, outer_max, unconverged, iterative_steps;
} multifluid_data;

extern const mf_solver_ops mf_solver_multiFluid;
#define MULTIFLUID_NPARAMS (MPS_NPARAMS + 5)
extern const mf_param multifluid_params[MULTIFLUID_NPARAMS];

/* multifluid_module.c */
int multifluid_reserve(multifluid_data *d, size_t n);

/* multifluid_step.c: density, light density and viscosity per particle
 * (walls: the w-weighted mean density of their fluid neighbours). */
int multifluid_fill_properties(multifluid_data *d, const mf_sim *sim);
int multifluid_step(multifluid_data *d, mf_sim *sim, double dt);

/* multifluid_pressure.c: the iterative two-step pressure (section 3.4). */
int multifluid_iterative_pressure(multifluid_data *d, mf_sim *sim, double dt);

/* multifluid_surface.c: surfaceTension's freeSurface pressure. The
 * pressure phase with p = sigma kappa held on the free surface (eq. 18),
 * and the correction (eq. 15) with the surface particles' own pressure. */
int multifluid_surface_pressure_phase(multifluid_data *d, mf_sim *sim, double dt);
int multifluid_surface_correction(multifluid_data *d, mf_sim *sim, double dt);

#endif
