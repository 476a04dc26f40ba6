/* surface_fo.c: the `surface` function object, which reconstructs the free
 * surface at the write times of a run (after the snapshot is written). It sits in the
 * post-processing layer because it writes meshes (io); the surface modules
 * themselves (solvers/surface) write nothing.
 *
 *   functions
 *   {
 *       surface
 *       {
 *           type            surface;
 *           method          levelSet;           // or blobby
 *           levelSetCoeffs  { gridSpacing 0.004; integrator imex; }
 *           writeOBJ        no;
 *       }
 *   }
 *
 * Frames go to postProcessing/<name>/surface_NNNNNN.{ply,obj,h5} with the
 * index postProcessing/<name>/surface.xdmf. NNNNNN counts on from the
 * frames already there, as the snapshots do, so a fresh run numbers both
 * alike. The module's state (the level set's previous phi) lives as long
 * as the run: each frame is warm-started from the last. */
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_post.h"
#include "surface/levelset/levelset.h"
#include "mf_mesh_writer.h"

typedef struct surface_fo {
    surface_settings s;
    mf_module m;
    char dir[4400];
    int next_index;
    mf_mesh mesh;
} surface_fo;

static void fo_destroy(void *data)
{
    surface_fo *d = data;
    if (!d)
        return;
    surface_close(&d->m);
    mf_mesh_free(&d->mesh);
    free(d);
}

static int fo_create(const void *settings, const mf_sim *sim, const char *out_dir, void **data)
{
    surface_fo *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->s = *(const surface_settings *)settings;
    mf_mesh_init(&d->mesh);
    snprintf(d->dir, sizeof d->dir, "%s", out_dir);
    const mf_dict *coeffs = strcmp(d->s.method, "levelSet") == 0 ? d->s.levelset_coeffs
                            : strcmp(d->s.method, "blobby") == 0 ? d->s.blobby_coeffs
                                                                 : NULL;
    int rc = mf_module_prepare(sim->reg, MF_KIND_SURFACE, d->s.method, coeffs, NULL, NULL, &d->m);
    if (rc == 0)
        rc = ((const mf_surface_ops *)d->m.info)->create(d->m.settings, &d->m.data);
    if (rc != 0) {
        fo_destroy(d);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    d->next_index = mf_mesh_last_index(d->dir, "surface") + 1;
    *data = d;
    return 0;
}

static int fo_execute(void *data, const mf_sim *sim)
{
    (void)data;
    (void)sim;
    return 0;
}

static int write_frame(surface_fo *d, const mf_sim *sim);

/* On several ranks the whole fluid is gathered on rank 0, which makes and
 * writes the frame (the surface is one field over all the particles; the
 * frames of a run are few, the `surface -parallel` command spreads a
 * case's frames over ranks instead). */
static int fo_write(void *data, const mf_sim *sim)
{
    surface_fo *d = data;
    if (!sim->par)
        return write_frame(d, sim);
    mf_particles *all = NULL;
    MF_CALL(mf_parallel_gather(sim->par, sim->p, 0, &all));
    int rc = 0;
    if (mf_parallel_is_root(sim->par)) {
        mf_sim whole = *sim;
        whole.p = all;
        whole.par = NULL;
        whole.halo = NULL;
        rc = write_frame(d, &whole);
        mf_particles_destroy(all);
    } else {
        d->next_index++; /* the same numbering on every rank */
    }
    return rc;
}

static int write_frame(surface_fo *d, const mf_sim *sim)
{
    const mf_surface_ops *ops = (const mf_surface_ops *)d->m.info;
    size_t counts[MF_NKINDS];
    mf_particles_count_kinds(sim->p, counts);
    if (counts[MF_FLUID] == 0) { /* a scene that fills over time starts empty */
        mf_log_printf(sim->log, MF_LOG_NORMAL, "surface: time %g: no fluid yet, skipped\n",
                      sim->time);
        d->next_index++; /* frames keep the snapshots' numbers */
        return 0;
    }
    double t0 = mf_wall_seconds();
    MF_CALL(ops->reconstruct(d->m.data, sim, &d->mesh));
    MF_CALL(mf_mesh_write_frame(d->dir, "surface", d->next_index, &d->mesh, d->s.write_ply,
                                d->s.write_obj));
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "surface: %s/surface_%06d (%zu triangles, %s) in %.2f s\n", d->dir,
                  d->next_index, d->mesh.ntris, d->s.method, mf_wall_seconds() - t0);
    d->next_index++;
    return 0;
}

const mf_function_object_ops mf_function_surface = {
    .info = {MF_ABI_VERSION, MF_KIND_FUNCTION_OBJECT, "surface",
             "reconstructs the free surface (levelSet or blobby) at the write times",
             surface_params, SURFACE_NPARAMS, sizeof(surface_settings)},
    .create = fo_create,
    .execute = fo_execute,
    .destroy = fo_destroy,
    .write = fo_write,
};
