/* mf_registry.h: the module registry (PETSc's string-keyed list, SQLite's
 * versioned tables).
 *
 * Contract:
 *  - A module is a const ops table that starts with mf_module_info. The
 *    kind-specific tables (mf_solver_ops, ... in mf_modules.h) only ever
 *    grow at the end; abi_version says which layout a module was built for.
 *  - Names are unique within a kind; a registered table never changes and
 *    must outlive the registry (static storage, or a plugin kept loaded).
 *  - Built-ins register through one explicit call (mf_register_builtins);
 *    a plugin "libNAME.so" exports `int mf_plugin_register_NAME(mf_registry *)`
 *    that the host calls after dlopen. No constructor magic, no other globals.
 *  - An unknown name fails with the list of valid names.
 */
#ifndef MF_REGISTRY_H
#define MF_REGISTRY_H

#include <stddef.h>
#include <stdio.h>

#include "mf_params.h"

#define MF_ABI_VERSION 1

typedef enum {
    MF_KIND_SOLVER,
    MF_KIND_PRESSURE,
    MF_KIND_CONVECTION,
    MF_KIND_FORCE,
    MF_KIND_FUNCTION_OBJECT,
    MF_KIND_SURFACE,
    MF_KIND_WRITER,
    MF_KIND_COUNT
} mf_module_kind;

typedef struct mf_module_info {
    int abi_version;        /* MF_ABI_VERSION at build time */
    mf_module_kind kind;
    const char *name;       /* unique within the kind; used in case files */
    const char *summary;    /* one line */
    const mf_param *params; /* may be NULL when nparams == 0 */
    size_t nparams;
    size_t settings_size;   /* size of the struct the params fill */
} mf_module_info;

typedef struct mf_registry mf_registry;

int mf_registry_create(mf_registry **out);
void mf_registry_destroy(mf_registry *reg); /* also dlcloses plugins */

/* Add a module. Refuses a NULL/empty name, a duplicate name within its kind,
 * an ABI version it does not know, and a kind out of range. */
int mf_registry_add(mf_registry *reg, const mf_module_info *module);

/* Find by kind and name. Unknown: MF_ERR_INPUT naming the valid choices. */
int mf_registry_find(const mf_registry *reg, mf_module_kind kind, const char *name,
                     const mf_module_info **out);
/* Find by name in any kind (for `mpsflow modules NAME`). NULL if none. */
const mf_module_info *mf_registry_lookup_any(const mf_registry *reg, const char *name);

size_t mf_registry_count(const mf_registry *reg, mf_module_kind kind);
const mf_module_info *mf_registry_at(const mf_registry *reg, mf_module_kind kind, size_t i);

/* Load a plugin: `lib` is "libNAME.so", "NAME", or a path. Searched as
 * given, then in each directory of MPSFLOW_PLUGIN_PATH, then beside the
 * executable's plugin folder given by mf_registry_set_plugin_dir. */
int mf_registry_load_plugin(mf_registry *reg, const char *lib);
void mf_registry_set_plugin_dir(mf_registry *reg, const char *dir);

const char *mf_module_kind_name(mf_module_kind kind);   /* "solver", "pressure", ... */
void mf_registry_print(const mf_registry *reg, FILE *f); /* `mpsflow modules` */

#endif
