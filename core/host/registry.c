/* registry.c: string-keyed lists of module tables, and plugin loading. */
#include "mf_registry.h"

#include <ctype.h>
#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_modules.h" /* mf_ops_size */

#define MF_MAX_PLUGINS 64

struct mf_registry {
    size_t n[MF_KIND_COUNT], cap[MF_KIND_COUNT];
    const mf_module_info **mod[MF_KIND_COUNT];
    void *plugin_handle[MF_MAX_PLUGINS];
    char *plugin_name[MF_MAX_PLUGINS];
    int nplugins;
    char *plugin_dir;
    /* Tables of older modules copied into the current layout (freed with
     * the registry). */
    void **upgraded;
    size_t nupgraded, cap_upgraded;
};

static const char *const kind_names[MF_KIND_COUNT] = {
    "solver", "pressure", "convection", "force", "functionObject", "surface", "writer", "metric",
};

const char *mf_module_kind_name(mf_module_kind kind)
{
    return (kind >= 0 && kind < MF_KIND_COUNT) ? kind_names[kind] : "unknown";
}

int mf_registry_create(mf_registry **out)
{
    *out = calloc(1, sizeof **out);
    if (!*out)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory creating the registry");
    return 0;
}

void mf_registry_destroy(mf_registry *reg)
{
    if (!reg)
        return;
    for (int k = 0; k < MF_KIND_COUNT; k++)
        free(reg->mod[k]);
    for (size_t i = 0; i < reg->nupgraded; i++)
        free(reg->upgraded[i]);
    free(reg->upgraded);
    /* Tables of a plugin live in its library: close those last. */
    for (int i = reg->nplugins - 1; i >= 0; i--) {
        dlclose(reg->plugin_handle[i]);
        free(reg->plugin_name[i]);
    }
    free(reg->plugin_dir);
    free(reg);
}

/* A table of an older layout: copy its mf_ops_size(kind, its version)
 * bytes into a zeroed table of the current layout, so the slots added since
 * read as NULL; nothing past the module's own table is read. */
static int upgrade_table(mf_registry *reg, const mf_module_info *m, const mf_module_info **out)
{
    const size_t old = mf_ops_size(m->kind, m->abi_version);
    const size_t now = mf_ops_size(m->kind, MF_ABI_VERSION);
    if (old == 0 || now < old)
        return MF_ERROR(MF_ERR_INTERNAL, "no table size for a %s module of ABI version %d",
                        kind_names[m->kind], m->abi_version);
    if (reg->nupgraded == reg->cap_upgraded) {
        size_t cap = reg->cap_upgraded ? 2 * reg->cap_upgraded : 8;
        if (mf_resize(&reg->upgraded, cap, sizeof *reg->upgraded))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory registering '%s'", m->name);
        reg->cap_upgraded = cap;
    }
    void *copy = calloc(1, now);
    if (!copy)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory registering '%s'", m->name);
    memcpy(copy, m, old);
    reg->upgraded[reg->nupgraded++] = copy;
    *out = copy;
    return 0;
}

int mf_registry_add(mf_registry *reg, const mf_module_info *m)
{
    if (!m || !m->name || !m->name[0])
        return MF_ERROR(MF_ERR_INPUT, "refusing to register a module without a name");
    if (m->abi_version > MF_ABI_VERSION || m->abi_version < MF_ABI_OLDEST)
        return MF_ERROR(MF_ERR_INPUT,
                        "module '%s' was built for module ABI version %d, this mpsflow reads "
                        "versions %d to %d: rebuild it against this version's headers",
                        m->name, m->abi_version, MF_ABI_OLDEST, MF_ABI_VERSION);
    if (m->kind < 0 || m->kind >= MF_KIND_COUNT)
        return MF_ERROR(MF_ERR_INPUT, "module '%s' has an unknown kind %d", m->name, (int)m->kind);
    if (mf_ops_size(m->kind, m->abi_version) == 0) /* a kind newer than the module's version */
        return MF_ERROR(MF_ERR_INPUT,
                        "module '%s' is a %s module, a kind added after the module ABI version "
                        "%d it was built for: rebuild it against this version's headers",
                        m->name, kind_names[m->kind], m->abi_version);
    if (m->nparams && !m->params)
        return MF_ERROR(MF_ERR_INPUT, "module '%s' declares %zu parameters but no table",
                        m->name, m->nparams);
    for (size_t i = 0; i < m->nparams; i++)
        if (!m->params[i].name || !m->params[i].doc)
            return MF_ERROR(MF_ERR_INPUT,
                            "module '%s': parameter %zu of %zu has no name or doc (is nparams "
                            "right?)",
                            m->name, i + 1, m->nparams);
    int k = m->kind;
    for (size_t i = 0; i < reg->n[k]; i++)
        if (strcmp(reg->mod[k][i]->name, m->name) == 0)
            return MF_ERROR(MF_ERR_INPUT, "a %s module named '%s' is already registered",
                            kind_names[k], m->name);
    if (reg->n[k] == reg->cap[k]) {
        size_t cap = reg->cap[k] ? 2 * reg->cap[k] : 8;
        if (mf_resize(&reg->mod[k], cap, sizeof *reg->mod[k]))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory registering '%s'", m->name);
        reg->cap[k] = cap;
    }
    const mf_module_info *table = m;
    if (m->abi_version < MF_ABI_VERSION)
        MF_CALL(upgrade_table(reg, m, &table));
    reg->mod[k][reg->n[k]++] = table;
    return 0;
}

int mf_registry_find(const mf_registry *reg, mf_module_kind kind, const char *name,
                     const mf_module_info **out)
{
    *out = NULL;
    if (kind < 0 || kind >= MF_KIND_COUNT)
        return MF_ERROR(MF_ERR_INTERNAL, "unknown module kind %d", (int)kind);
    const char *names[256] = {0};
    size_t n = reg->n[kind] < 256 ? reg->n[kind] : 256;
    for (size_t i = 0; i < reg->n[kind]; i++) {
        if (strcmp(reg->mod[kind][i]->name, name) == 0) {
            *out = reg->mod[kind][i];
            return 0;
        }
        if (i < n)
            names[i] = reg->mod[kind][i]->name;
    }
    char list[2048] = "";
    for (size_t i = 0; i < n; i++) {
        strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
        strncat(list, names[i], sizeof list - strlen(list) - 1);
    }
    const char *hint = mf_did_you_mean(name, names, n);
    return MF_ERROR(MF_ERR_INPUT, "unknown %s module '%s'%s%s%s; valid %s modules: %s",
                    kind_names[kind], name, hint ? " (did you mean '" : "", hint ? hint : "",
                    hint ? "'?)" : "", kind_names[kind], n ? list : "(none registered)");
}

const mf_module_info *mf_registry_lookup_any(const mf_registry *reg, const char *name)
{
    for (int k = 0; k < MF_KIND_COUNT; k++)
        for (size_t i = 0; i < reg->n[k]; i++)
            if (strcmp(reg->mod[k][i]->name, name) == 0)
                return reg->mod[k][i];
    return NULL;
}

size_t mf_registry_count(const mf_registry *reg, mf_module_kind kind)
{
    return (kind >= 0 && kind < MF_KIND_COUNT) ? reg->n[kind] : 0;
}

const mf_module_info *mf_registry_at(const mf_registry *reg, mf_module_kind kind, size_t i)
{
    return i < mf_registry_count(reg, kind) ? reg->mod[kind][i] : NULL;
}

void mf_registry_set_plugin_dir(mf_registry *reg, const char *dir)
{
    free(reg->plugin_dir);
    reg->plugin_dir = dir ? strdup(dir) : NULL;
}

/* "libfoo.so", "foo", "path/to/libfoo.so" -> "foo" (the registration
 * function is mf_plugin_register_foo). */
static int plugin_base_name(const char *lib, char *out, size_t len)
{
    const char *s = strrchr(lib, '/');
    s = s ? s + 1 : lib;
    if (strncmp(s, "lib", 3) == 0)
        s += 3;
    size_t n = strcspn(s, ".");
    if (n == 0 || n >= len)
        return MF_ERROR(MF_ERR_INPUT, "cannot derive a plugin name from library '%s'", lib);
    for (size_t i = 0; i < n; i++)
        if (!isalnum((unsigned char)s[i]) && s[i] != '_')
            return MF_ERROR(MF_ERR_INPUT,
                            "plugin library '%s': the name may hold only letters, digits and _",
                            lib);
    memcpy(out, s, n);
    out[n] = '\0';
    return 0;
}

static void *open_library(const mf_registry *reg, const char *lib, const char *base,
                          char *tried, size_t tried_len)
{
    char file[1024], path[4096];
    if (strchr(lib, '/') || strstr(lib, ".so"))
        snprintf(file, sizeof file, "%s", lib);
    else
        snprintf(file, sizeof file, "lib%s.so", base);
    tried[0] = '\0';
    /* As given (absolute, relative, or through the loader's own path). */
    void *h = dlopen(file, RTLD_NOW | RTLD_LOCAL);
    snprintf(tried, tried_len, "%s", file);
    if (h || strchr(file, '/'))
        return h;
    const char *env = getenv("MPSFLOW_PLUGIN_PATH");
    char dirs[4096] = "";
    if (env)
        snprintf(dirs, sizeof dirs, "%s", env);
    if (reg->plugin_dir)
        snprintf(dirs + strlen(dirs), sizeof dirs - strlen(dirs), "%s%s", dirs[0] ? ":" : "",
                 reg->plugin_dir);
    for (char *save = NULL, *d = strtok_r(dirs, ":", &save); d; d = strtok_r(NULL, ":", &save)) {
        snprintf(path, sizeof path, "%s/%s", d, file);
        size_t used = strlen(tried);
        snprintf(tried + used, tried_len - used, ", %s", path);
        h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (h)
            return h;
    }
    return NULL;
}

int mf_registry_load_plugin(mf_registry *reg, const char *lib)
{
    char base[256], tried[8192], symbol[300];
    MF_CALL(plugin_base_name(lib, base, sizeof base));
    for (int i = 0; i < reg->nplugins; i++)
        if (strcmp(reg->plugin_name[i], base) == 0)
            return 0; /* loaded already: `libs` may repeat a library */
    if (reg->nplugins == MF_MAX_PLUGINS)
        return MF_ERROR(MF_ERR_INPUT, "too many plugins (at most %d)", MF_MAX_PLUGINS);
    void *h = open_library(reg, lib, base, tried, sizeof tried);
    if (!h) {
        const char *why = dlerror();
        return MF_ERROR(MF_ERR_INPUT,
                        "cannot load plugin '%s' (tried %s): %s. Set MPSFLOW_PLUGIN_PATH to the "
                        "folder that holds it",
                        lib, tried, why ? why : "not found");
    }
    snprintf(symbol, sizeof symbol, "mf_plugin_register_%s", base);
    dlerror();
    int (*reg_fn)(mf_registry *);
    *(void **)&reg_fn = dlsym(h, symbol);
    if (!reg_fn) {
        dlclose(h);
        return MF_ERROR(MF_ERR_INPUT, "plugin '%s' has no function %s(mf_registry *)", lib,
                        symbol);
    }
    /* Keep the handle before registering: its tables must outlive the registry. */
    reg->plugin_handle[reg->nplugins] = h;
    reg->plugin_name[reg->nplugins] = strdup(base);
    if (!reg->plugin_name[reg->nplugins]) {
        dlclose(h);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    }
    reg->nplugins++;
    int rc = reg_fn(reg);
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    return 0;
}

void mf_registry_print(const mf_registry *reg, FILE *f)
{
    for (int k = 0; k < MF_KIND_COUNT; k++) {
        fprintf(f, "%s modules:\n", kind_names[k]);
        if (reg->n[k] == 0)
            fprintf(f, "    (none)\n");
        for (size_t i = 0; i < reg->n[k]; i++)
            fprintf(f, "    %-20s %s\n", reg->mod[k][i]->name, reg->mod[k][i]->summary);
    }
}
