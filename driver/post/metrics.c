/* metrics.c: the table of validation metrics (validation/metric names one)
 * and the snapshots a metric works on. */
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_post.h"

extern const mf_metric mf_metric_scalar_advection; /* metric_scalar.c */
extern const mf_metric mf_metric_volume_flux;      /* metric_scalar.c */
extern const mf_metric mf_metric_poiseuille;       /* metric_poiseuille.c */
extern const mf_metric mf_metric_couette;          /* metric_poiseuille.c */
extern const mf_metric mf_metric_sloshing;         /* metric_sloshing.c */
extern const mf_metric mf_metric_containment;      /* metric_containment.c */
extern const mf_metric mf_metric_resting_tank;     /* metric_resting_tank.c */
extern const mf_metric mf_metric_target_fraction;  /* metric_target_fraction.c */
extern const mf_metric mf_metric_floating;         /* metric_floating.c */
/* metric_droplet.c: the multi-fluid cases */
extern const mf_metric mf_metric_laplace, mf_metric_oscillation, mf_metric_layering,
    mf_metric_rayleigh_taylor, mf_metric_fluid_surge_front;

const mf_metric *const mf_metrics[] = {
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
};
const size_t mf_nmetrics = sizeof mf_metrics / sizeof mf_metrics[0];

const mf_metric *mf_metric_find(const char *name)
{
    for (size_t k = 0; k < mf_nmetrics; k++)
        if (strcmp(mf_metrics[k]->name, name) == 0)
            return mf_metrics[k];
    return NULL;
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
