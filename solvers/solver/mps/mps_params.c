/* mps_params.c: the parameters of the MPS solver, with the paper's defaults. */
#include <stddef.h>

#include "mps.h"

#define MPS_OFFSET(field) offsetof(mps_settings, field)
const mf_param mps_params[MPS_NPARAMS] = {MPS_PARAM_ENTRIES(MPS_OFFSET, "robust")};
/* Too many entries fail to compile; too few leave a nameless entry, which
 * the registry refuses at start-up. */

const char *const mps_viscosity_choices[] = {"explicit", "implicit", NULL};
/* gradientWeight, in mf_grad_weight order (mps_module.c: gradient_weight). */
const char *const mps_gradient_weight_choices[] = {"paper", "wendland", "wendlandW", NULL};
