/* test_registry.c: the module registry and plugin loading.
 * argv[1]: the folder holding libkineticEnergy.so (the build's plugins/). */
#include <string.h>

#include "mf_hdf5.h"
#include "mf_modules.h"
#include "mf_solvers.h"
#include "mf_test.h"

typedef struct dummy_settings {
    double x;
} dummy_settings;

/* Two slots, the second left empty: a module that miscounts its table. */
static const mf_param dummy_params[2] = {
    {"x", MF_PARAM_SCALAR, "1", 0, 2, NULL, 0, "a number"},
};

static mf_force_ops make_force(const char *name, int abi, size_t nparams)
{
    mf_force_ops ops;
    memset(&ops, 0, sizeof ops);
    ops.info.abi_version = abi;
    ops.info.kind = MF_KIND_FORCE;
    ops.info.name = name;
    ops.info.summary = "test";
    ops.info.params = dummy_params;
    ops.info.nparams = nparams;
    ops.info.settings_size = sizeof(dummy_settings);
    return ops;
}

static void test_builtins_and_lookup(void)
{
    mf_registry *reg = NULL;
    CHECK_OK(mf_registry_create(&reg));
    CHECK_OK(mf_solvers_register_all(reg));
    CHECK_OK(mf_registry_add(reg, &mf_writer_hdf5.info));
    const mf_module_info *m = NULL;
    CHECK_OK(mf_registry_find(reg, MF_KIND_SOLVER, "MPS", &m));
    CHECK(m && strcmp(m->name, "MPS") == 0);
    CHECK_OK(mf_registry_find(reg, MF_KIND_PRESSURE, "PCG_BoomerAMG", &m));
    /* Unknown: the message lists the valid names and suggests the closest. */
    CHECK(mf_registry_find(reg, MF_KIND_PRESSURE, "PCG_BoomerAGM", &m) == MF_ERR_INPUT);
    const char *msg = mf_error_message();
    printf("unknown name: %s\n", msg);
    CHECK(strstr(msg, "PCG_BoomerAMG") && strstr(msg, "PCG_diagonal") && strstr(msg, "did you mean"));
    CHECK(m == NULL);
    mf_error_clear();
    /* The same name in another kind is someone else. */
    CHECK(mf_registry_find(reg, MF_KIND_FORCE, "MPS", &m) == MF_ERR_INPUT);
    mf_error_clear();
    CHECK(mf_registry_lookup_any(reg, "gravity") != NULL);
    CHECK(mf_registry_lookup_any(reg, "nothing") == NULL);
    /* Registering a built-in twice is refused. */
    CHECK(mf_solvers_register_all(reg) == MF_ERR_INPUT);
    printf("duplicate: %s\n", mf_error_message());
    CHECK(strstr(mf_error_message(), "already registered") != NULL);
    mf_error_clear();
    mf_registry_destroy(reg);
}

static void test_refusals(void)
{
    mf_registry *reg = NULL;
    CHECK_OK(mf_registry_create(&reg));
    mf_force_ops ok = make_force("good", MF_ABI_VERSION, 1);
    mf_force_ops dup = make_force("good", MF_ABI_VERSION, 1);
    mf_force_ops old = make_force("old", MF_ABI_VERSION + 1, 1);
    mf_force_ops noname = make_force("", MF_ABI_VERSION, 1);
    mf_force_ops badcount = make_force("miscounted", MF_ABI_VERSION, 2);
    mf_force_ops badkind = make_force("weird", MF_ABI_VERSION, 1);
    badkind.info.kind = (mf_module_kind)42;
    CHECK_OK(mf_registry_add(reg, &ok.info));
    CHECK(mf_registry_add(reg, &dup.info) == MF_ERR_INPUT);
    mf_error_clear();
    CHECK(mf_registry_add(reg, &old.info) == MF_ERR_INPUT);
    printf("ABI mismatch: %s\n", mf_error_message());
    CHECK(strstr(mf_error_message(), "ABI") != NULL);
    mf_error_clear();
    CHECK(mf_registry_add(reg, &noname.info) == MF_ERR_INPUT);
    mf_error_clear();
    CHECK(mf_registry_add(reg, &badcount.info) == MF_ERR_INPUT); /* reads a zeroed entry */
    mf_error_clear();
    CHECK(mf_registry_add(reg, &badkind.info) == MF_ERR_INPUT);
    mf_error_clear();
    CHECK(mf_registry_count(reg, MF_KIND_FORCE) == 1);
    mf_registry_destroy(reg);
}

static void test_plugin(const char *plugin_dir)
{
    mf_registry *reg = NULL;
    CHECK_OK(mf_registry_create(&reg));
    /* Not found: the message says where it looked and what to set. */
    CHECK(mf_registry_load_plugin(reg, "libnoSuchPlugin.so") == MF_ERR_INPUT);
    printf("missing plugin: %s\n", mf_error_message());
    CHECK(strstr(mf_error_message(), "MPSFLOW_PLUGIN_PATH") != NULL);
    mf_error_clear();
    /* A library without the registration function is refused. */
    CHECK(mf_registry_load_plugin(reg, "libm.so.6") == MF_ERR_INPUT);
    printf("not a plugin: %s\n", mf_error_message());
    mf_error_clear();
    /* Found through the plugin folder, by library name or short name. */
    mf_registry_set_plugin_dir(reg, plugin_dir);
    CHECK_OK(mf_registry_load_plugin(reg, "libkineticEnergy.so"));
    CHECK_OK(mf_registry_load_plugin(reg, "kineticEnergy")); /* already loaded: fine */
    const mf_module_info *m = NULL;
    CHECK_OK(mf_registry_find(reg, MF_KIND_FUNCTION_OBJECT, "kineticEnergy", &m));
    CHECK(m && m->abi_version == MF_ABI_VERSION);
    mf_registry_destroy(reg);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_registry PLUGIN_DIR\n");
        return 2;
    }
    test_builtins_and_lookup();
    test_refusals();
    test_plugin(argv[1]);
    return mf_test_summary("registry");
}
