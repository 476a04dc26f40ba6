/* mf_solvers.h: what solvers/ offers the driver. */
#ifndef MF_SOLVERS_H
#define MF_SOLVERS_H

#include "mf_registry.h"

/* Register every solver, pressure, convection and force module. */
int mf_solvers_register_all(mf_registry *reg);

#endif
