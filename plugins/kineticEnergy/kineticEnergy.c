/* kineticEnergy.c: a plugin of two modules that shows how someone outside
 * the project adds modules: include the installed headers, export
 * mf_plugin_register_<library name>, list the library in `libs`.
 *
 * The function object kineticEnergy records the total kinetic energy of
 * the fluid each step:
 *
 *   functions { energy { type kineticEnergy; libs ("libkineticEnergy.so"); } }
 *
 * It writes postProcessing/<name>/kineticEnergy.dat: time, E = sum m |u|^2 / 2
 * (m = rho l0^d with each particle's own fluid's rho: mf_sim_particle_mass),
 * max speed. On several ranks (-parallel) the sums are
 * reduced over the ranks and rank 0 writes the file.
 *
 * The metric finalKineticEnergy scores a run by the same E at its last
 * snapshot, for a case that should come to rest (validation/metric):
 *
 *   metric finalKineticEnergy; libs ("libkineticEnergy.so");
 *
 * `mpsflow validate` prints E (J; per metre of depth in 2-D) and writes
 * validation/result.csv: time and E of every snapshot. */
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

/* E = sum m |u|^2 / 2 over the owned fluid particles of sim (m = rho l0^d
 * of each particle's own fluid: mf_sim_particle_mass) and their largest
 * speed: the one formula of both modules. */
static void fluid_energy(const mf_sim *sim, double *e, double *umax)
{
    const mf_particles *p = sim->p;
    const int fluid_field = mf_particles_field_index(p, "FluidId");
    *e = 0;
    *umax = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *v = &p->vel[3 * i];
        double u2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        *e += 0.5 * mf_sim_particle_mass(sim, fluid_field, i) * u2;
        if (u2 > *umax * *umax)
            *umax = sqrt(u2);
    }
}

static int ke_execute(void *data, const mf_sim *sim)
{
    ke_data *d = data;
    if (sim->step % d->s.interval != 0)
        return 0;
    double e, umax;
    fluid_energy(sim, &e, &umax);
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

/* ---- the metric finalKineticEnergy ---------------------------------------- */
typedef struct final_settings {
    const char *metric;
    double relative_to;
} final_settings;

static const mf_param final_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(final_settings, metric),
     "finalKineticEnergy"},
    {"relativeTo", MF_PARAM_SCALAR, "0", 0, 1e30, NULL, offsetof(final_settings, relative_to),
     "J: the error is E / relativeTo (0: E itself, J)"},
};

/* E of every snapshot of ctx into result.csv; *error: E at the last one. */
static int final_evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    const final_settings *s = settings;
    int *idx = NULL;
    size_t n = 0;
    MF_CALL(ctx->snapshots(ctx, &idx, &n));
    char path[4600];
    snprintf(path, sizeof path, "%s/result.csv", ctx->out_dir);
    mf_replace result; /* written whole or not at all (mf_fs.h) */
    int rc = mf_replace_open(&result, path, "w");
    FILE *out = result.f;
    if (rc == 0 && n == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no snapshot to score", ctx->case_dir);
    if (rc == 0)
        fprintf(out, "# fluid kinetic energy E = sum rho l0^d |u|^2 / 2 (plugin "
                     "kineticEnergy); error = E at the last snapshot\ntime,E\n");
    for (size_t k = 0; rc == 0 && k < n; k++) {
        mf_sim snap;
        memset(&snap, 0, sizeof snap);
        rc = ctx->read_snapshot(ctx, idx[k], &snap);
        double e = 0, umax = 0;
        if (rc == 0) {
            fluid_energy(&snap, &e, &umax);
            fprintf(out, "%.10g,%.10g\n", snap.time, e);
            *error = s->relative_to > 0 ? e / s->relative_to : e;
        }
        mf_particles_destroy(snap.p);
    }
    if (out)
        rc = mf_replace_commit(&result, rc);
    free(idx);
    return rc;
}

static const mf_metric_ops final_energy_ops = {
    .info = {MF_ABI_VERSION, MF_KIND_METRIC, "finalKineticEnergy",
             "the fluid's kinetic energy at the last snapshot, J (plugin example)", final_params,
             sizeof final_params / sizeof final_params[0], sizeof(final_settings)},
    .evaluate = final_evaluate,
    .extra_keys = NULL,
};

/* The one symbol the host looks for: mf_plugin_register_ + library name. */
int mf_plugin_register_kineticEnergy(mf_registry *reg);
int mf_plugin_register_kineticEnergy(mf_registry *reg)
{
    MF_CALL(mf_registry_add(reg, &kinetic_energy_ops.info));
    MF_CALL(mf_registry_add(reg, &final_energy_ops.info));
    return 0;
}
