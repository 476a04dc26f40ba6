/* mf_watch.h: watching a run for the signs of instability.
 *
 * After every step the watch checks, in this order:
 *   nonFinite     NaN or Inf in a position, a velocity or any field;
 *   throughWall   a fluid particle past the wall-particle line of a closed
 *                 face of a wall box (fluid centres stay about l0/2 inside);
 *   densityCollapse  the mean number density of the fluid below a fraction
 *                 of n0, or of its value at the start when that is lower (a
 *                 thin sheet, a spray, a single particle start below n0: the
 *                 fluid has blown apart when it thins from where it was);
 *   energy        kinetic energy growing without a source: KE - KE0 - W - A,
 *                 W the work of the force modules (gravity, surface tension,
 *                 ...) integrated over the run, from the accelerations each
 *                 step's forces gave (mf_force_accumulate records them: the
 *                 watch makes no force pass of its own), A what no force
 *                 module reports, counted in full: 1/2 M u_w^2 of the fastest
 *                 wall so far (moving walls, sliding lids) and sigma S
 *                 (surface tension applied as a pressure condition; S the
 *                 surface of the fluid's bounding box at the start), above a
 *                 fraction (energyTolerance) of the run's energy scale
 *                 KE0 + |W| + sum m |a_ext| L + A. The MPS schemes dissipate:
 *                 on every tutorial the excess stays below 0.005 of the
 *                 scale, while the water/air dam break's burst at its end-wall
 *                 impact (the water's kinetic energy above the column's
 *                 available potential energy) reaches 0.03;
 *   availableEnergy  kinetic energy above what the fluid can have at all:
 *                 KE0 + P + A + max(W_o, 0), P the potential energy the
 *                 fluid's start has above the least it can reach (the same
 *                 fluid laid level on the container's floor, the densest
 *                 lowest; or where it is when it has settled below that, a
 *                 compacted fluid), A as above, W_o the work of the force
 *                 modules other than gravity (W minus gravity's, from the g
 *                 the gravity module records in mf_sim.gravity), by more
 *                 than availableEnergyTolerance of that budget plus E, the
 *                 level layers' own energy above the floor (M |g| H / 2 for
 *                 one fluid H deep: a tank at rest has P = 0, and its
 *                 particles' jitter, 0.39 J in the 157 J of hydrostatic2D,
 *                 is no burst). It applies to a fluid in one tank box
 *                 with a closed floor and closed sides (no periodic axis,
 *                 no outlet), at rest or translating, gravity along an axis,
 *                 no inlets, outlets or nozzles; otherwise the log says once
 *                 why not (core/run/watch_available.c).
 * A pressure solve that diverges or does not converge is reported by the
 * solver itself, in the same form: `unstable (pressureSolve) at time ...`
 * with the particle of the largest residual (solvers/solver/mps/mps_ppe.c); a step
 * that the limits shrink below minDeltaT is `unstable (timeStep)` (core/run/run.c).
 * A check
 * that fires fails the step with MF_ERR_NUMERIC and a message that names
 * the criterion, the time and the particle (the time loop retries with a
 * smaller step, then stops and keeps the last good state).
 */
#ifndef MF_WATCH_H
#define MF_WATCH_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>

#include "mf_dict.h"
#include "mf_log.h"
#include "mf_params.h"
#include "mf_sim.h"

typedef struct mf_watch_settings {
    bool enabled;
    double energy_tolerance;  /* fraction of the energy scale */
    double density_collapse;  /* fraction of n0 */
    bool available_energy;    /* the availableEnergy criterion on */
    double available_tolerance; /* fraction of the available energy (and E) */
} mf_watch_settings;

/* The container's floor for the availableEnergy criterion
 * (watch_available.c): gravity along axis `axis` of magnitude g, heights
 * measured up (against g), the floor the face of tank box `tank` that g
 * points at, of area `area` (2-D: its width, per unit depth). */
typedef struct mf_watch_floor {
    bool applies;
    int axis;
    double up;      /* +1: up is +axis (g points at -axis); -1: the other way */
    double g;       /* |g|, m/s^2 */
    size_t tank;    /* its index in sim->walls */
    double area;
} mf_watch_floor;

typedef struct mf_watch {
    mf_watch_settings s;
    bool started;
    double ke0;          /* kinetic energy when the watch started */
    double work;         /* work of the force modules since then */
    double pot_scale;    /* sum m |a_ext| L at the start */
    double surface_scale; /* sigma S at the start: what surface tension as a pressure can release */
    double wall_scale;   /* the largest 1/2 M u_w^2 so far: what moving walls can give the fluid */
    double n_start;      /* mean fluid number density at the first check (-1: not yet) */
    /* Candidate values of the step being checked (committed on accept). */
    double next_work;
    double next_excess;
    /* The largest (KE - KE0 - W) / scale of an accepted step: how close the
     * run came to the energy criterion (the log's last lines). */
    double peak_excess;
    double peak_excess_time;
    double next_time;
    /* availableEnergy: the floor, the fluid's potential energy and gravity's
     * momentum at the start, gravity's work (from the momentum, the
     * trapezoidal rule as W) and the step's candidates, and the peak
     * (KE - budget) / (budget + E) of an accepted step. */
    mf_watch_floor floor;
    double pe0, rest_energy; /* rest_energy: E, the level layers' above the floor */
    double momentum[3], next_momentum[3];
    double gravity_work, next_gravity_work;
    double next_available, peak_available, peak_available_time;
} mf_watch;

extern const mf_param mf_watch_params[];
extern const size_t mf_watch_nparams;

/* Settings from controlDict's `watch { ... }` (dict may be NULL: defaults). */
int mf_watch_init(mf_watch *w, const mf_dict *dict, mf_dict *resolved);
/* Check the state after a step of dt. 0, or MF_ERR_NUMERIC with a diagnosis. */
int mf_watch_check(mf_watch *w, const mf_sim *sim, double dt);
/* The step was accepted: keep its energy bookkeeping. */
void mf_watch_accept(mf_watch *w);
/* The end of a run: how close it came to the energy criterion (the log's
 * `Watch:` line; nothing when the energy check is off). */
void mf_watch_report(const mf_watch *w, mf_log *log);

#pragma GCC visibility pop
#endif
