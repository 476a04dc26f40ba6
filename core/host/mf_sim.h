/* mf_sim.h: the state of a run that the modules work on.
 *
 * The driver owns it: it builds the particles from the case, creates the
 * modules the case names, and advances time. Solver modules change the
 * particles; function objects and writers only read. */
#ifndef MF_SIM_H
#define MF_SIM_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stddef.h>

#include "mf_dict.h"
#include "mf_log.h"
#include "mf_neighbours.h"
#include "mf_particles.h"
#include "mf_registry.h"

#define MF_MAX_FLUIDS 16
#define MF_MAX_SCALARS 8

struct mf_emitters; /* mf_emitter.h */

typedef struct mf_fluid {
    char name[64];
    double rho;   /* density, kg/m^3 */
    double nu;    /* kinematic viscosity, m^2/s */
    double sigma; /* surface tension coefficient, N/m (0: none) */
} mf_fluid;

/* One created module: its table, its filled settings and its private data. */
typedef struct mf_module {
    const mf_module_info *info;
    void *settings; /* info->settings_size bytes, filled from the parameter table */
    void *data;     /* the module's own state (from create) */
    /* Kept by the calling wrappers (mf_modules.h): calls and their seconds. */
    long calls;
    double seconds;
} mf_module;

/* A wall box as the scene built it: the region it encloses and which faces
 * are open. The run's watch uses it to see particles that pass a wall. */
typedef struct mf_wall_box {
    double min[3], max[3];
    bool open[3][2];
} mf_wall_box;

/* ---- fault injection (tests) --------------------------------------------- */
/* Where the calling wrappers (mf_modules.h) offer a test hook a chance to
 * break the result. */
typedef enum {
    MF_FAULT_FORCE,    /* after a force's accumulate: values = acc, 3 per particle */
    MF_FAULT_PRESSURE, /* after a linear solve: values = x, one per row */
    MF_FAULT_STEP,     /* after the solver's step: values = NULL */
} mf_fault_site;
/* The hook sees the module's name, its output and its return code, and
 * returns the code to go on with (it may also change the values). Installed
 * in sim->fault by a test-only module (tests/plugins/faultInjection.c). */
struct mf_sim;
typedef struct mf_fault_hook {
    int (*fn)(void *ctx, const struct mf_sim *sim, mf_fault_site site, const char *module,
              double *values, size_t n, int rc);
    void *ctx;
} mf_fault_hook;

/* What mf_force_accumulate recorded of the step being taken, for the run's
 * watch (which uses it instead of a second force pass). */
#define MF_FORCE_FIELD "ForceAcceleration" /* 3 per particle, not in snapshots */
typedef struct mf_force_record {
    bool valid;   /* the forces ran in this attempt (the time loop clears it); their
                     accelerations are in the particle field MF_FORCE_FIELD */
    double power; /* sum over fluid particles of m a.u at the state the forces saw */
} mf_force_record;

typedef struct mf_sim {
    int dim;
    double l0;                 /* particle spacing */
    mf_particles *p;
    int nfluids;
    mf_fluid fluid[MF_MAX_FLUIDS];
    /* Time. */
    double time;
    double end_time;
    double dt;                 /* the step being taken (or last taken) */
    double dt_natural;         /* the last step the limits allowed, before it was shortened
                                  to land on a write time: the controller grows from it, so
                                  a restart needs it to continue exactly */
    long step;
    /* Modules the case names, in order. */
    size_t nforces;
    mf_module *forces;         /* kind MF_KIND_FORCE */
    /* The neighbour service (mf_neighbours.h), created with the sim and
     * shared by every module: a module requests its radius once
     * (mf_neighbours_request) and asks for the pairs when it loops. */
    mf_neighbours *neighbours;
    /* Walls of the scene (box walls), for the watch. */
    size_t nwall_boxes;
    mf_wall_box *wall_boxes;
    /* n0 of the solver's number density (0: the solver has none), for the watch. */
    double n0;
    /* Set by a solver that treats viscosity implicitly: the time loop then
     * applies no viscous (maxDi) limit to the step. */
    bool viscosity_implicit;
    const mf_registry *reg;
    mf_log *log;
    /* Statistics the driver reports (filled by modules). */
    long pressure_iterations;  /* summed over the run */
    /* Transported scalars ("dye", "temperature"): optional particle fields of
     * these names, declared by the case (mf_emitter.h); a solver that convects
     * (MPS-MAFL) carries each. */
    int nscalars;
    char scalar_name[MF_MAX_SCALARS][32];
    /* Inlets, outlets and nozzles (mf_emitter.h), applied by the time loop
     * before each step; NULL when the case has none. */
    struct mf_emitters *emitters;
    /* Snapshots written so far by this process. A module that keeps work
     * from step to step (an AMG hierarchy) starts afresh when it changes:
     * a run restarted from a snapshot then repeats the straight run bit for
     * bit, both having started afresh at that step. */
    long snapshot_epoch;
    /* This step's force accelerations (mf_force_accumulate). */
    mf_force_record forces_record;
    /* Tests only: a hook the calling wrappers offer their results to (no
     * hook: fn NULL). */
    mf_fault_hook fault;
} mf_sim;

/* Mass of particle i: rho l0^d of its fluid; fluid_field is the index of
 * the FluidId field (-1 with one fluid: fluid 0). */
static inline double mf_sim_particle_mass(const mf_sim *sim, int fluid_field, size_t i)
{
    const int f = fluid_field >= 0 ? mf_particles_fi(sim->p, fluid_field)[i] : 0;
    const double vol = sim->dim == 3 ? sim->l0 * sim->l0 * sim->l0 : sim->l0 * sim->l0;
    return sim->fluid[f].rho * vol;
}

#pragma GCC visibility pop
#endif
