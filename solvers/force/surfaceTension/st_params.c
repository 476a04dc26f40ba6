/* st_params.c: the parameters of the surfaceTension force. */
#include <stddef.h>

#include "surface_tension.h"

static const char *const curvature_models[] = {"exact", "paper", "normal", NULL};
static const char *const free_surface_models[] = {"force", "pressure", NULL};

const mf_param st_params[] = {
    {"radius", MF_PARAM_SCALAR, "4.1", 1.5, 10, NULL, offsetof(st_settings, radius),
     "r_st, the radius of the surface-tension number densities (eqs. 34-37), in l0"},
    {"curvature", MF_PARAM_WORD, "normal", MF_NO_RANGE, curvature_models,
     offsetof(st_settings, curvature),
     "kappa from n^st2: exact (disk/ball intersection) or paper (eqs. 38-39, 2/3 of it); "
     "or normal: the divergence of the interface normal (Brackbill et al. 1992)"},
    {"beta", MF_PARAM_SCALAR, "0.85", 0.5, 1, NULL, offsetof(st_settings, beta),
     "free-surface interface where fewer than beta N_full particles lie within r_st"},
    {"dtFactor", MF_PARAM_SCALAR, "1", 0.01, 10, NULL, offsetof(st_settings, dt_factor),
     "dt <= dtFactor sqrt(rho l0^3 / (2 pi sigma)) (Brackbill et al. 1992); rho: the pair's "
     "mean density"},
    {"smoothing", MF_PARAM_INT, "1", 0, 10, NULL, offsetof(st_settings, smoothing),
     "passes of curvature averaging over the free-surface particles within r_st (0: none)"},
    {"freeSurface", MF_PARAM_WORD, "force", MF_NO_RANGE, free_surface_models,
     offsetof(st_settings, free_surface),
     "a free surface of a fluid with sigma > 0: force (eq. 33 on its interface band; its "
     "free-surface particles keep p = 0, eq. 18) or pressure (they hold the Laplace "
     "pressure sigma kappa instead, and no force acts there; needs solver multiFluid with "
     "one pressure solve per step)"},
    {"interfaces", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(st_settings, interfaces),
     "tension of fluid pairs: name { fluids (a b); sigma 0.03; } (else |sigma_a - sigma_b|)"},
};
