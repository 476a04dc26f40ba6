/* forces.h: force modules (kind force). Each adds an acceleration to the
 * fluid particles; none is computed unless the case names it in
 * system/solverDict `forces { ... }`. Solvers call them through the
 * wrappers of mf_modules.h (mf_force_accumulate, mf_stable_dt,
 * mf_forces_surface_pressure), which know them only by their tables. */
#ifndef FORCES_H
#define FORCES_H

#include "mf_modules.h"

extern const mf_force_ops mf_force_gravity;
extern const mf_force_ops mf_force_surfaceTension; /* surfaceTension/, Appendix A */
extern const mf_force_ops mf_force_drag;           /* drag.c, Appendix B */

#endif
