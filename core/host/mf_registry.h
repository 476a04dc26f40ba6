/* mf_registry.h: the module registry (PETSc's string-keyed list, SQLite's
 * versioned tables).
 *
 * Contract:
 *  - A module is a const ops table that starts with mf_module_info. The
 *    kind-specific tables (mf_solver_ops, ... in mf_modules.h) only ever
 *    grow at the end; abi_version says which layout a module was built for.
 *    mf_module_info itself never changes.
 *  - Older tables are accepted (any version from MF_ABI_OLDEST on): the
 *    registry knows each kind's table size at each version (mf_ops_size),
 *    copies the module's table, that many bytes and no more, into a zeroed
 *    table of the current layout, and hands out the copy, so the slots the
 *    module's version did not have read as NULL (absent optional slots) and
 *    nothing past the end of the module's table is ever read. A table newer
 *    than this host is refused: it may rely on slots the host never calls.
 *  - Names are unique within a kind; a registered table never changes and
 *    must outlive the registry (static storage, or a plugin kept loaded).
 *  - Built-ins register through one explicit call (mf_register_builtins);
 *    a plugin "libNAME.so" exports `int mf_plugin_register_NAME(mf_registry *)`
 *    that the host calls after dlopen. No constructor magic, no other globals.
 *  - An unknown name fails with the list of valid names.
 */
#ifndef MF_REGISTRY_H
#define MF_REGISTRY_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stddef.h>
#include <stdio.h>

#include "mf_params.h"

/* Versions of the tables' layout (mf_modules.h lists what each added):
 *   1  the first tables;
 *   2  force: flags, stable_dt, write_fields, claim_surface_pressure,
 *      surface_pressure; pressure: solve_rows; writer: purge;
 *   3  the metric kind (mf_metric_ops). */
#define MF_ABI_VERSION 3
#define MF_ABI_OLDEST 1

typedef enum {
    MF_KIND_SOLVER,
    MF_KIND_PRESSURE,
    MF_KIND_CONVECTION,
    MF_KIND_FORCE,
    MF_KIND_FUNCTION_OBJECT,
    MF_KIND_SURFACE,
    MF_KIND_WRITER,
    MF_KIND_METRIC, /* ABI 3 */
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
 * an ABI version outside [MF_ABI_OLDEST, MF_ABI_VERSION], and a kind out of
 * range. The tables that find and at return are of the current layout: the
 * module's own, or the registry's upgraded copy of an older one. */
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

#pragma GCC visibility pop
#endif
