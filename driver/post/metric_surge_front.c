/* metric_surge_front.c: the dam-break surge front against an experiment.
 *
 * Front z: the largest distance from the back wall of a fluid particle with
 * at least two fluid neighbours within 2.1 l0 (isolated spray is ignored).
 * Z = z / a, T = t sqrt(2 g / a). The run's Z(T) is interpolated linearly in
 * time at each reference T inside the run; error = RMS of Z over them. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_pairs.h"
#include "mf_post.h"
#include "mf_report.h"

typedef struct front_settings {
    const char *metric, *reference;
    double a, back_wall, g;
    long direction;
} front_settings;

static const mf_param front_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(front_settings, metric),
     "surgeFront"},
    {"reference", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(front_settings, reference),
     "CSV file T,Z in validation/"},
    {"columnWidth", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(front_settings, a),
     "a, the initial column width, m"},
    {"backWall", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL, offsetof(front_settings, back_wall),
     "x of the back wall, m"},
    {"gravity", MF_PARAM_SCALAR, "9.81", 1e-9, 1e9, NULL, offsetof(front_settings, g),
     "g, m/s^2"},
};

/* Counts i's neighbours, stopping at two. */
static inline bool count_two(void *acc, const void *ctx, const mf_pair *pr)
{
    (void)ctx;
    (void)pr;
    return ++*(int *)acc < 2;
}

int mf_front_of_particles(const mf_particles *fluid, double l0, double back_wall, double *z)
{
    const double radius = 2.1 * l0;
    *z = 0;
    if (fluid->n == 0)
        return 0;
    mf_neighbours *nb = NULL;
    MF_CALL(mf_neighbours_create(&nb));
    int h = 0;
    mf_pairs v;
    int rc = mf_neighbours_request(nb, radius, radius, &h);
    if (rc == 0)
        rc = mf_neighbours_pairs(nb, fluid, h, &v);
    for (size_t i = 0; rc == 0 && i < fluid->n; i++) {
        int count = 0;
        mf_pairs_row_r2(&v, i, NULL, count_two, NULL, &count);
        if (count >= 2 && fluid->pos[3 * i] - back_wall > *z)
            *z = fluid->pos[3 * i] - back_wall;
    }
    mf_neighbours_destroy(nb);
    return rc;
}

/* Front of one snapshot, in m from the back wall. */
static int front_of(const mf_sim *snap, double back_wall, double *z)
{
    const mf_particles *all = snap->p;
    mf_particles *fluid = NULL;
    MF_CALL(mf_particles_create(all->dim, all->n, &fluid));
    int rc = 0;
    for (size_t i = 0; i < all->n && rc == 0; i++)
        if (all->kind[i] == MF_FLUID)
            rc = mf_particles_add(fluid, MF_FLUID, &all->pos[3 * i], &all->vel[3 * i], NULL);
    if (rc == 0)
        rc = mf_front_of_particles(fluid, snap->l0, back_wall, z);
    mf_particles_destroy(fluid);
    return rc;
}

static int evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    const char *case_dir = ctx->case_dir;
    front_settings s = *(const front_settings *)settings;
    char path[4400];
    snprintf(path, sizeof path, "%s/validation/%s", case_dir, s.reference);
    double *Tref = NULL, *Zref = NULL;
    size_t nref = 0;
    MF_CALL(mf_read_csv2(path, &Tref, &Zref, &nref));
    int *idx = NULL;
    size_t nsnap = 0;
    int rc = mf_metric_snapshots(ctx, &idx, &nsnap);
    double *T = calloc(nsnap + 1, sizeof *T), *Z = calloc(nsnap + 1, sizeof *Z);
    if (rc == 0 && (!T || !Z))
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    const double tscale = sqrt(2 * s.g / s.a);
    size_t n = 0;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        mf_sim snap;
        memset(&snap, 0, sizeof snap);
        mf_snapshot_path(case_dir, idx[k], path, sizeof path);
        mf_hdf5_header h;
        rc = mf_hdf5_read_header(path, &h);
        if (rc == 0)
            rc = mf_hdf5_read_snapshot(path, &snap);
        double z = 0;
        snap.l0 = h.l0;
        if (rc == 0)
            rc = front_of(&snap, s.back_wall, &z);
        mf_particles_destroy(snap.p);
        if (rc == 0 && (n == 0 || h.time * tscale > T[n - 1])) {
            T[n] = h.time * tscale;
            Z[n] = z / s.a;
            n++;
        }
    }
    /* RMS over the reference points the run covers. */
    double sum = 0, *Zsim = calloc(nref, sizeof *Zsim);
    size_t used = 0;
    for (size_t i = 0; rc == 0 && Zsim && i < nref; i++) {
        Zsim[i] = mf_interp(T, Z, n, Tref[i]);
        if (!isnan(Zsim[i])) {
            sum += (Zsim[i] - Zref[i]) * (Zsim[i] - Zref[i]);
            used++;
        }
    }
    if (rc == 0 && used == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: the run (T up to %.3g) covers none of the reference "
                      "times (from T = %.3g): run longer",
                      case_dir, n ? T[n - 1] : 0.0, Tref[0]);
    if (rc == 0) {
        *error = sqrt(sum / used);
        snprintf(path, sizeof path, "%s/result.csv", ctx->out_dir);
        const double *cols[3] = {Tref, Zref, Zsim};
        char comment[512];
        snprintf(comment, sizeof comment,
                 "surge front Z = z/a against T = t sqrt(2g/a); reference: %s\n"
                 "Z_sim interpolated linearly in time (nan: outside the run)\n"
                 "RMS error over %zu points = %.6g",
                 s.reference, used, *error);
        rc = mf_report_csv(path, comment, "T,Z_reference,Z_mpsflow", 3, cols, nref);
    }
    if (rc == 0) {
        snprintf(path, sizeof path, "%s/result.png", ctx->out_dir);
        char title[256];
        snprintf(title, sizeof title, "Dam break surge front (RMS error of Z = %.3g)", *error);
        mf_plot plot = {title, "T = t sqrt(2g/a)", "Z = z/a", false, false, NULL};
        mf_series series[2] = {
            {"mpsflow", T, Z, n, "lines lw 2", NULL},
            {s.reference, Tref, Zref, nref, "points pt 7 ps 1.5", NULL},
        };
        rc = mf_report_plot(path, &plot, series, 2);
    }
    free(Zsim);
    free(T);
    free(Z);
    free(idx);
    free(Tref);
    free(Zref);
    return rc;
}

const mf_metric_ops mf_metric_surge_front = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "surgeFront",
     "dam-break surge front Z(T) against an experiment",
     front_params, sizeof front_params / sizeof front_params[0], sizeof(front_settings)},
    evaluate,
    NULL,
};
