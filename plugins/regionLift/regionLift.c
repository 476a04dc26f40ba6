/* regionLift.c: a control force written by a user, built as a plugin: a
 * constant acceleration on the fluid inside a box, nothing elsewhere. It is
 * the smallest control force (the built-in ones, `mpsflow modules
 * attraction`, velocityRegion and pathFollow, are in
 * solvers/force/control/), and shows what one needs: a parameter table, a
 * create that keeps the settings, an accumulate that adds to acc only where
 * the force acts, and the exported registration function.
 *
 *   libs   ("libregionLift.so");                       // controlDict
 *   forces { lift { type regionLift; min (0 0 0); max (0.3 0.6 0);
 *                   acceleration (0 20 0); } }        // solverDict
 *
 * Built outside the tree against an installed mpsflow:
 *   cc -std=c11 $(pkg-config --cflags mpsflow) -shared -fPIC \
 *      -o libregionLift.so regionLift.c
 * (plugins/README.md). */
#include <stddef.h>
#include <stdlib.h>

#include "mf_error.h"
#include "mf_modules.h"

typedef struct lift_settings {
    double min[3], max[3], a[3];
} lift_settings;

static const mf_param lift_params[] = {
    {"min", MF_PARAM_VECTOR, "(0 0 0)", -1e6, 1e6, NULL, offsetof(lift_settings, min),
     "lower corner of the box, m"},
    {"max", MF_PARAM_VECTOR, "(1 1 1)", -1e6, 1e6, NULL, offsetof(lift_settings, max),
     "upper corner of the box, m"},
    {"acceleration", MF_PARAM_VECTOR, "(0 0 0)", -1e6, 1e6, NULL, offsetof(lift_settings, a),
     "added to the fluid particles inside the box, m/s^2"},
};

static int lift_create(const void *settings, mf_sim *sim, void **data)
{
    const lift_settings *given = settings;
    for (int c = 0; c < sim->dim; c++)
        if (!(given->max[c] > given->min[c]))
            return MF_ERROR(MF_ERR_INPUT, "regionLift: max must exceed min on every axis "
                            "(axis %d: %g, %g)", c, given->min[c], given->max[c]);
    lift_settings *s = malloc(sizeof *s);
    if (!s)
        return MF_ERROR(MF_ERR_MEMORY, "regionLift: out of memory");
    *s = *given;
    *data = s;
    return 0;
}

static int lift_accumulate(void *data, const mf_sim *sim, double *acc)
{
    const lift_settings *s = data;
    const mf_particles *p = sim->p;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *x = &p->pos[3 * i];
        bool inside = true;
        for (int c = 0; c < p->dim; c++)
            inside = inside && x[c] >= s->min[c] && x[c] <= s->max[c];
        if (inside)
            for (int c = 0; c < 3; c++)
                acc[3 * i + c] += s->a[c];
    }
    return 0;
}

static void lift_destroy(void *data) { free(data); }

static const mf_force_ops lift_ops = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "regionLift",
             "a constant acceleration on the fluid inside a box (a user's control force)",
             lift_params, sizeof lift_params / sizeof lift_params[0], sizeof(lift_settings)},
    .create = lift_create,
    .accumulate = lift_accumulate,
    .destroy = lift_destroy,
};

/* The host calls mf_plugin_register_<library name without lib and .so>. */
int mf_plugin_register_regionLift(mf_registry *reg);
int mf_plugin_register_regionLift(mf_registry *reg)
{
    return mf_registry_add(reg, &lift_ops.info);
}
