/* levelset_module.c: the levelSet surface module (eqs. 29-32): create,
 * reconstruct (levelset_step.c), destroy, and its ops table. */
#include <stdlib.h>
#include <string.h>

#include "levelset.h"

static int ls_create(const void *settings, void **data)
{
    ls_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->s = *(const ls_settings *)settings;
    d->imex = strcmp(d->s.integrator, "imex") == 0;
    d->s.integrator = NULL;
    ls_band_init(&d->band, (double)d->s.band_width, ls_memory_limit(d->s.max_memory));
    *data = d;
    return 0;
}

static void ls_destroy(void *data)
{
    ls_data *d = data;
    if (!d)
        return;
    ls_band_free(&d->band);
    free(d);
}

static int ls_reconstruct(void *data, const mf_sim *sim, mf_mesh *out)
{
    MF_CALL(ls_frame(data, sim, out));
    return 0;
}

const mf_surface_ops mf_surface_levelSet = {
    .info = {MF_ABI_VERSION, MF_KIND_SURFACE, "levelSet",
             "level set surface from particles, eqs. 29-32, integrated by SUNDIALS ARKODE",
             ls_params, LS_NPARAMS, sizeof(ls_settings)},
    .create = ls_create,
    .destroy = ls_destroy,
    .reconstruct = ls_reconstruct,
};
