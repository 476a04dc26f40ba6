/* module.c: create the settings of a module from a dictionary. */
#include <stddef.h>
#include <stdlib.h>

#include "mf_error.h"
#include "mf_modules.h"

int mf_module_prepare(const mf_registry *reg, mf_module_kind kind, const char *name,
                      const mf_dict *dict, const char *const *extra_keys, mf_dict *resolved,
                      mf_module *out)
{
    out->info = NULL;
    out->settings = NULL;
    out->data = NULL;
    MF_CALL(mf_registry_find(reg, kind, name, &out->info));
    out->settings = calloc(1, out->info->settings_size ? out->info->settings_size : 1);
    if (!out->settings)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory creating module '%s'", name);
    if (dict)
        MF_CALL(mf_params_apply(out->info->params, out->info->nparams, dict, extra_keys,
                                out->settings, resolved));
    else
        MF_CALL(mf_params_defaults(out->info->params, out->info->nparams, out->settings));
    if (resolved && !dict) /* still record the defaults that were used */
        MF_CALL(mf_params_apply(out->info->params, out->info->nparams, NULL, NULL, out->settings,
                                resolved));
    return 0;
}

void mf_module_release(mf_module *m)
{
    free(m->settings);
    m->settings = NULL;
    m->info = NULL;
    m->data = NULL;
}

size_t mf_ops_size(mf_module_kind kind, int abi)
{
    if (abi < MF_ABI_OLDEST || abi > MF_ABI_VERSION)
        return 0;
    switch (kind) {
    case MF_KIND_SOLVER: return sizeof(mf_solver_ops);
    /* ABI 2 added solve_rows. */
    case MF_KIND_PRESSURE:
        return abi >= 2 ? sizeof(mf_pressure_ops) : offsetof(mf_pressure_ops, solve_rows);
    case MF_KIND_CONVECTION: return sizeof(mf_convection_ops);
    /* ABI 2 added flags and the slots after it. */
    case MF_KIND_FORCE: return abi >= 2 ? sizeof(mf_force_ops) : offsetof(mf_force_ops, flags);
    case MF_KIND_FUNCTION_OBJECT: return sizeof(mf_function_object_ops);
    case MF_KIND_SURFACE: return sizeof(mf_surface_ops);
    /* ABI 2 added purge. */
    case MF_KIND_WRITER: return abi >= 2 ? sizeof(mf_writer_ops) : offsetof(mf_writer_ops, purge);
    /* ABI 3 added the kind: an older module cannot be a metric. */
    case MF_KIND_METRIC: return abi >= 3 ? sizeof(mf_metric_ops) : 0;
    default: return 0;
    }
}
