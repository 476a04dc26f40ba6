/* builtins.c: the one explicit registration call for built-in modules. */
#include "mf_app.h"
#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_post.h"
#include "mf_solvers.h"

int mf_register_builtins(mf_registry *reg)
{
    MF_CALL(mf_solvers_register_all(reg));
    MF_CALL(mf_post_register_all(reg));
    MF_CALL(mf_registry_add(reg, &mf_writer_hdf5.info));
    return 0;
}
