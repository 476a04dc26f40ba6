/* forces.h: force modules (kind force). Each adds an acceleration to the
 * fluid particles; none is computed unless the case names it in
 * system/solverDict `forces { ... }`. */
#ifndef FORCES_H
#define FORCES_H

#include "mf_modules.h"

extern const mf_force_ops mf_force_gravity;
extern const mf_force_ops mf_force_surfaceTension; /* surface_tension.c, Appendix A */
extern const mf_force_ops mf_force_drag;           /* drag.c, Appendix B */

/* The largest step the case's forces allow (the capillary limit of
 * surfaceTension); INFINITY when none limits it. For a solver's stable_dt. */
double mf_forces_stable_dt(const mf_sim *sim);

#endif
