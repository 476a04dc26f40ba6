/* test_registry.c: the module registry and plugin loading; a module table
 * of an older ABI version (read only as far as it goes, its missing slots
 * NULL); a plugin built for version 2. argv[1]: the folder holding
 * libkineticEnergy.so (the build's plugins/); argv[2]: the one holding
 * libabi2Plugin.so (the build's tests/). */
#include <math.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "mf_dictio.h"
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
    mf_force_ops newer = make_force("newer", MF_ABI_VERSION + 1, 1);
    mf_force_ops ancient = make_force("ancient", MF_ABI_OLDEST - 1, 1);
    mf_force_ops noname = make_force("", MF_ABI_VERSION, 1);
    mf_force_ops badcount = make_force("miscounted", MF_ABI_VERSION, 2);
    mf_force_ops badkind = make_force("weird", MF_ABI_VERSION, 1);
    badkind.info.kind = (mf_module_kind)42;
    CHECK_OK(mf_registry_add(reg, &ok.info));
    CHECK(mf_registry_add(reg, &dup.info) == MF_ERR_INPUT);
    mf_error_clear();
    CHECK(mf_registry_add(reg, &newer.info) == MF_ERR_INPUT);
    printf("ABI mismatch: %s\n", mf_error_message());
    CHECK(strstr(mf_error_message(), "ABI") != NULL);
    mf_error_clear();
    CHECK(mf_registry_add(reg, &ancient.info) == MF_ERR_INPUT);
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
    /* The same library adds a metric. */
    CHECK_OK(mf_registry_find(reg, MF_KIND_METRIC, "finalKineticEnergy", &m));
    CHECK(m && m->kind == MF_KIND_METRIC && ((const mf_metric_ops *)m)->evaluate);
    mf_registry_destroy(reg);
}

/* ---- a plugin built for ABI version 2 ------------------------------------ */
/* Version 3 added the metric kind and no slot: a version-2 force is taken
 * as it is (its table copied into the current layout, every slot kept),
 * and a "version-2 metric", a kind its headers did not have, is refused
 * with a message that says so. */
static void test_abi2_plugin(const char *dir)
{
    CHECK(MF_ABI_VERSION == 3);
    CHECK(mf_ops_size(MF_KIND_METRIC, 2) == 0);
    CHECK(mf_ops_size(MF_KIND_METRIC, 3) == sizeof(mf_metric_ops));
    CHECK(mf_ops_size(MF_KIND_FORCE, 2) == sizeof(mf_force_ops));
    mf_registry *reg = NULL;
    CHECK_OK(mf_registry_create(&reg));
    mf_registry_set_plugin_dir(reg, dir);
    CHECK(mf_registry_load_plugin(reg, "abi2Plugin") == MF_ERR_INPUT);
    printf("version-2 metric: %s\n", mf_error_message());
    CHECK(strstr(mf_error_message(), "'abi2Metric' is a metric module, a kind added after the "
                                     "module ABI version 2") != NULL);
    mf_error_clear();
    const mf_module_info *m = NULL;
    CHECK_OK(mf_registry_find(reg, MF_KIND_FORCE, "abi2Push", &m));
    const mf_force_ops *ops = (const mf_force_ops *)m;
    CHECK(m && m->abi_version == 2 && m->nparams == 1 && ops->create && ops->accumulate &&
          ops->destroy && !ops->stable_dt && ops->flags == 0);
    CHECK(mf_registry_find(reg, MF_KIND_METRIC, "abi2Metric", &m) == MF_ERR_INPUT);
    mf_error_clear();
    /* Created from a dictionary and called like any force. */
    mf_module mod;
    mf_dict *d = NULL;
    CHECK_OK(mf_dict_parse_string("a 2.5;", 6, "test", &d));
    CHECK_OK(mf_module_prepare(reg, MF_KIND_FORCE, "abi2Push", d, NULL, NULL, &mod));
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    CHECK_OK(mf_particles_create(2, 2, &sim.p));
    const double x0[3] = {0, 0, 0}, v[3] = {0, 0, 0};
    CHECK_OK(mf_particles_add(sim.p, MF_FLUID, x0, v, NULL));
    double acc[3] = {0};
    CHECK_OK(ops->create(mod.settings, &sim, &mod.data));
    CHECK_OK(ops->accumulate(mod.data, &sim, acc));
    CHECK(acc[0] == 2.5 && acc[1] == 0);
    ops->destroy(mod.data);
    mf_module_release(&mod);
    mf_dict_free(d);
    mf_particles_destroy(sim.p);
    mf_registry_destroy(reg);
}

/* ---- a force built for ABI version 1 ------------------------------------- */
/* The layout of mf_force_ops in version 1: the header and three slots. */
typedef struct force_ops_v1 {
    mf_module_info info;
    int (*create)(const void *settings, mf_sim *sim, void **data);
    int (*accumulate)(void *data, const mf_sim *sim, double *acc);
    void (*destroy)(void *data);
} force_ops_v1;

static int v1_create(const void *settings, mf_sim *sim, void **data)
{
    (void)sim;
    *data = (void *)settings;
    return 0;
}

static int v1_accumulate(void *data, const mf_sim *sim, double *acc)
{
    const dummy_settings *s = data;
    for (size_t i = 0; i < sim->p->n_owned; i++)
        acc[3 * i] += s->x;
    return 0;
}

static void v1_destroy(void *data) { (void)data; }

/* The v1 table ends exactly where an inaccessible page begins: a host that
 * read a slot past it (flags, stable_dt, ...) would fault. Registered,
 * created and called through the wrappers, it must work as a version-1
 * force does: its acceleration added, no stable step, no surface pressure. */
static void test_older_abi(void)
{
    CHECK(mf_ops_size(MF_KIND_FORCE, 1) == sizeof(force_ops_v1));
    CHECK(mf_ops_size(MF_KIND_FORCE, MF_ABI_VERSION) == sizeof(mf_force_ops));
    CHECK(mf_ops_size(MF_KIND_FORCE, MF_ABI_VERSION + 1) == 0);
    const size_t page = (size_t)sysconf(_SC_PAGESIZE);
    char *mem = mmap(NULL, 2 * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    CHECK(mem != MAP_FAILED);
    if (mem == MAP_FAILED)
        return;
    force_ops_v1 *v1 = (force_ops_v1 *)(mem + page - sizeof *v1);
    *v1 = (force_ops_v1){
        .info = {1, MF_KIND_FORCE, "oldForce", "a force built for ABI version 1", dummy_params,
                 1, sizeof(dummy_settings)},
        .create = v1_create,
        .accumulate = v1_accumulate,
        .destroy = v1_destroy,
    };
    CHECK(mprotect(mem + page, page, PROT_NONE) == 0);

    mf_registry *reg = NULL;
    CHECK_OK(mf_registry_create(&reg));
    CHECK_OK(mf_registry_add(reg, &v1->info));
    const mf_module_info *info = NULL;
    CHECK_OK(mf_registry_find(reg, MF_KIND_FORCE, "oldForce", &info));
    const mf_force_ops *ops = (const mf_force_ops *)info;
    CHECK(info && info->abi_version == 1);
    CHECK(ops && ops->create == v1_create && ops->accumulate == v1_accumulate &&
          ops->destroy == v1_destroy);
    CHECK(ops && ops->flags == 0 && !ops->stable_dt && !ops->write_fields &&
          !ops->claim_surface_pressure && !ops->surface_pressure);

    /* A run's forces: this one alone, on two fluid particles. */
    mf_log log;
    mf_log_init(&log, stdout, MF_LOG_QUIET);
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    sim.dim = 2;
    sim.l0 = 0.01;
    sim.nfluids = 1;
    sim.fluid[0].rho = 1000;
    sim.log = &log;
    sim.reg = reg;
    CHECK_OK(mf_particles_create(2, 4, &sim.p));
    const double x0[3] = {0, 0, 0}, x1[3] = {0.01, 0, 0}, v[3] = {0, 1, 0};
    CHECK_OK(mf_particles_add(sim.p, MF_FLUID, x0, v, NULL));
    CHECK_OK(mf_particles_add(sim.p, MF_FLUID, x1, v, NULL));
    mf_module m;
    mf_dict *d = NULL;
    CHECK_OK(mf_dict_parse_string("x 0.5;", 6, "test", &d));
    CHECK_OK(mf_module_prepare(reg, MF_KIND_FORCE, "oldForce", d, NULL, NULL, &m));
    CHECK_OK(ops->create(m.settings, &sim, &m.data));
    sim.forces = &m;
    sim.nforces = 1;
    double acc[6] = {0}, dt = 0;
    const char *who = "";
    CHECK_OK(mf_force_accumulate(&sim, acc));
    CHECK(acc[0] == 0.5 && acc[3] == 0.5 && acc[1] == 0 && sim.forces_record.valid);
    CHECK_OK(mf_forces_stable_dt(&sim, &dt, &who));
    CHECK(isinf(dt) && who == NULL);
    CHECK(!mf_forces_claim_surface_pressure(&sim));
    double p[2] = {1, 1};
    const uint8_t dirichlet[2] = {1, 1};
    CHECK_OK(mf_forces_surface_pressure(&sim, dirichlet, p));
    CHECK(p[0] == 0 && p[1] == 0);
    ops->destroy(m.data);
    mf_module_release(&m);
    mf_dict_free(d);
    mf_particles_destroy(sim.p);
    mf_registry_destroy(reg);
    munmap(mem, 2 * page);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_registry PLUGIN_DIR TEST_PLUGIN_DIR\n");
        return 2;
    }
    test_builtins_and_lookup();
    test_refusals();
    test_older_abi();
    test_plugin(argv[1]);
    test_abi2_plugin(argv[2]);
    return mf_test_summary("registry");
}
