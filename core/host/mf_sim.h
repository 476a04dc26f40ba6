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
#include "mf_halo.h"
#include "mf_parallel.h"
#include "mf_particles.h"
#include "mf_registry.h"

#define MF_MAX_FLUIDS 16
#define MF_MAX_SCALARS 8

struct mf_emitters; /* mf_emitter.h */
struct mf_walls;    /* mf_walls.h */
struct mf_trimesh_reader; /* mf_trimesh.h */

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
    /* The solids of the scene (mf_walls.h: tanks, obstacles, mesh walls,
     * their motions), built by the scene with or without their particles
     * (wall_weight: without, for a solver that takes walls through wall
     * weight functions; the driver sets it from the solver's settings). */
    struct mf_walls *walls;
    bool wall_weight;
    /* n0 of the solver's number density (0: the solver has none), for the watch. */
    double n0;
    /* Set by a solver that treats viscosity implicitly: the time loop then
     * applies no viscous (maxDi) limit to the step. */
    bool viscosity_implicit;
    const mf_registry *reg;
    mf_log *log;
    /* The ranks of a -parallel run (mf_parallel.h); NULL for a serial run. */
    mf_parallel *par;
    /* The copies [n_owned, n) of the particles while a solver's step runs
     * (mf_halo.h: other ranks' particles, periodic images), for a force that
     * needs its own intermediate values on them (mf_halo_update); NULL when
     * there are none. */
    mf_halo *halo;
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
    /* How a module reads a polygon file it names (a control force's target
     * mesh: solvers/force/control/), found as the geometry's are: relative
     * to mesh_relative_to (constant/geometry), then constant/triSurface/.
     * NULL when the driver gives none (a test's sim). */
    const struct mf_trimesh_reader *mesh_reader;
    const char *mesh_relative_to;
    /* This step's force accelerations (mf_force_accumulate). */
    mf_force_record forces_record;
    /* Tests only: a hook the calling wrappers offer their results to (no
     * hook: fn NULL). */
    mf_fault_hook fault;
    /* The uniform gravity the fluid feels, m/s^2: the sum of the g of the
     * gravity force modules, recorded by their create (solvers/force/
     * gravity.c); zero without one. Read by the watch's availableEnergy
     * criterion (core/run/watch_available.c). Last in the struct: plugins
     * built against the fields above keep their offsets. */
    double gravity[3];
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
