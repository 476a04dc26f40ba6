/* register_all.c: every module of solvers/ (PETSc's XXXRegisterAll). */
#include "mf_error.h"
#include "mf_solvers.h"

#include "convection/convection.h"
#include "force/forces.h"
#include "surface/levelset/levelset.h"
#include "solver/mafl/mafl.h"
#include "solver/mps/mps.h"
#include "solver/multifluid/multifluid.h"
#include "pressure/pressure_hypre.h"

int mf_solvers_register_all(mf_registry *reg)
{
    static const mf_module_info *const modules[] = {
        &mf_solver_MPS.info,
        &mf_pressure_PCG_BoomerAMG.info,
        &mf_pressure_PCG_diagonal.info,
        &mf_force_gravity.info,
        &mf_surface_levelSet.info,
        &mf_surface_blobby.info,
        &mf_solver_multiFluid.info,
        &mf_force_surfaceTension.info,
        &mf_force_drag.info,
        &mf_force_attraction.info,
        &mf_force_velocityRegion.info,
        &mf_force_pathFollow.info,
        &mf_solver_MAFL.info,
        &mf_convection_upwind.info,
        &mf_convection_QUICK.info,
    };
    for (size_t k = 0; k < sizeof modules / sizeof modules[0]; k++)
        MF_CALL(mf_registry_add(reg, modules[k]));
    return 0;
}
