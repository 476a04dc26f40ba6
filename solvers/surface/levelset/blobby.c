/* blobby.c: the blobby preview, the iso-surface of a sum of compact kernels
 * (Blinn's "blobby molecules" with Wyvill's polynomial (1 - d^2/R^2)^3):
 * one field evaluation near the surface and one mesh extraction, no
 * evolution. Fast feedback while a scene is set up; the level set is the
 * smooth surface for the final render. */
#include <stdlib.h>
#include <string.h>

#include "levelset.h"

typedef struct blobby_data {
    blobby_settings s;
} blobby_data;

static int blobby_create(const void *settings, void **data)
{
    blobby_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->s = *(const blobby_settings *)settings;
    *data = d;
    return 0;
}

static void blobby_destroy(void *data) { free(data); }

static int blobby_reconstruct(void *data, const mf_sim *sim, mf_mesh *out)
{
    const blobby_settings *s = &((blobby_data *)data)->s;
    const double l0 = sim->l0, h = ls_grid_spacing(s->grid_spacing, l0);
    const size_t limit = ls_memory_limit(s->max_memory);
    char what[96];
    snprintf(what, sizeof what, "blobby at time %g", sim->time);
    out->nverts = out->ntris = 0;
    out->time = sim->time;
    ls_field f;
    ls_crossing cross;
    ls_field_init(&f);
    ls_crossing_init(&cross);
    int32_t *nb = NULL;
    int rc = 0;
    double t0 = mf_wall_seconds();
    MF_CALL_GOTO(rc, ls_field_setup(&f, sim->p, LS_KERNEL_BLOBBY, h, l0, s->radius, s->radius, 2,
                                    -s->iso_value, false, limit, what),
                 done);
    double t1 = mf_wall_seconds();
    MF_CALL_GOTO(rc, ls_detect(&f, l0, limit, &cross), done);
    double t2 = mf_wall_seconds();
    MF_CALL_GOTO(rc, ls_bricks_neighbours(&cross.b, &nb), done);
    MF_CALL_GOTO(rc, ls_mesh_extract(&cross.b, nb, cross.F, NULL, NULL, h, out), done);
    double t3 = mf_wall_seconds();
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "blobby: time %g, %zu fluid particles, grid spacing %g m (l0/h = %.3g): %zu "
                  "bricks crossed, mesh of %zu vertices and %zu triangles; seconds: binning "
                  "%.3f, field %.3f, mesh %.3f\n",
                  sim->time, f.n, h, l0 / h, cross.b.n, out->nverts, out->ntris, t1 - t0,
                  t2 - t1, t3 - t2);
done:
    free(nb);
    ls_field_free(&f);
    ls_crossing_free(&cross);
    return rc;
}

const mf_surface_ops mf_surface_blobby = {
    .info = {MF_ABI_VERSION, MF_KIND_SURFACE, "blobby",
             "iso-surface of a sum of compact kernels: a fast preview", blobby_params,
             BLOBBY_NPARAMS, sizeof(blobby_settings)},
    .create = blobby_create,
    .destroy = blobby_destroy,
    .reconstruct = blobby_reconstruct,
};
