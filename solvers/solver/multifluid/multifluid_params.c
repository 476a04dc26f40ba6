/* multifluid_params.c: the parameters of the multi-fluid solver: those of
 * MPS (the same list, mps.h's MPS_PARAM_ENTRIES) and its own. */
#include <stddef.h>

#include "multifluid.h"

static const char *const averages[] = {"arithmetic", "harmonic", NULL};

#define MPS_OFFSET(field) offsetof(multifluid_settings, mps.field)
#define OWN(field) offsetof(multifluid_settings, field)

const mf_param multifluid_params[MULTIFLUID_NPARAMS] = {
    MPS_PARAM_ENTRIES(MPS_OFFSET, "stabilised")
    {"densityRatioThreshold", MF_PARAM_SCALAR, "10", 1, 1e12, NULL, OWN(ratio_threshold),
     "largest/smallest density below which one pressure solve per step is made; above it "
     "the iterative two-step solve (light fluid, then heavy fluid)"},
    {"densityAverage", MF_PARAM_WORD, "arithmetic", MF_NO_RANGE, averages,
     OWN(density_average),
     "pair density rho_ij of the PPE and the pressure gradient, 1/rho_ij = 1/rho_bar: "
     "arithmetic (rho_i + rho_j)/2 or harmonic 2 rho_i rho_j/(rho_i + rho_j)"},
    {"viscosityAverage", MF_PARAM_WORD, "harmonic", MF_NO_RANGE, averages,
     OWN(viscosity_average), "pair viscosity mu_ij between unlike particles (mu = rho nu)"},
    {"maxOuterIterations", MF_PARAM_INT, "10", 1, 1000, NULL, OWN(max_outer),
     "iterative pressure: at most this many light/heavy rounds per step"},
    {"outerTolerance", MF_PARAM_SCALAR, "1e-3", 1e-12, 1, NULL, OWN(outer_tolerance),
     "iterative pressure: converged when a round moves no particle by more than this, in l0 "
     "(its velocity by more than outerTolerance l0/dt)"},
};
