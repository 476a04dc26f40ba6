/* mafl_params.c: the parameters of MPS-MAFL. The Lagrangian phase takes the
 * MPS module's own entries (one list, in mps.h), so MAFLCoeffs accepts
 * every MPSCoeffs key with the same defaults. */
#include <stddef.h>

#include "mafl.h"

static const char *const rules[] = {"fixed", "fraction", "relax", "lagrangian", NULL};
static const char *const references[] = {"n0", "startOfStep", "divergence", NULL};

#define MAFL_MPS_OFFSET(field) offsetof(mafl_settings, mps.field)
#define MAFL_OFFSET(field) offsetof(mafl_settings, field)

const mf_param mafl_params[MAFL_NPARAMS] = {
    MPS_PARAM_ENTRIES(MAFL_MPS_OFFSET, "paper")
    {"reconfiguration", MF_PARAM_WORD, "fixed", MF_NO_RANGE, rules,
     MAFL_OFFSET(reconfiguration),
     "where interior points go: fixed (the Eulerian limit), fraction (of the flow), relax "
     "(the flow, shifted toward even spacing), lagrangian (the flow: pure MPS)"},
    {"densityReference", MF_PARAM_WORD, "n0", MF_NO_RANGE, references,
     MAFL_OFFSET(density_reference),
     "source of the pressure equation: n0, (n* - n0)/n0 as in MPS; startOfStep, the "
     "compression of this step's motion only; divergence, the same linearised in every pair "
     "(-rho/dt <div u*>: keeps the flow rate along a channel). The last two are for flows "
     "without a free surface: a uniform flow along walls stays exactly uniform"},
    {"fraction", MF_PARAM_SCALAR, "0.5", 0, 1, NULL, MAFL_OFFSET(fraction),
     "rule fraction: interior points move this share of their Lagrangian displacement"},
    {"shift", MF_PARAM_SCALAR, "0.05", 0, 1, NULL, MAFL_OFFSET(shift),
     "rule relax: strength of the shift toward an even distribution (at most 0.2 l0 a step)"},
    {"surfaceShift", MF_PARAM_SCALAR, "0.1", 0, 0.5, NULL, MAFL_OFFSET(surface_shift),
     "free-surface points move this share toward the mean of their surface neighbours, "
     "along the surface (0: pure Lagrangian)"},
    {"gridSpacing", MF_PARAM_SCALAR, "1", 0.1, 4, NULL, MAFL_OFFSET(grid_spacing),
     "dr, the spacing of the 1-D grid along each streamline, in l0"},
    {"reInterpolation", MF_PARAM_SCALAR, "2.1", 1.01, 4, NULL, MAFL_OFFSET(re_interpolation),
     "radius of the weight w = re/r - 1 of eq. 23, in l0"},
    {"diskThickness", MF_PARAM_SCALAR, "1", 0.1, 4, NULL, MAFL_OFFSET(disk_thickness),
     "thickness of the disk around a grid point whose neighbours give its value (eq. 23), in dr"},
    {"convection", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, MAFL_OFFSET(convection),
     "{ scheme QUICK; ... }: the convection module (upwind, QUICK, or a plugin's) and its "
     "parameters (mpsflow modules QUICK)"},
    {"addPoints", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL, MAFL_OFFSET(add_points),
     "fill holes inside the fluid with new points, valued from the closest old point (eq. 22)"},
    {"removeDistance", MF_PARAM_SCALAR, "0.5", 0, 0.95, NULL, MAFL_OFFSET(remove_distance),
     "of two fluid points closer than this (in l0) the newer is removed (0: never)"},
    {"holeDistance", MF_PARAM_SCALAR, "0.9", 0.5, 2, NULL, MAFL_OFFSET(hole_distance),
     "a lattice site with no point within this (in l0) ..."},
    {"holeDensity", MF_PARAM_SCALAR, "0.75", 0.3, 1, NULL, MAFL_OFFSET(hole_density),
     "... and at least this share of a full lattice site's neighbours within reNumberDensity "
     "is a hole"},
    {"holeSpacing", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL, MAFL_OFFSET(hole_spacing),
     "a new point goes l0 from its nearest point (along the line through the site) rather "
     "than onto the lattice site: holes found late by up to |u^c| dt are not packed"},
    {"separation", MF_PARAM_SCALAR, "0.6", 0, 0.95, NULL, MAFL_OFFSET(separation),
     "rules fraction and relax: fluid points closer than this (in l0) are moved apart, so that "
     "they need not merge (a merge removes a point's volume; 0: never)"},
};
