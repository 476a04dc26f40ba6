/* gravity.c: a uniform body force g (eq. 9's g). */
#include <stddef.h>
#include <stdlib.h>

#include "forces.h"
#include "mf_error.h"

typedef struct gravity_settings {
    double g[3];
} gravity_settings;

static const mf_param gravity_params[] = {
    {"g", MF_PARAM_VECTOR, "(0 -9.81 0)", -1e6, 1e6, NULL, offsetof(gravity_settings, g),
     "acceleration of gravity, m/s^2"},
};

static int gravity_create(const void *settings, mf_sim *sim, void **data)
{
    gravity_settings *s = malloc(sizeof *s);
    if (!s)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    *s = *(const gravity_settings *)settings;
    for (int c = 0; c < 3; c++) /* for the watch's available energy (mf_sim.h) */
        sim->gravity[c] += s->g[c];
    *data = s;
    return 0;
}

static int gravity_accumulate(void *data, const mf_sim *sim, double *acc)
{
    const gravity_settings *s = data;
    const mf_particles *p = sim->p;
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->kind[i] == MF_FLUID)
            for (int c = 0; c < 3; c++)
                acc[3 * i + c] += s->g[c];
    return 0;
}

static void gravity_destroy(void *data) { free(data); }

const mf_force_ops mf_force_gravity = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "gravity", "uniform gravitational acceleration g",
             gravity_params, 1, sizeof(gravity_settings)},
    .create = gravity_create,
    .accumulate = gravity_accumulate,
    .destroy = gravity_destroy,
};
