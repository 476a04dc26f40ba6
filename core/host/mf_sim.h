/* mf_sim.h: the state of a run that the modules work on.
 *
 * The driver owns it: it builds the particles from the case, creates the
 * modules the case names, and advances time. Solver modules change the
 * particles; function objects and writers only read. */
#ifndef MF_SIM_H
#define MF_SIM_H

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
} mf_module;

/* A wall box as the scene built it: the region it encloses and which faces
 * are open. The run's watch uses it to see particles that pass a wall. */
typedef struct mf_wall_box {
    double min[3], max[3];
    bool open[3][2];
} mf_wall_box;

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
    /* Time-step control (system/controlDict). */
    double max_courant;
    double max_dt;
    bool fixed_dt;
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
    /* The ranks of a -parallel run (mf_parallel.h); NULL for a serial run. */
    mf_parallel *par;
    /* The copies [n_owned, n) of the particles while a solver's step runs
     * (mf_halo.h: other ranks' particles, periodic images), for a force that
     * needs its own intermediate values on them (mf_halo_update); NULL when
     * there are none. */
    mf_halo *halo;
    /* Statistics the driver reports (filled by modules). */
    double courant_mean, courant_max;
    long pressure_iterations;  /* summed over the run */
    /* Transported scalars ("dye", "temperature"): optional particle fields of
     * these names, declared by the case (mf_emitter.h); a solver that convects
     * (MPS-MAFL) carries each. */
    int nscalars;
    char scalar_name[MF_MAX_SCALARS][32];
    /* Inlets, outlets and nozzles (mf_emitter.h), applied by the time loop
     * before each step; NULL when the case has none. */
    struct mf_emitters *emitters;
} mf_sim;

#endif
