/* faultInjection.c: a force module for tests only, loaded as a plugin, that
 * breaks a run on purpose so that the run's watch can be seen to catch it.
 *   functions none; solverDict: forces { fault { type fault; nanAt 0.01; } }
 * nanAt T: from time T, the acceleration of the first fluid particle is NaN.
 * pushAt T, push A: from time T, the first fluid particle is accelerated by
 * A (a vector) on top of everything else: through a wall if A points at one.
 * scatterAt T, scatter S: from time T, every fluid particle is accelerated
 * away from the fluid's centroid c by S (x - c) (S in 1/s^2): the fluid
 * blows apart (the density-collapse case; the force's work is a source, so
 * the energy check does not see it). */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "mf_error.h"
#include "mf_modules.h"

typedef struct fault_settings {
    double nan_at, push_at, push[3];
    double scatter_at, scatter;
} fault_settings;

static const mf_param fault_params[] = {
    {"nanAt", MF_PARAM_SCALAR, "1e30", 0, 1e30, NULL, offsetof(fault_settings, nan_at),
     "time from which one particle's acceleration is NaN"},
    {"pushAt", MF_PARAM_SCALAR, "1e30", 0, 1e30, NULL, offsetof(fault_settings, push_at),
     "time from which one particle is pushed"},
    {"push", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, offsetof(fault_settings, push),
     "acceleration of the push, m/s^2"},
    {"scatterAt", MF_PARAM_SCALAR, "1e30", 0, 1e30, NULL, offsetof(fault_settings, scatter_at),
     "time from which the fluid is pushed apart"},
    {"scatter", MF_PARAM_SCALAR, "0", 0, 1e12, NULL, offsetof(fault_settings, scatter),
     "rate of the push apart, 1/s^2: a = scatter (x - centroid)"},
};

static int fault_create(const void *settings, mf_sim *sim, void **data)
{
    (void)sim;
    fault_settings *s = malloc(sizeof *s);
    if (!s)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    *s = *(const fault_settings *)settings;
    *data = s;
    return 0;
}

static int fault_accumulate(void *data, const mf_sim *sim, double *acc)
{
    const fault_settings *s = data;
    const mf_particles *p = sim->p;
    size_t first = 0;
    while (first < p->n_owned && p->kind[first] != MF_FLUID)
        first++;
    if (first == p->n_owned)
        return 0;
    if (sim->time >= s->scatter_at && s->scatter > 0) {
        double c[3] = {0, 0, 0};
        size_t n = 0;
        for (size_t i = 0; i < p->n_owned; i++)
            if (p->kind[i] == MF_FLUID) {
                for (int a = 0; a < 3; a++)
                    c[a] += p->pos[3 * i + a];
                n++;
            }
        for (size_t i = 0; i < p->n_owned; i++)
            if (p->kind[i] == MF_FLUID)
                for (int a = 0; a < 3; a++)
                    acc[3 * i + a] += s->scatter * (p->pos[3 * i + a] - c[a] / (double)n);
    }
    for (int c = 0; c < 3; c++) {
        if (sim->time >= s->nan_at)
            acc[3 * first + c] = NAN;
        if (sim->time >= s->push_at)
            acc[3 * first + c] += s->push[c];
    }
    return 0;
}

static void fault_destroy(void *data) { free(data); }

static const mf_force_ops fault_ops = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "fault", "breaks a run on purpose (tests only)",
             fault_params, 5, sizeof(fault_settings)},
    .create = fault_create,
    .accumulate = fault_accumulate,
    .destroy = fault_destroy,
};

int mf_plugin_register_faultInjection(mf_registry *reg);
int mf_plugin_register_faultInjection(mf_registry *reg)
{
    return mf_registry_add(reg, &fault_ops.info);
}
