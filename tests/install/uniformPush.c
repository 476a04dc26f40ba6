/* uniformPush.c: a force module built outside the tree, against an
 * installed mpsflow (tests/test_install.sh):
 *   cc $(pkg-config --cflags mpsflow) -shared -fPIC -o libuniformPush.so uniformPush.c
 * It adds one constant acceleration to every fluid particle:
 *   forces { push { type uniformPush; acceleration (2 0 0); } }
 * with libs ("libuniformPush.so"); in controlDict. */
#include <stddef.h>
#include <stdlib.h>

#include "mf_error.h"
#include "mf_modules.h"

typedef struct push_settings {
    double a[3];
} push_settings;

static const mf_param push_params[] = {
    {"acceleration", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL,
     offsetof(push_settings, a), "added to every fluid particle, m/s^2"},
};

static int push_create(const void *settings, mf_sim *sim, void **data)
{
    (void)sim;
    push_settings *s = malloc(sizeof *s);
    if (!s)
        return MF_ERROR(MF_ERR_MEMORY, "uniformPush: out of memory");
    *s = *(const push_settings *)settings;
    *data = s;
    return 0;
}

static int push_accumulate(void *data, const mf_sim *sim, double *acc)
{
    const push_settings *s = data;
    for (size_t i = 0; i < sim->p->n_owned; i++)
        if (sim->p->kind[i] == MF_FLUID)
            for (int c = 0; c < 3; c++)
                acc[3 * i + c] += s->a[c];
    return 0;
}

static void push_destroy(void *data) { free(data); }

static const mf_force_ops uniform_push_ops = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "uniformPush",
             "a constant acceleration of the fluid (out-of-tree plugin example)", push_params, 1,
             sizeof(push_settings)},
    .create = push_create,
    .accumulate = push_accumulate,
    .destroy = push_destroy,
};

int mf_plugin_register_uniformPush(mf_registry *reg);
int mf_plugin_register_uniformPush(mf_registry *reg)
{
    return mf_registry_add(reg, &uniform_push_ops.info);
}
