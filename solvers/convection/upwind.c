/* upwind.c: the first-order upwind scheme of the MAFL Eulerian phase (eq. 24). */
#include <stddef.h>
#include <stdlib.h>

#include "convection.h"
#include "mf_error.h"

typedef struct upwind_settings {
    bool filter;
} upwind_settings;

static const mf_param upwind_params[] = {
    {"filter", MF_PARAM_BOOL, "no", MF_NO_RANGE, NULL, offsetof(upwind_settings, filter),
     "clip to [min, max] of f_{i-1}, f_i (eq. 26; upwind with q <= 1 needs none)"},
};

static int upwind_create(const void *settings, void **data)
{
    upwind_settings *d = malloc(sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    *d = *(const upwind_settings *)settings;
    *data = d;
    return 0;
}

/* eq. 24: f_i - q (f_i - f_{i-1}), linear interpolation between f_{i-1} and
 * f_i at the departure point. */
static double upwind_convect(const void *data, const double f[4], double q)
{
    const upwind_settings *s = data;
    double x = f[2] - q * (f[2] - f[1]);
    return s->filter ? mf_convection_clip(x, f, 1) : x;
}

static void upwind_destroy(void *data) { free(data); }

const mf_convection_ops mf_convection_upwind = {
    .info = {MF_ABI_VERSION, MF_KIND_CONVECTION, "upwind",
             "first-order upwind along the streamline (eq. 24)", upwind_params,
             sizeof upwind_params / sizeof upwind_params[0], sizeof(upwind_settings)},
    .create = upwind_create,
    .convect = upwind_convect,
    .destroy = upwind_destroy,
};
