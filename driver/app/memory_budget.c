/* memory_budget.c: how much memory a case's scene may take, checked before
 * the scene allocates a particle (mf_scene_build_budgeted). */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mf_app.h"
#include "mf_error.h"

/* Physical memory, or the cgroup (v2, then v1) limit when lower: a container
 * is killed at its limit, not at the machine's. */
static double machine_memory(const char **what)
{
    double bytes = (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
    *what = "this machine's memory";
    static const char *const limits[] = {"/sys/fs/cgroup/memory.max",
                                         "/sys/fs/cgroup/memory/memory.limit_in_bytes"};
    for (int k = 0; k < 2; k++) {
        FILE *f = fopen(limits[k], "r");
        double limit = 0;
        if (f && fscanf(f, "%lf", &limit) == 1 && limit > 0 && limit < bytes) {
            bytes = limit;
            *what = "this cgroup's memory limit";
        }
        if (f)
            fclose(f);
    }
    return bytes;
}

/* The largest neighbour radius of the solver's settings (its re* keys, in
 * particle spacings), from the resolved parameters of a trial preparation:
 * the module's own table and defaults say it, nothing is copied here. */
static int solver_radius(mf_app *app, double *radius)
{
    *radius = 3.1; /* the paper's Laplacian radius, if the solver names none */
    const mf_dict *sd = app->cs.solver_dict;
    const char *name = app->opt.solver;
    if (!name && mf_dict_get_word(sd, "solver", &name) != 0)
        return mf_error_trace(MF_ERR_INPUT, __FILE__, __LINE__, __func__);
    char coeffs[256];
    snprintf(coeffs, sizeof coeffs, "%sCoeffs", name);
    mf_dict *resolved = mf_dict_new("", NULL);
    if (!resolved)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    mf_module m;
    int rc = mf_module_prepare(app->reg, MF_KIND_SOLVER, name, mf_dict_subdict(sd, coeffs), NULL,
                               resolved, &m);
    double largest = 0;
    for (size_t k = 0; rc == 0 && k < resolved->n; k++) {
        const mf_entry *e = resolved->entries[k];
        if (strncmp(e->key, "re", 2) == 0 && isupper((unsigned char)e->key[2]) && e->n == 1 &&
            e->items[0]->kind == MF_VAL_NUMBER && e->items[0]->number > largest)
            largest = e->items[0]->number;
    }
    mf_module_release(&m);
    mf_dict_free(resolved);
    MF_CALL(rc);
    if (largest > 0)
        *radius = largest;
    return 0;
}

int mf_app_memory_budget(mf_app *app, mf_scene_budget *b)
{
    memset(b, 0, sizeof *b);
    MF_CALL(solver_radius(app, &b->radius_l0));
    long dim = 2;
    if (mf_dict_get_int(app->cs.geometry, "dimension", &dim) != 0)
        mf_error_clear(); /* the scene builder says what is wrong with it */
    b->bytes_per_particle = mf_memory_per_particle(dim == 3 ? 3 : 2, b->radius_l0);
    static char source[128];
    if (app->cs.control.max_memory > 0) {
        b->max_bytes = app->cs.control.max_memory * 1e9;
        snprintf(source, sizeof source, "set in system/controlDict");
    } else {
        const char *what;
        double total = machine_memory(&what);
        b->max_bytes = 0.8 * total;
        snprintf(source, sizeof source, "80%% of %s, %.3g GB", what, total / 1e9);
    }
    b->limit_source = source;
    mf_dict *rc = mf_dict_subdict(app->cs.resolved, "controlDict");
    if (rc)
        MF_CALL(mf_dict_set_number(rc, "maxMemory", b->max_bytes / 1e9));
    return 0;
}
