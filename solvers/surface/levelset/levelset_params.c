/* levelset_params.c: the parameters of the surface reconstruction modules
 * (levelSet, blobby) and of the `surface` function object / system/surfaceDict. */
#include <stddef.h>

#include "levelset.h"

static const char *const integrators[] = {"explicit", "imex", NULL};

const mf_param ls_params[LS_NPARAMS] = {
    {"gridSpacing", MF_PARAM_SCALAR, "0", 0, 1e3, NULL, offsetof(ls_settings, grid_spacing),
     "grid spacing of the level set, m, independent of the particles (0: half the particle "
     "spacing l0)"},
    /* r = 0.73 l0, cutoff 2.5 l0, T = -2: the zero level of a flat face of a
     * cubic lattice lies 0.497 l0 beyond the last particle layer (ls_field.c). */
    {"radius", MF_PARAM_SCALAR, "0.73", 0.05, 10, NULL, offsetof(ls_settings, radius),
     "r_i of eq. 31, in l0: each particle's f is 1/2 at this distance"},
    {"cutoff", MF_PARAM_SCALAR, "2.5", 0.5, 10, NULL, offsetof(ls_settings, cutoff),
     "support of the kernel, in l0: f is tapered by (1 - d^2/cutoff^2)^2 to zero"},
    {"kernelPower", MF_PARAM_INT, "2", 1, 8, NULL, offsetof(ls_settings, kernel_power),
     "k of eq. 31 (the paper: k = 1 oversmooths, k > 2 interpolates too little)"},
    {"threshold", MF_PARAM_SCALAR, "-2", -100, -1e-9, NULL, offsetof(ls_settings, threshold),
     "T of eq. 30, negative: the surface is where the kernel sum reaches -T"},
    /* Off by default: as reconstructed, eq. 32 shrinks a fast particle's
     * support to 1/(1 + s) of its volume, and fast fluid falls below T
     * (README, "Surface"). */
    {"anisotropic", MF_PARAM_BOOL, "no", MF_NO_RANGE, NULL, offsetof(ls_settings, anisotropic),
     "stretch each particle's distance along its velocity and shrink it across (eq. 32)"},
    {"alpha", MF_PARAM_SCALAR, "1", 0, 100, NULL, offsetof(ls_settings, alpha),
     "weight of F in eq. 29"},
    {"beta", MF_PARAM_SCALAR, "1", 0, 100, NULL, offsetof(ls_settings, beta),
     "weight of the mean curvature (made dimensionless with l0) in eq. 29"},
    {"integrator", MF_PARAM_WORD, "explicit", MF_NO_RANGE, integrators,
     offsetof(ls_settings, integrator),
     "pseudo-time integration: explicit (ARKODE ERKStep, damped Chebyshev stages at fixed "
     "steps) or imex (ARKStep, curvature implicit, SPGMR)"},
    {"tolerance", MF_PARAM_SCALAR, "0.03", 1e-8, 10, NULL, offsetof(ls_settings, tolerance),
     "converged when |d phi / d tau| within a cell of the surface falls below this (cells per "
     "unit pseudo-time)"},
    {"relTol", MF_PARAM_SCALAR, "1e-3", 1e-10, 1, NULL, offsetof(ls_settings, rel_tol),
     "ARKODE relative tolerance (imex: of the Newton iterations; explicit runs at fixed, "
     "stability-chosen steps and has no error test)"},
    {"absTol", MF_PARAM_SCALAR, "1e-3", 1e-12, 10, NULL, offsetof(ls_settings, abs_tol),
     "ARKODE absolute tolerance, grid cells (imex: of the Newton iterations)"},
    {"maxSteps", MF_PARAM_INT, "20000", 1, 1e9, NULL, offsetof(ls_settings, max_steps),
     "ARKODE steps per frame at most"},
    {"maxPseudoTime", MF_PARAM_SCALAR, "50", 0.5, 1e9, NULL,
     offsetof(ls_settings, max_pseudo_time), "pseudo-time per frame at most"},
    {"bandWidth", MF_PARAM_INT, "3", 2, 6, NULL, offsetof(ls_settings, band_width),
     "half-width of the evolved narrow band, cells"},
    {"warmStart", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL, offsetof(ls_settings, warm_start),
     "start each frame from the previous frame's phi (no: every frame from F = 0)"},
    {"maxMemory", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(ls_settings, max_memory),
     "memory the reconstruction may use, MB (0: 3/4 of the physical memory)"},
};

const mf_param blobby_params[BLOBBY_NPARAMS] = {
    {"gridSpacing", MF_PARAM_SCALAR, "0", 0, 1e3, NULL, offsetof(blobby_settings, grid_spacing),
     "grid spacing, m (0: half the particle spacing l0)"},
    /* R = 1.5 l0, iso 1.1: a flat face of a cubic lattice at 0.50 l0 beyond
     * the last particle layer (ripple +-0.03 l0). */
    {"radius", MF_PARAM_SCALAR, "1.5", 0.5, 10, NULL, offsetof(blobby_settings, radius),
     "support R of each particle's kernel (1 - d^2/R^2)^3, in l0"},
    {"isoValue", MF_PARAM_SCALAR, "1.1", 1e-6, 1e3, NULL, offsetof(blobby_settings, iso_value),
     "the surface is where the kernel sum equals this"},
    {"maxMemory", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(blobby_settings, max_memory),
     "memory the reconstruction may use, MB (0: 3/4 of the physical memory)"},
};

const mf_param surface_params[SURFACE_NPARAMS] = {
    {"method", MF_PARAM_WORD, "levelSet", MF_NO_RANGE, NULL, offsetof(surface_settings, method),
     "surface module: levelSet (eqs. 29-32) or blobby (fast preview)"},
    {"levelSetCoeffs", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL,
     offsetof(surface_settings, levelset_coeffs), "parameters of levelSet"},
    {"blobbyCoeffs", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL,
     offsetof(surface_settings, blobby_coeffs), "parameters of blobby"},
    {"writePLY", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL, offsetof(surface_settings, write_ply),
     "write binary PLY (Blender, MeshLab, ParaView)"},
    {"writeOBJ", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL, offsetof(surface_settings, write_obj),
     "write Wavefront OBJ (text)"},
};
