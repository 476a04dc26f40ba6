/* quick.c: QUICK on the MAFL directional grid (eq. 25, Leonard 1979).
 *
 * Eq. 25 as printed is QUICK's face values with a forward-Euler step:
 *   f_i - q D,  D = 3/8 f_{i+1} + 3/8 f_i - 7/8 f_{i-1} + 1/8 f_{i-2}.
 * Expanded at the departure point f(x_i - q dr), its error per step is
 * q^2 dr^2 f''/2 + O(dr^3): the time-stepping term of order q^2, not the
 * spatial stencil, leads. Over a fixed time (steps ~ 1/(q dr)) that is an
 * error of order q dr: first order at a fixed Courant number, like upwind,
 * and anti-diffusive (the scheme grows smooth modes slowly and is unstable
 * for q above about 0.4 on long runs). tests/test_convection.c measures it.
 *
 * Leonard's QUICKEST ("QUICK with estimated streaming terms", Comput.
 * Methods Appl. Mech. Eng. 19, 1979) adds the terms of the Taylor series in
 * time. For point values on the MAFL grid they make the step the cubic
 * interpolation through f_{i-2} .. f_{i+1} at the departure point:
 *   f_i - q (D - (q/2) B + ((4 q^2 - 1)/24) T),
 *   B = f_{i+1} - 2 f_i + f_{i-1},  T = f_{i+1} - 3 f_i + 3 f_{i-1} - f_{i-2},
 * third order in space and time, stable for 0 <= q <= 1. That is the
 * default (streamingTerms yes); streamingTerms no is eq. 25 exactly.
 *
 * The filter (eq. 26) clips to [min, max] of the four grid values.
 */
#include <stddef.h>
#include <stdlib.h>

#include "convection.h"
#include "mf_error.h"

typedef struct quick_settings {
    bool filter;
    bool streaming;
} quick_settings;

static const mf_param quick_params[] = {
    {"filter", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL, offsetof(quick_settings, filter),
     "clip to [min, max] of f_{i-2} .. f_{i+1} (eq. 26): no over- or undershoot"},
    {"streamingTerms", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL,
     offsetof(quick_settings, streaming),
     "add Leonard's streaming (time) terms: third order; no: eq. 25 as printed (first order "
     "at a fixed Courant number)"},
};

static int quick_create(const void *settings, void **data)
{
    quick_settings *d = malloc(sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    *d = *(const quick_settings *)settings;
    *data = d;
    return 0;
}

static double quick_convect(const void *data, const double f[4], double q)
{
    const quick_settings *s = data;
    const double fm2 = f[0], fm1 = f[1], fi = f[2], fp1 = f[3];
    /* eq. 25: the difference of the QUICK face values
     * f_{i+1/2} = 6/8 f_i + 3/8 f_{i+1} - 1/8 f_{i-1} and its neighbour. */
    double flux = 0.375 * fp1 + 0.375 * fi - 0.875 * fm1 + 0.125 * fm2;
    if (s->streaming) {
        double curvature = fp1 - 2.0 * fi + fm1;
        double third = fp1 - 3.0 * fi + 3.0 * fm1 - fm2;
        flux += -0.5 * q * curvature + (4.0 * q * q - 1.0) / 24.0 * third;
    }
    double x = fi - q * flux;
    return s->filter ? mf_convection_clip(x, f, 0) : x;
}

static void quick_destroy(void *data) { free(data); }

const mf_convection_ops mf_convection_QUICK = {
    .info = {MF_ABI_VERSION, MF_KIND_CONVECTION, "QUICK",
             "QUICK along the streamline (eq. 25) with Leonard's streaming terms and the "
             "min/max filter (eq. 26)",
             quick_params, sizeof quick_params / sizeof quick_params[0], sizeof(quick_settings)},
    .create = quick_create,
    .convect = quick_convect,
    .destroy = quick_destroy,
};
