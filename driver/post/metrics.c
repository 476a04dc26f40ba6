/* metrics.c: the registration of the post-processing modules (every
 * validation metric, the surface function object) and the snapshots a
 * metric works on. */
#include <stdlib.h>
#include <string.h>

#include "fluid_snapshots.h"
#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_post.h"

/* Every metric of this layer, in the order `mpsflow modules` lists them. */
static const mf_metric_ops *const metrics[] = {
    &mf_metric_surge_front,
    &mf_metric_hydrostatic,
    &mf_metric_scalar_advection,
    &mf_metric_volume_flux,
    &mf_metric_laplace,
    &mf_metric_oscillation,
    &mf_metric_layering,
    &mf_metric_rayleigh_taylor,
    &mf_metric_fluid_surge_front,
    &mf_metric_poiseuille,
    &mf_metric_couette,
    &mf_metric_sloshing,
    &mf_metric_containment,
    &mf_metric_resting_tank,
    &mf_metric_target_fraction,
    &mf_metric_floating,
    &mf_metric_water_entry,
};

int mf_post_register_all(mf_registry *reg)
{
    MF_CALL(mf_registry_add(reg, &mf_function_surface.info));
    for (size_t k = 0; k < sizeof metrics / sizeof metrics[0]; k++)
        MF_CALL(mf_registry_add(reg, &metrics[k]->info));
    return 0;
}

int mf_metric_snapshots(const mf_metric_ctx *ctx, int **indices, size_t *n)
{
    if (!ctx->selected)
        return mf_list_snapshots(ctx->case_dir, indices, n);
    if (ctx->nselected == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: no snapshot selected", ctx->case_dir);
    *indices = malloc(ctx->nselected * sizeof **indices);
    if (!*indices)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    memcpy(*indices, ctx->selected, ctx->nselected * sizeof **indices);
    *n = ctx->nselected;
    return 0;
}

int mf_metric_read_snapshot(const mf_metric_ctx *ctx, int index, mf_sim *snap)
{
    char path[4400];
    mf_snapshot_path(ctx->case_dir, index, path, sizeof path);
    mf_hdf5_header h;
    MF_CALL(mf_hdf5_read_header(path, &h));
    MF_CALL(mf_post_read_fluids(ctx->case_dir, snap)); /* masses: mf_sim_particle_mass */
    MF_CALL(mf_hdf5_read_snapshot(path, snap));
    snap->time = h.time;
    snap->step = h.step;
    snap->l0 = h.l0;
    return 0;
}
