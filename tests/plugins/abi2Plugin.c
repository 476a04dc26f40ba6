/* abi2Plugin.c: a plugin for tests only whose tables are those of a plugin
 * built against the version-2 headers (before the metric kind): a force,
 * whose version-2 layout is the current one (ABI 3 added a kind, not a
 * slot), and a metric that claims version 2, which cannot exist. The host
 * must take the force and refuse the metric, saying why
 * (tests/test_registry.c). */
#include <stddef.h>

#include "mf_error.h"
#include "mf_modules.h"

typedef struct push_settings {
    double a;
} push_settings;

static const mf_param push_params[] = {
    {"a", MF_PARAM_SCALAR, "1", -1e9, 1e9, NULL, offsetof(push_settings, a),
     "acceleration along x, m/s^2"},
};

static int push_create(const void *settings, mf_sim *sim, void **data)
{
    (void)sim;
    *data = (void *)settings;
    return 0;
}

static int push_accumulate(void *data, const mf_sim *sim, double *acc)
{
    const push_settings *s = data;
    for (size_t i = 0; i < sim->p->n_owned; i++)
        acc[3 * i] += s->a;
    return 0;
}

static void push_destroy(void *data) { (void)data; }

/* abi_version 2: what MF_ABI_VERSION was when this plugin was built. */
static const mf_force_ops abi2_force = {
    .info = {2, MF_KIND_FORCE, "abi2Push", "a force of a version-2 plugin (tests)", push_params,
             1, sizeof(push_settings)},
    .create = push_create,
    .accumulate = push_accumulate,
    .destroy = push_destroy,
};

static int no_evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    (void)settings;
    (void)ctx;
    *error = 0;
    return 0;
}

static const mf_metric_ops abi2_metric = {
    .info = {2, MF_KIND_METRIC, "abi2Metric", "a metric claiming version 2 (tests)", NULL, 0, 0},
    .evaluate = no_evaluate,
};

int mf_plugin_register_abi2Plugin(mf_registry *reg);
int mf_plugin_register_abi2Plugin(mf_registry *reg)
{
    MF_CALL(mf_registry_add(reg, &abi2_force.info));
    /* Refused: the registry's error is the test's to read. */
    return mf_registry_add(reg, &abi2_metric.info);
}
