/* fluid_snapshots.h: what the multi-fluid metrics share (metric_droplet.c,
 * metric_layering.c, metric_rayleigh_taylor.c, metric_fluid_front.c): the
 * case's fluids by name, snapshots loaded with their FluidId and Pressure,
 * centroids, and the growable columns of their result.csv. Fluids are named
 * as in constant/fluids (their order there is the FluidId); with one fluid
 * every fluid particle belongs to it. Internal to driver/post. */
#ifndef MF_FLUID_SNAPSHOTS_H
#define MF_FLUID_SNAPSHOTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mf_hdf5.h"
#include "mf_report.h"
#include "mf_sim.h"

/* Index of a fluid of the case by name (constant/fluids order); the error
 * names the case's validation/metric. */
int mf_post_fluid_index(const char *case_dir, const char *name, int *index);
/* *sim zeroed, then its fluid table from the case's constant/fluids. */
int mf_post_read_fluids(const char *case_dir, mf_sim *sim);
/* The densities of the case's fluids (constant/fluids order). */
int mf_post_fluid_densities(const char *case_dir, double rho[MF_MAX_FLUIDS]);

/* One snapshot: its particles (every stored field) and header. */
typedef struct mf_fsnap {
    mf_sim sim;
    mf_hdf5_header h;
    const int32_t *fid;    /* NULL with one fluid */
    const double *p;       /* Pressure, or NULL */
} mf_fsnap;

int mf_fsnap_load(const char *case_dir, int index, mf_fsnap *s);
void mf_fsnap_free(mf_fsnap *s);

/* Is particle i a fluid particle of `fluid` (any fluid when fluid < 0)? */
static inline bool mf_fsnap_is_of(const mf_fsnap *s, size_t i, int fluid)
{
    return s->sim.p->kind[i] == MF_FLUID && (!s->fid || fluid < 0 || s->fid[i] == fluid);
}

/* Centroid of the particles of a fluid, and how many there are. */
void mf_fsnap_centroid(const mf_fsnap *s, int fluid, double c[3], size_t *count);

/* Growable columns for result.csv (ncols <= 6; zero-initialise, set ncols). */
typedef struct mf_table {
    size_t n, cap, ncols;
    double *col[6];
} mf_table;

int mf_table_add(mf_table *t, const double *row);
void mf_table_free(mf_table *t);
/* out_dir/result.csv from the table, out_dir/result.png from the plot. */
int mf_table_report(const char *out_dir, const char *comment, const char *header,
                    const mf_table *t, const mf_plot *plot, const mf_series *series,
                    size_t nseries);

#endif
