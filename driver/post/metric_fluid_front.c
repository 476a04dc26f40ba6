/* metric_fluid_front.c: fluidSurgeFront, the dam-break front of one fluid
 * among several (water in air) against an experiment, as surgeFront
 * (metric_surge_front.c) for a single fluid. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_snapshots.h"
#include "mf_error.h"
#include "mf_post.h"

/* The dam-break front of one fluid among several (the water of a water/air
 * dam break): as surgeFront, the largest distance from the back wall of a
 * particle of that fluid with at least two particles of it within 2.1 l0,
 * Z = z/a against T = t sqrt(2g/a), RMS of Z over the reference points the
 * run covers (linear interpolation in time). */

typedef struct front_settings {
    const char *metric, *reference, *fluid;
    double a, back_wall, g, end_wall;
} front_settings;


static const mf_param front_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(front_settings, metric),
     "fluidSurgeFront"},
    {"reference", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(front_settings, reference),
     "CSV file T,Z in validation/"},
    {"fluid", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(front_settings, fluid),
     "the fluid whose front is followed"},
    {"columnWidth", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(front_settings, a),
     "a, the initial column width, m"},
    {"backWall", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL, offsetof(front_settings, back_wall),
     "x of the back wall, m"},
    {"gravity", MF_PARAM_SCALAR, "9.81", 1e-9, 1e9, NULL, offsetof(front_settings, g),
     "g, m/s^2"},
    {"endWall", MF_PARAM_SCALAR, "1e9", -1e9, 1e9, NULL, offsetof(front_settings, end_wall),
     "x of the far wall, m: reference points beyond it (the front stops there) are left out"},
};

/* The front of one fluid (metric_surge_front.c's rule). */
static int fluid_front(const mf_fsnap *sn, int fluid, double back_wall, double *z)
{
    const mf_particles *all = sn->sim.p;
    mf_particles *f = NULL;
    MF_CALL(mf_particles_create(all->dim, all->n + 1, &f));
    int rc = 0;
    for (size_t i = 0; i < all->n && rc == 0; i++)
        if (mf_fsnap_is_of(sn, i, fluid))
            rc = mf_particles_add(f, MF_FLUID, &all->pos[3 * i], &all->vel[3 * i], NULL);
    if (rc == 0)
        rc = mf_front_of_particles(f, sn->h.l0, back_wall, z);
    mf_particles_destroy(f);
    return rc;
}

static int front_evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    const char *case_dir = ctx->case_dir;
    front_settings s = *(const front_settings *)settings;
    int fluid = 0;
    MF_CALL(mf_post_fluid_index(case_dir, s.fluid, &fluid));
    char path[4400];
    snprintf(path, sizeof path, "%s/validation/%s", case_dir, s.reference);
    double *Tref = NULL, *Zref = NULL;
    size_t nref = 0;
    MF_CALL(mf_read_csv2(path, &Tref, &Zref, &nref));
    int *idx = NULL;
    size_t nsnap = 0;
    int rc = mf_metric_snapshots(ctx, &idx, &nsnap);
    mf_table t = {.ncols = 2};
    const double tscale = sqrt(2 * s.g / s.a);
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        mf_fsnap sn;
        rc = mf_fsnap_load(case_dir, idx[k], &sn);
        if (rc != 0)
            break;
        double z = 0;
        rc = fluid_front(&sn, sn.fid ? fluid : -1, s.back_wall, &z);
        double row[2] = {sn.h.time * tscale, z / s.a};
        if (rc == 0 && (t.n == 0 || row[0] > t.col[0][t.n - 1]))
            rc = mf_table_add(&t, row);
        mf_fsnap_free(&sn);
    }
    free(idx);
    double sum = 0, *Zsim = calloc(nref ? nref : 1, sizeof *Zsim);
    size_t used = 0;
    for (size_t i = 0; rc == 0 && Zsim && i < nref; i++) {
        Zsim[i] = mf_interp(t.col[0], t.col[1], t.n, Tref[i]);
        /* Within 0.2 a of the far wall the front has reached it; the
         * experiment's tank was longer. */
        if (Zref[i] * s.a >= s.end_wall - s.back_wall - 0.2 * s.a)
            Zsim[i] = NAN;
        if (!isnan(Zsim[i])) {
            sum += (Zsim[i] - Zref[i]) * (Zsim[i] - Zref[i]);
            used++;
        }
    }
    if (rc == 0 && !Zsim)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    if (rc == 0 && used == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: the run covers none of the reference times: run longer",
                      case_dir);
    if (rc == 0) {
        *error = sqrt(sum / (double)used);
        snprintf(path, sizeof path, "%s/result.csv", ctx->out_dir);
        const double *cols[3] = {Tref, Zref, Zsim};
        char comment[512], title[256];
        snprintf(comment, sizeof comment,
                 "surge front of %s, Z = z/a against T = t sqrt(2g/a); reference: %s\n"
                 "Z_sim interpolated linearly in time (nan: outside the run, or the reference "
                 "front beyond endWall = %g m less 0.2 a)\nRMS error over %zu points = %.6g",
                 s.fluid, s.reference, s.end_wall, used, *error);
        rc = mf_report_csv(path, comment, "T,Z_reference,Z_mpsflow", 3, cols, nref);
        if (rc == 0) {
            snprintf(path, sizeof path, "%s/result.png", ctx->out_dir);
            snprintf(title, sizeof title, "Surge front of %s (RMS error of Z = %.3g)", s.fluid,
                     *error);
            mf_plot plot = {title, "T = t sqrt(2g/a)", "Z = z/a", false, false, NULL};
            mf_series series[2] = {{"mpsflow", t.col[0], t.col[1], t.n, "lines lw 2", NULL},
                                   {s.reference, Tref, Zref, nref, "points pt 7 ps 1.5", NULL}};
            rc = mf_report_plot(path, &plot, series, 2);
        }
    }
    free(Zsim);
    free(Tref);
    free(Zref);
    mf_table_free(&t);
    return rc;
}

const mf_metric_ops mf_metric_fluid_surge_front = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "fluidSurgeFront",
     "dam-break surge front of one fluid among several",
     front_params, sizeof front_params / sizeof front_params[0], sizeof(front_settings)},
    front_evaluate,
    NULL,
};
