/* mf_timestep.h: time-step limits (Courant, viscous, user maximum). */
#ifndef MF_TIMESTEP_H
#define MF_TIMESTEP_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include "mf_particles.h"

typedef struct mf_dt_choice {
    double dt;
    double umax;          /* largest fluid speed */
    const char *limiter;  /* "Courant", "viscous", "maxDeltaT" */
} mf_dt_choice;

/* Largest speed among fluid particles (0 when there are none). */
double mf_max_fluid_speed(const mf_particles *p);
/* Mean and max Courant number |u| dt / l0 over fluid particles. */
void mf_courant(const mf_particles *p, double dt, double l0, double *mean, double *max);
/* dt = min(courant l0 / umax, viscous l0^2 / nu, dt_max). nu <= 0 or
 * viscous <= 0 disable the viscous limit; courant <= 0 disables Courant. */
void mf_dt_choose(double l0, double umax, double courant, double nu, double viscous,
                  double dt_max, mf_dt_choice *out);

#pragma GCC visibility pop
#endif
