/* forces.h: force modules (kind force). Each adds an acceleration to the
 * fluid particles; none is computed unless the case names it in
 * system/solverDict `forces { ... }`. */
#ifndef FORCES_H
#define FORCES_H

#include "mf_modules.h"

extern const mf_force_ops mf_force_gravity;

#endif
