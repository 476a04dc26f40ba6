/* faultInjection.c: a force module for tests only, loaded as a plugin, that
 * breaks a run on purpose so that the run's watch and the calling wrappers'
 * checks can be seen to catch it, and that shows a plugin force limiting
 * the time step.
 *   functions none; solverDict: forces { fault { type fault; nanAt 0.01; } }
 * Through the wrappers' fault-injection point (mf_sim.fault, installed at
 * create when a fault is asked for):
 *   nanAt T: from time T, the acceleration this force gives the first fluid
 *     particle is NaN (mf_force_accumulate names the force);
 *   solveNanAt T: from time T, every linear solve returns a NaN in its first
 *     row (mf_pressure_solve says which solve);
 *   kickAt T, kick V: from time T, each step of the solver ends with V (a
 *     vector, m/s) added to the velocity of every fluid particle: kinetic
 *     energy from no force, the availableEnergy case of the watch.
 * As a force:
 *   pushAt T, push A: from time T, the first fluid particle is accelerated by
 *     A (a vector) on top of everything else: through a wall if A points at one;
 *   scatterAt T, scatter S: from time T, every fluid particle is accelerated
 *     away from the fluid's centroid c by S (x - c) (S in 1/s^2): the fluid
 *     blows apart (the density-collapse case; the force's work is a source,
 *     so the energy check does not see it);
 *   stableDt D: the force's stable_dt is D (the time loop must keep every
 *     step at or below it, whatever the solver). */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_modules.h"

typedef struct fault_settings {
    double nan_at, solve_nan_at, push_at, push[3];
    double scatter_at, scatter;
    double stable_dt;
    double kick_at, kick[3];
} fault_settings;

static const mf_param fault_params[] = {
    {"nanAt", MF_PARAM_SCALAR, "1e30", 0, 1e30, NULL, offsetof(fault_settings, nan_at),
     "time from which one particle's acceleration is NaN"},
    {"solveNanAt", MF_PARAM_SCALAR, "1e30", 0, 1e30, NULL,
     offsetof(fault_settings, solve_nan_at), "time from which linear solves return a NaN"},
    {"pushAt", MF_PARAM_SCALAR, "1e30", 0, 1e30, NULL, offsetof(fault_settings, push_at),
     "time from which one particle is pushed"},
    {"push", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, offsetof(fault_settings, push),
     "acceleration of the push, m/s^2"},
    {"scatterAt", MF_PARAM_SCALAR, "1e30", 0, 1e30, NULL, offsetof(fault_settings, scatter_at),
     "time from which the fluid is pushed apart"},
    {"scatter", MF_PARAM_SCALAR, "0", 0, 1e12, NULL, offsetof(fault_settings, scatter),
     "rate of the push apart, 1/s^2: a = scatter (x - centroid)"},
    {"kickAt", MF_PARAM_SCALAR, "1e30", 0, 1e30, NULL, offsetof(fault_settings, kick_at),
     "time from which every step ends with the fluid's velocity kicked"},
    {"kick", MF_PARAM_VECTOR, "(0 0 0)", -1e6, 1e6, NULL, offsetof(fault_settings, kick),
     "velocity added to every fluid particle after each step, m/s"},
    {"stableDt", MF_PARAM_SCALAR, "1e30", 1e-12, 1e30, NULL,
     offsetof(fault_settings, stable_dt), "the largest step this force allows, s"},
};

static size_t first_fluid(const mf_particles *p)
{
    size_t first = 0;
    while (first < p->n_owned && p->kind[first] != MF_FLUID)
        first++;
    return first;
}

static int fault_hook(void *ctx, const mf_sim *sim, mf_fault_site site, const char *module,
                      double *values, size_t n, int rc)
{
    const fault_settings *s = ctx;
    if (rc != 0 || !values)
        return rc;
    if (site == MF_FAULT_FORCE && strcmp(module, "fault") == 0 && sim->time >= s->nan_at) {
        size_t first = first_fluid(sim->p);
        if (3 * first + 2 < n)
            values[3 * first] = values[3 * first + 1] = values[3 * first + 2] = NAN;
    }
    if (site == MF_FAULT_PRESSURE && sim->time >= s->solve_nan_at && n > 0)
        values[0] = NAN;
    return rc;
}

/* The step's end: the particles are the sim's to change (sim->p is not
 * const), and a retry of the step restores them. */
static int kick_hook(void *ctx, const mf_sim *sim, mf_fault_site site, const char *module,
                     double *values, size_t n, int rc)
{
    const fault_settings *s = ctx;
    rc = fault_hook(ctx, sim, site, module, values, n, rc);
    if (rc != 0 || site != MF_FAULT_STEP || sim->time < s->kick_at)
        return rc;
    mf_particles *p = sim->p;
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->kind[i] == MF_FLUID)
            for (int c = 0; c < 3; c++)
                p->vel[3 * i + c] += s->kick[c];
    return rc;
}

static int fault_create(const void *settings, mf_sim *sim, void **data)
{
    fault_settings *s = malloc(sizeof *s);
    if (!s)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    *s = *(const fault_settings *)settings;
    if (s->nan_at < 1e30 || s->solve_nan_at < 1e30 || s->kick_at < 1e30) {
        if (sim->fault.fn) {
            free(s);
            return MF_ERROR(MF_ERR_INPUT, "fault: another module holds the fault hook");
        }
        sim->fault.fn = kick_hook;
        sim->fault.ctx = s;
    }
    *data = s;
    return 0;
}

static int fault_accumulate(void *data, const mf_sim *sim, double *acc)
{
    const fault_settings *s = data;
    const mf_particles *p = sim->p;
    const size_t first = first_fluid(p);
    if (first == p->n_owned)
        return 0;
    if (sim->time >= s->scatter_at && s->scatter > 0) {
        double c[3] = {0, 0, 0};
        size_t n = 0;
        for (size_t i = 0; i < p->n_owned; i++)
            if (p->kind[i] == MF_FLUID) {
                for (int a = 0; a < 3; a++)
                    c[a] += p->pos[3 * i + a];
                n++;
            }
        for (size_t i = 0; i < p->n_owned; i++)
            if (p->kind[i] == MF_FLUID)
                for (int a = 0; a < 3; a++)
                    acc[3 * i + a] += s->scatter * (p->pos[3 * i + a] - c[a] / (double)n);
    }
    if (sim->time >= s->push_at)
        for (int c = 0; c < 3; c++)
            acc[3 * first + c] += s->push[c];
    return 0;
}

static int fault_stable_dt(void *data, const mf_sim *sim, double *dt)
{
    (void)sim;
    *dt = ((const fault_settings *)data)->stable_dt;
    return 0;
}

static void fault_destroy(void *data) { free(data); }

static const mf_force_ops fault_ops = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "fault", "breaks a run on purpose (tests only)",
             fault_params, sizeof fault_params / sizeof fault_params[0],
             sizeof(fault_settings)},
    .create = fault_create,
    .accumulate = fault_accumulate,
    .destroy = fault_destroy,
    .stable_dt = fault_stable_dt,
};

int mf_plugin_register_faultInjection(mf_registry *reg);
int mf_plugin_register_faultInjection(mf_registry *reg)
{
    return mf_registry_add(reg, &fault_ops.info);
}
