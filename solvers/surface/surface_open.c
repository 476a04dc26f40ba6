/* surface_open.c: open a surface module from a dictionary laid out as
 * system/surfaceDict (`method`, <method>Coeffs), shared by the `surface`
 * function object and `mpsflow surface`. */
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "surface/levelset/levelset.h"

int surface_open(const mf_registry *reg, const mf_dict *dict, const char *method_override,
                 const char *const *extra_keys, mf_dict *resolved, surface_settings *s,
                 mf_module *m)
{
    /* Keys allowed besides the table: the caller's, and <name>Coeffs of any
     * registered surface module (plugins included). */
    size_t ns = mf_registry_count(reg, MF_KIND_SURFACE), ne = 0;
    while (extra_keys && extra_keys[ne])
        ne++;
    char(*names)[128] = calloc(ns + 1, sizeof *names);
    const char **extra = calloc(ns + ne + 1, sizeof *extra);
    if (!names || !extra) {
        free(names);
        free(extra);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    }
    size_t k = 0;
    for (size_t i = 0; i < ne; i++)
        extra[k++] = extra_keys[i];
    for (size_t i = 0; i < ns; i++) {
        snprintf(names[i], sizeof names[i], "%sCoeffs",
                 mf_registry_at(reg, MF_KIND_SURFACE, i)->name);
        extra[k++] = names[i];
    }
    extra[k] = NULL;
    int rc = mf_params_apply(surface_params, SURFACE_NPARAMS, dict, extra, s, resolved);
    free(names);
    free(extra);
    MF_CALL(rc);
    if (method_override)
        s->method = method_override;
    char key[160];
    snprintf(key, sizeof key, "%sCoeffs", s->method);
    const mf_dict *coeffs = dict ? mf_dict_subdict(dict, key) : NULL;
    mf_dict *rsub = resolved ? mf_dict_set_subdict(resolved, key) : NULL;
    if (resolved) {
        MF_CALL(mf_dict_set_word(resolved, "method", s->method));
    }
    MF_CALL(mf_module_prepare(reg, MF_KIND_SURFACE, s->method, coeffs, NULL, rsub, m));
    const mf_surface_ops *ops = (const mf_surface_ops *)m->info;
    if (!ops->reconstruct)
        return MF_ERROR(MF_ERR_INPUT, "surface module '%s' has no reconstruct function",
                        s->method);
    MF_CALL(ops->create(m->settings, &m->data));
    return 0;
}

void surface_close(mf_module *m)
{
    if (m->info && m->data)
        ((const mf_surface_ops *)m->info)->destroy(m->data);
    m->data = NULL;
    mf_module_release(m);
}
