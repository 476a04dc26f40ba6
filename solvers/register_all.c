/* register_all.c: every module of solvers/ (PETSc's XXXRegisterAll). */
#include "mf_error.h"
#include "mf_solvers.h"

#include "forces/forces.h"
#include "mps/mps.h"
#include "pressure/pressure_hypre.h"

int mf_solvers_register_all(mf_registry *reg)
{
    static const mf_module_info *const modules[] = {
        &mf_solver_MPS.info,
        &mf_pressure_PCG_BoomerAMG.info,
        &mf_pressure_PCG_diagonal.info,
        &mf_force_gravity.info,
    };
    for (size_t k = 0; k < sizeof modules / sizeof modules[0]; k++)
        MF_CALL(mf_registry_add(reg, modules[k]));
    return 0;
}
