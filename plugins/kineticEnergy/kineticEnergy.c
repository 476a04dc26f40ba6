/* kineticEnergy.c: a function object, built as a plugin, that records the
 * total kinetic energy of the fluid each step. It shows how someone outside
 * the project adds a module: include the installed headers, export
 * mf_plugin_register_<library name>, list the library in `libs`.
 *
 *   functions { energy { type kineticEnergy; libs ("libkineticEnergy.so"); } }
 *
 * Writes postProcessing/<name>/kineticEnergy.dat: time, E = sum m |u|^2 / 2
 * (m = rho l0^d with each particle's own fluid's rho: mf_sim_particle_mass),
 * max speed. On several ranks (-parallel) the
 * sums are reduced over the ranks and rank 0 writes the file. */
#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mf_error.h"
#include "mf_fs.h"
#include "mf_modules.h"
#include "mf_sim.h"

typedef struct ke_settings {
    long interval; /* every N steps */
} ke_settings;

typedef struct ke_data {
    ke_settings s;
    FILE *out;
} ke_data;

static const mf_param ke_params[] = {
    {"interval", MF_PARAM_INT, "1", 1, 1000000, NULL, offsetof(ke_settings, interval),
     "record every N steps"},
};

static int ke_create(const void *settings, const mf_sim *sim, const char *out_dir, void **data)
{
    ke_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->s = *(const ke_settings *)settings;
    if (!mf_parallel_is_root(sim->par)) { /* rank 0 writes the file */
        *data = d;
        return 0;
    }
    int rc = mf_mkdir_p(out_dir);
    if (rc != 0) {
        free(d);
        return rc;
    }
    char path[4600];
    snprintf(path, sizeof path, "%s/kineticEnergy.dat", out_dir);
    d->out = fopen(path, "a");
    if (!d->out) {
        free(d);
        return MF_ERROR(MF_ERR_IO, "%s: cannot open for writing (%s)", path, strerror(errno));
    }
    fprintf(d->out, "# time kineticEnergy[J] maxSpeed[m/s]\n");
    *data = d;
    return 0;
}

static int ke_execute(void *data, const mf_sim *sim)
{
    ke_data *d = data;
    if (sim->step % d->s.interval != 0)
        return 0;
    const mf_particles *p = sim->p;
    const int fluid_field = mf_particles_field_index(p, "FluidId");
    double e = 0, umax = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *v = &p->vel[3 * i];
        double u2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        e += 0.5 * mf_sim_particle_mass(sim, fluid_field, i) * u2;
        if (u2 > umax * umax)
            umax = sqrt(u2);
    }
    mf_parallel_sum(sim->par, &e, 1);
    mf_parallel_max(sim->par, &umax, 1);
    if (d->out)
        fprintf(d->out, "%.10g %.10g %.10g\n", sim->time, e, umax);
    return 0;
}

static void ke_destroy(void *data)
{
    ke_data *d = data;
    if (d->out)
        fclose(d->out);
    free(d);
}

static const mf_function_object_ops kinetic_energy_ops = {
    .info = {MF_ABI_VERSION, MF_KIND_FUNCTION_OBJECT, "kineticEnergy",
             "records the fluid's total kinetic energy (plugin example)", ke_params, 1,
             sizeof(ke_settings)},
    .create = ke_create,
    .execute = ke_execute,
    .destroy = ke_destroy,
    .write = NULL,
};

/* The one symbol the host looks for: mf_plugin_register_ + library name. */
int mf_plugin_register_kineticEnergy(mf_registry *reg);
int mf_plugin_register_kineticEnergy(mf_registry *reg)
{
    return mf_registry_add(reg, &kinetic_energy_ops.info);
}
