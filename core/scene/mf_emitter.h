/* mf_emitter.h: inlets, outlets and nozzles (the scene layer that adds and
 * removes particles during a run), and the transported scalars a case
 * declares. Every solver gets them: the time loop calls
 * mf_emitters_apply once per step, before the solver's step.
 *
 * In constant/geometry (beside fluidBlocks and walls):
 *
 *   inlets  { left  { min (-0.04 0 0); max (0 0.2 0); velocity (1 0 0);
 *                     profile uniform;            // or parabolic (same mean)
 *                     scalars { dye 0; } } }
 *   outlets { right { min (1 0 0); max (1.04 0.2 0); direction (1 0 0);
 *                     velocity (1 0 0); } }       // initial velocity of its points
 *   emitters { tap  { type nozzle; centre (0.1 0.5 0); velocity (0 -1 0);
 *                     diameter 0.04; start 0; end 0.5; fluid water;
 *                     rate 0.04;                  // optional: m^2/s (2-D), m^3/s (3-D)
 *                     scalars { dye 1; } } }
 *   fluidBlocks { channel { ...; scalars { dye { type gaussian; centre (0.3 0 0);
 *                     direction (1 0 0); width 0.05; amplitude 1; } } } }
 *
 * Inlet and outlet boxes are filled, like fluid blocks, with particles on
 * the lattice min + (i + 1/2) l0: kinds MF_INLET and MF_OUTLET. The inflow
 * direction is the axis of the inlet velocity; the outflow direction is
 * given. Both must be along a coordinate axis.
 *
 * Two ways to treat inlet and outlet particles (mf_emitters.fixed_buffers):
 *  - moving buffers (the default, for Lagrangian solvers such as MPS, which
 *    moves fluid particles only): inlet particles move with the inlet
 *    velocity; one that crosses the inlet's downstream face becomes fluid
 *    and a new inlet particle takes its place one buffer length upstream.
 *    Fluid that crosses an outlet's upstream face becomes an outlet
 *    particle, moves on with the velocity it had, and is removed when it
 *    leaves the outlet box.
 *  - fixed buffers (set by MPS-MAFL, whose inlet and outlet points are fixed
 *    computation points): inlet points keep their place and get the inlet
 *    velocity and scalar values each step; fluid points that enter an
 *    outlet box have left the domain and are removed.
 * A nozzle is the same in both: it adds layers of fluid particles across
 * its opening at the rate given, during [start, end).
 *
 * Nothing here keeps state between steps: what a step adds depends only on
 * the particles and the time, so a step that fails and is retried with a
 * smaller dt, or a restart, adds exactly what an uninterrupted run adds.
 * Ids of added particles come from mf_particles_add: unique, never reused.
 */
#ifndef MF_EMITTER_H
#define MF_EMITTER_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stddef.h>

#include "mf_dict.h"
#include "mf_sim.h"

/* ---- transported scalars ------------------------------------------------ */

/* A scalar's initial value in space: a number, or
 *   { type uniform;  value v; }
 *   { type gaussian; centre (..); width s; amplitude a; base b; direction (..); }
 *       b + a exp(-d^2 / (2 s^2)), d the distance from the centre (along
 *       `direction` only, when given: a profile that varies along one axis)
 *   { type step;     origin (..); normal (..); below v1; above v2; }
 *       v1 where (x - origin).normal < 0, else v2
 *   { type box;      min (..); max (..); inside v1; outside v2; } */
typedef enum {
    MF_PROFILE_UNIFORM,
    MF_PROFILE_GAUSSIAN,
    MF_PROFILE_STEP,
    MF_PROFILE_BOX
} mf_profile_type;

typedef struct mf_scalar_profile {
    mf_profile_type type;
    double value;        /* uniform; gaussian: base */
    double amplitude;    /* gaussian */
    double width;        /* gaussian: standard deviation */
    double centre[3];    /* gaussian centre, step origin */
    double direction[3]; /* gaussian direction (zero: radial), step normal; unit */
    double min[3], max[3];
    double inside, outside; /* box; step: below, above */
} mf_scalar_profile;

/* Read one scalar entry (a number or a profile dictionary). `e` is the
 * entry `name value;` or `name { ... }`. resolved (may be NULL) receives it. */
int mf_scalar_profile_read(const mf_entry *e, int dim, mf_scalar_profile *out,
                           mf_dict *resolved);
double mf_scalar_profile_eval(const mf_scalar_profile *s, const double x[3]);

/* The particle field of a transported scalar, created on first use (double,
 * one component, written to snapshots) and listed in sim->scalar_name so
 * that solvers which convect scalars find it. Names of the core datasets
 * and of solver fields are refused. */
int mf_scalar_declare(mf_sim *sim, const char *name, int *field);

/* scalars { dye { type gaussian; ... } tracer 0; } of a fluid block: set the
 * particles [first, last) from each profile. */
int mf_scene_block_scalars(mf_sim *sim, const mf_dict *scalars, size_t first, size_t last,
                           mf_dict *resolved);

/* ---- inlets, outlets, nozzles -------------------------------------------- */

#define MF_EMITTER_MAX_SCALARS 8

typedef struct mf_emitter_scalars {
    int n;
    int field[MF_EMITTER_MAX_SCALARS];
    mf_scalar_profile value[MF_EMITTER_MAX_SCALARS];
} mf_emitter_scalars;

typedef enum { MF_INLET_UNIFORM, MF_INLET_PARABOLIC } mf_inlet_profile;

typedef struct mf_inlet {
    char name[64];
    double min[3], max[3];
    int axis, sign;          /* inflow direction: sign * e_axis */
    double velocity[3];      /* mean velocity */
    mf_inlet_profile profile;
    int fluid;               /* index in sim->fluid */
    mf_emitter_scalars scalars;
} mf_inlet;

typedef struct mf_outlet {
    char name[64];
    double min[3], max[3];
    int axis, sign;          /* outflow direction: sign * e_axis */
    double velocity[3];      /* initial velocity of its points */
} mf_outlet;

typedef struct mf_nozzle {
    char name[64];
    double centre[3];        /* middle of the opening */
    double velocity[3];      /* of the fluid it adds; its direction is the axis */
    double dir[3];           /* unit vector of velocity */
    double speed;
    double diameter;         /* width of the opening in 2-D */
    double rate;             /* volume per second (area per second in 2-D) */
    double start, end;       /* emits during [start, end) */
    double period;           /* time between two layers */
    int fluid;
    size_t nper_layer;
    double *offset;          /* 3 * nper_layer: lattice points across the opening */
    mf_emitter_scalars scalars;
} mf_nozzle;

typedef struct mf_emitters {
    bool fixed_buffers;      /* set by a solver that keeps inlet/outlet points in place */
    size_t ninlets, noutlets, nnozzles;
    mf_inlet *inlet;
    mf_outlet *outlet;
    mf_nozzle *nozzle;
    int fluid_field;         /* FluidId field, or -1 with one fluid */
    size_t total_added, total_removed; /* over the accepted steps (kept by the time loop) */
    /* Work: removal flags (grown as needed). */
    unsigned char *flag;
    size_t cap_flag;
} mf_emitters;

/* Parse the inlets, outlets and emitters groups (any may be NULL) of the
 * geometry and place the initial inlet and outlet particles. *out stays
 * NULL when all three are absent. resolved_* (may be NULL) receive them. */
int mf_emitters_create(mf_sim *sim, const mf_dict *inlets, const mf_dict *outlets,
                       const mf_dict *nozzles, mf_dict *resolved_inlets,
                       mf_dict *resolved_outlets, mf_dict *resolved_nozzles,
                       mf_emitters **out);
void mf_emitters_destroy(mf_emitters *em);

/* One step from sim->time to sim->time + dt, before the solver's step:
 * adds and removes particles as described above. */
int mf_emitters_apply(mf_emitters *em, mf_sim *sim, double dt, size_t *added, size_t *removed);

/* Set the velocity and scalars of every inlet point to the inlet's values
 * (a solver that restores inlet points after its own phases may call it). */
void mf_emitters_set_inlet_values(const mf_emitters *em, mf_sim *sim);

/* Kinetic energy of the fluid particles, sum 1/2 rho l0^dim |u|^2 (J; J per
 * metre of depth in 2-D): the time loop counts what the emitters bring in
 * as a source of energy for the run's watch. */
double mf_emitters_fluid_kinetic_energy(const mf_sim *sim);

/* The inlet's velocity at x (the profile across its box). */
void mf_inlet_velocity(const mf_inlet *in, int dim, const double x[3], double u[3]);

/* Index of the inlet / outlet whose box (grown by `margin` across the flow
 * and along it) holds x, or -1. */
int mf_emitters_inlet_at(const mf_emitters *em, int dim, const double x[3], double margin);
int mf_emitters_outlet_at(const mf_emitters *em, int dim, const double x[3], double margin);

#pragma GCC visibility pop
#endif
