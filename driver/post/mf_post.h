/* mf_post.h: the post-processing layer: validation metrics, the `surface`
 * function object and the helpers they share. It reads snapshots and writes
 * reports and meshes (io) from what the solvers compute; the commands that
 * drive it are the driver's (driver/app). */
#ifndef MF_POST_H
#define MF_POST_H

#include <stddef.h>

#include "mf_dict.h"
#include "mf_modules.h"
#include "mf_sim.h"

/* Indices of the case's snapshots, ascending. Free *indices. */
int mf_list_snapshots(const char *case_dir, int **indices, size_t *n);
void mf_snapshot_path(const char *case_dir, int index, char *path, size_t len);

/* A validation metric: reads the case's output, writes
 * validation/result.csv and result.png, returns the error. */
typedef struct mf_metric {
    const char *name;
    const char *summary;
    int (*evaluate)(const char *case_dir, const mf_dict *metric_dict, double *error);
    const mf_param *params; /* the keys of validation/metric besides `metric` */
    size_t nparams;
} mf_metric;

extern const mf_metric mf_metric_surge_front;
/* Every metric `validate` knows (driver/app/validate.c). */
const mf_metric *const *mf_metric_list(size_t *n);

/* The surge front of a fluid particle set: the largest x - back_wall of a
 * particle with at least two neighbours within 2.1 l0 (lone splashes do not
 * count); 0 for no particle. */
int mf_front_of_particles(const mf_particles *fluid, double l0, double back_wall, double *z);
extern const mf_metric mf_metric_hydrostatic;

/* Linear interpolation of y(x) at xq on ascending x; NAN outside. */
double mf_interp(const double *x, const double *y, size_t n, double xq);
/* Read a two-column CSV with '#' comments and one header line. */
int mf_read_csv2(const char *path, double **a, double **b, size_t *n);

/* Register the post-processing modules (the `surface` function object). */
int mf_post_register_all(mf_registry *reg);
extern const mf_function_object_ops mf_function_surface;

#endif
