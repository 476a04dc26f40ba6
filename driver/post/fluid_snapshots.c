/* fluid_snapshots.c: the helpers of fluid_snapshots.h. */
#include "fluid_snapshots.h"

#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_post.h"
#include "mf_scene.h"

int mf_post_read_fluids(const char *case_dir, mf_sim *sim)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/constant/fluids", case_dir);
    mf_dict *d = NULL;
    MF_CALL(mf_dict_parse_file(path, &d));
    memset(sim, 0, sizeof *sim);
    int rc = mf_scene_read_fluids(d, sim);
    mf_dict_free(d);
    return rc;
}

int mf_post_fluid_index(const char *case_dir, const char *name, int *index)
{
    mf_sim sim;
    int rc = mf_post_read_fluids(case_dir, &sim);
    if (rc == 0)
        rc = mf_scene_fluid_index(&sim, name, index);
    if (rc != 0)
        return MF_ERROR(rc, "%s/validation/metric: %s", case_dir, mf_error_message());
    return 0;
}

int mf_post_fluid_densities(const char *case_dir, double rho[MF_MAX_FLUIDS])
{
    mf_sim sim;
    MF_CALL(mf_post_read_fluids(case_dir, &sim));
    for (int k = 0; k < sim.nfluids; k++)
        rho[k] = sim.fluid[k].rho;
    return 0;
}

int mf_fsnap_load(const char *case_dir, int index, mf_fsnap *s)
{
    char path[4400];
    memset(s, 0, sizeof *s);
    mf_snapshot_path(case_dir, index, path, sizeof path);
    MF_CALL(mf_hdf5_read_header(path, &s->h));
    MF_CALL(mf_hdf5_read_snapshot(path, &s->sim));
    int f = mf_particles_field_index(s->sim.p, "FluidId");
    s->fid = f >= 0 ? mf_particles_fi(s->sim.p, f) : NULL;
    f = mf_particles_field_index(s->sim.p, "Pressure");
    s->p = f >= 0 ? mf_particles_fd(s->sim.p, f) : NULL;
    return 0;
}

void mf_fsnap_free(mf_fsnap *s)
{
    mf_particles_destroy(s->sim.p);
}

/* Centroid of the particles of a fluid. */
void mf_fsnap_centroid(const mf_fsnap *s, int fluid, double c[3], size_t *count)
{
    const mf_particles *p = s->sim.p;
    c[0] = c[1] = c[2] = 0;
    *count = 0;
    for (size_t i = 0; i < p->n; i++)
        if (mf_fsnap_is_of(s, i, fluid)) {
            for (int a = 0; a < 3; a++)
                c[a] += p->pos[3 * i + a];
            (*count)++;
        }
    for (int a = 0; *count && a < 3; a++)
        c[a] /= (double)*count;
}

int mf_table_add(mf_table *t, const double *row)
{
    if (t->n == t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 64;
        for (size_t c = 0; c < t->ncols; c++)
            MF_CALL(mf_resize(&t->col[c], cap, sizeof *t->col[c]));
        t->cap = cap;
    }
    for (size_t c = 0; c < t->ncols; c++)
        t->col[c][t->n] = row[c];
    t->n++;
    return 0;
}

void mf_table_free(mf_table *t)
{
    for (size_t c = 0; c < t->ncols; c++)
        free(t->col[c]);
}

int mf_table_report(const char *out_dir, const char *comment, const char *header,
                    const mf_table *t, const mf_plot *plot, const mf_series *series,
                    size_t nseries)
{
    char path[4400];
    snprintf(path, sizeof path, "%s/result.csv", out_dir);
    MF_CALL(mf_report_csv(path, comment, header, t->ncols, (const double *const *)t->col, t->n));
    snprintf(path, sizeof path, "%s/result.png", out_dir);
    MF_CALL(mf_report_plot(path, plot, series, nseries));
    return 0;
}
