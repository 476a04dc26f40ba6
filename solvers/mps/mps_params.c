/* mps_params.c: the parameters of the MPS solver, with the paper's defaults. */
#include <stddef.h>

#include "mps.h"

const mf_param mps_params[MPS_NPARAMS] = {
    /* 3.1 rather than Koshizuka & Oka's 2.1: on hydrostatic2D the resting
     * pressure comes out 7.5% high at the bottom with 2.1 and within 1% with
     * 3.1 (README, "Choices measured"). */
    {"reNumberDensity", MF_PARAM_SCALAR, "3.1", 1.01, 10, NULL,
     offsetof(mps_settings, re_number_density),
     "radius of the number density (source term, surface), in l0"},
    {"reGradient", MF_PARAM_SCALAR, "2.1", 1.01, 10, NULL, offsetof(mps_settings, re_gradient),
     "radius of the pressure gradient, in l0"},
    {"reLaplacian", MF_PARAM_SCALAR, "3.1", 1.01, 10, NULL, offsetof(mps_settings, re_laplacian),
     "radius of the Laplacian (viscosity, pressure equation), in l0"},
    {"beta", MF_PARAM_SCALAR, "0.97", 0.5, 1.0, NULL, offsetof(mps_settings, beta),
     "free surface where n* < beta n0 (eq. 18)"},
    {"relaxation", MF_PARAM_SCALAR, "1", 0.01, 1, NULL, offsetof(mps_settings, relaxation),
     "factor on the source term of the pressure equation (1: the paper)"},
    {"compressibility", MF_PARAM_SCALAR, "0", 0, 1e-3, NULL,
     offsetof(mps_settings, compressibility),
     "artificial compressibility, 1/Pa (adds rho c/dt^2 to the diagonal; 0: off)"},
    {"clipNegativePressure", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL,
     offsetof(mps_settings, clip_negative_pressure), "set negative pressures to zero"},
    {"gradientPmin", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL,
     offsetof(mps_settings, gradient_pmin),
     "pressure gradient with p_min of the neighbourhood (eq. 5 note)"},
    {"collision", MF_PARAM_BOOL, "no", MF_NO_RANGE, NULL, offsetof(mps_settings, collision),
     "push apart particles closer than collisionDistance (not in the paper)"},
    {"collisionDistance", MF_PARAM_SCALAR, "0.5", 0.1, 1, NULL,
     offsetof(mps_settings, collision_distance), "collision distance, in l0"},
    {"restitution", MF_PARAM_SCALAR, "0.2", 0, 1, NULL, offsetof(mps_settings, restitution),
     "coefficient of restitution of the collision model"},
    {"reorderInterval", MF_PARAM_INT, "25", 0, 1000000, NULL,
     offsetof(mps_settings, reorder_interval),
     "sort particles along cells every N steps for memory locality (0: never)"},
};
/* Too many entries fail to compile; too few leave a nameless entry, which
 * the registry refuses at start-up. */
