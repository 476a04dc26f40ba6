/* forces.h: force modules (kind force). Each adds an acceleration to the
 * fluid particles; none is computed unless the case names it in
 * system/solverDict `forces { ... }`. */
#ifndef FORCES_H
#define FORCES_H

#include <stdbool.h>
#include <stdint.h>

#include "mf_modules.h"

extern const mf_force_ops mf_force_gravity;
extern const mf_force_ops mf_force_surfaceTension; /* surface_tension.c, Appendix A */
extern const mf_force_ops mf_force_drag;           /* drag.c, Appendix B */

/* The largest step the case's forces allow (the capillary limit of
 * surfaceTension); INFINITY when none limits it. For a solver's stable_dt. */
double mf_forces_stable_dt(const mf_sim *sim);

/* surfaceTension's `freeSurface pressure`: the Laplace pressure sigma kappa
 * becomes the Dirichlet value of the free surface (eq. 18) instead of 0, and
 * the module applies no force there. A solver that applies it claims it once
 * at create time (true: some surfaceTension module asks for it; a module in
 * that mode refuses to run unclaimed) and, each step after the forces have
 * accumulated and the free surface is known, gets p[i] (one entry per
 * particle: sigma kappa_i where dirichlet[i] is set, 0 elsewhere). */
bool mf_forces_claim_surface_pressure(mf_sim *sim);

/* The largest radius within which the case's forces read neighbours (m; 0
 * for none): the copies of other ranks' particles a solver keeps must reach
 * it. */
double mf_forces_radius(const mf_sim *sim);
double mf_drag_radius(const void *drag_data); /* drag.c */
void mf_forces_surface_pressure(const mf_sim *sim, const uint8_t *dirichlet, double *p);

#endif
