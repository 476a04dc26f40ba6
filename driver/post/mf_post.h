/* mf_post.h: the post-processing layer: validation metrics, the `surface`
 * function object and the helpers they share. It reads snapshots and writes
 * reports and meshes (io) from what the solvers compute; the commands that
 * drive it are the driver's (driver/app). */
#ifndef MF_POST_H
#define MF_POST_H

#include <stdbool.h>
#include <stddef.h>

#include "mf_dict.h"
#include "mf_modules.h"
#include "mf_sim.h"

/* Indices of the case's snapshots, ascending. Free *indices. */
int mf_list_snapshots(const char *case_dir, int **indices, size_t *n);
void mf_snapshot_path(const char *case_dir, int index, char *path, size_t len);

/* The snapshots of a metric's context (mf_metric_ctx, mf_modules.h): a
 * malloc'ed copy, free *indices. */
int mf_metric_snapshots(const mf_metric_ctx *ctx, int **indices, size_t *n);
/* One snapshot of the case into a zeroed *snap (p, dim, l0, time, step):
 * what the host puts in mf_metric_ctx.read_snapshot. */
int mf_metric_read_snapshot(const mf_metric_ctx *ctx, int index, mf_sim *snap);

/* The validation metrics (kind metric, mf_metric_ops): validation/metric
 * names one; mf_post_register_all registers every one. */
extern const mf_metric_ops mf_metric_surge_front, mf_metric_hydrostatic,
    mf_metric_scalar_advection, mf_metric_volume_flux, mf_metric_laplace,
    mf_metric_oscillation, mf_metric_layering, mf_metric_rayleigh_taylor,
    mf_metric_fluid_surge_front, mf_metric_poiseuille, mf_metric_couette, mf_metric_sloshing,
    mf_metric_containment, mf_metric_resting_tank, mf_metric_target_fraction, mf_metric_floating,
    mf_metric_water_entry;

/* Snapshots with their times (from the headers), ascending. Free both. */
int mf_snapshot_times(const char *case_dir, int **indices, double **times, size_t *n);
/* Mark the snapshots (times t[0..n)) that an OpenFOAM-style -time text
 * selects: a time (the nearest snapshot), a list "0.1,0.2", a range
 * "0.1:0.5", ":0.5", "0.5:". */
int mf_select_times(const char *spec, const double *t, size_t n, bool *sel);

/* The surge front of a fluid particle set: the largest x - back_wall of a
 * particle with at least two neighbours within 2.1 l0 (lone splashes do not
 * count); 0 for no particle. */
int mf_front_of_particles(const mf_particles *fluid, double l0, double back_wall, double *z);

/* Linear interpolation of y(x) at xq on ascending x; NAN outside. */
double mf_interp(const double *x, const double *y, size_t n, double xq);
/* The period of an oscillation q(t) (n samples) from its zero crossings:
 * 2 (t_last - t_first)/(crossings - 1), NAN with fewer than two; cross (n
 * entries) receives the crossing times, *nc their count. */
double mf_crossing_period(const double *t, const double *q, size_t n, double *cross, size_t *nc);
/* Read a two-column CSV with '#' comments and one header line. */
int mf_read_csv2(const char *path, double **a, double **b, size_t *n);

/* Register the post-processing modules: the `surface` function object and
 * every metric. */
int mf_post_register_all(mf_registry *reg);
extern const mf_function_object_ops mf_function_surface;

#endif
