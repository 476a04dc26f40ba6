/* metric_target_fraction.c: the fraction of the fluid inside a target shape
 * (the directedSplash tutorial, issue 18's control forces).
 *
 * For each snapshot: the number of fluid particles whose position lies in
 * the target region (the control forces' shapes: box, sphere, mesh, with
 * the level-set offset; force/control/control_shape.h) over the number of
 * fluid particles. The value `validate` prints is the fraction at the
 * newest snapshot: not an error, larger is better. With `uncontrolled` (a
 * case folder, relative to this one) the same is computed for that run, the
 * same scene without the control forces, and reported beside it (CSV
 * comment and columns, the plot): the control's effect is the difference. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "force/control/control_shape.h"
#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_mesh_import.h"
#include "mf_post.h"
#include "mf_report.h"

typedef struct fraction_settings {
    const char *metric;
    control_shape_settings target;
    const char *uncontrolled;
} fraction_settings;

static const mf_param fraction_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(fraction_settings, metric),
     "targetFraction"},
    CONTROL_SHAPE_PARAMS(fraction_settings, target, "target shape"),
    {"uncontrolled", MF_PARAM_WORD, "none", MF_NO_RANGE, NULL,
     offsetof(fraction_settings, uncontrolled),
     "case folder (relative to this case) of the same scene run without control: reported "
     "beside"},
};
#define FRACTION_NPARAMS (sizeof fraction_params / sizeof fraction_params[0])

/* The fractions of every snapshot of case_dir (all of them: the selection
 * applies to the case validated, and the uncontrolled run's times are matched
 * to it). */
typedef struct fraction_series {
    double *t, *f;
    size_t n;
} fraction_series;

static int fractions(const char *case_dir, const int *idx, size_t nsnap,
                     const fraction_settings *s, fraction_series *out)
{
    out->t = calloc(nsnap + 1, sizeof *out->t);
    out->f = calloc(nsnap + 1, sizeof *out->f);
    out->n = 0;
    if (!out->t || !out->f)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    char path[4400], geometry[4400];
    snprintf(geometry, sizeof geometry, "%s/constant/geometry", case_dir);
    const mf_trimesh_reader reader = mf_mesh_import_reader();
    control_shape shape;
    memset(&shape, 0, sizeof shape);
    bool made = false;
    int rc = 0;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        mf_snapshot_path(case_dir, idx[k], path, sizeof path);
        mf_hdf5_header h;
        mf_sim snap;
        memset(&snap, 0, sizeof snap);
        rc = mf_hdf5_read_header(path, &h);
        if (rc == 0)
            rc = mf_hdf5_read_snapshot(path, &snap);
        if (rc == 0 && !made) { /* the shape at the run's dimension and l0 */
            mf_sim geo = {.dim = h.dim, .l0 = h.l0, .mesh_reader = &reader,
                          .mesh_relative_to = geometry};
            rc = control_shape_create(&s->target, "targetFraction", &geo, &shape);
            made = rc == 0;
        }
        size_t inside = 0, fluid = 0;
        for (size_t i = 0; rc == 0 && i < snap.p->n; i++) {
            if (snap.p->kind[i] != MF_FLUID)
                continue;
            fluid++;
            inside += control_shape_contains(&shape, &snap.p->pos[3 * i], NULL);
        }
        mf_particles_destroy(snap.p);
        if (rc == 0) {
            out->t[out->n] = h.time;
            out->f[out->n] = fluid ? (double)inside / (double)fluid : 0;
            out->n++;
        }
    }
    if (made)
        control_shape_free(&shape);
    return rc;
}

static void series_free(fraction_series *s)
{
    free(s->t);
    free(s->f);
}

static int evaluate(const void *settings, const mf_metric_ctx *ctx, double *value)
{
    fraction_settings s = *(const fraction_settings *)settings;
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    fraction_series run = {0}, free_run = {0};
    int rc = fractions(ctx->case_dir, idx, nsnap, &s, &run);
    free(idx);
    idx = NULL;
    if (rc == 0 && run.n == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no snapshot", ctx->case_dir);
    char other[4400];
    const bool compare = strcmp(s.uncontrolled, "none") != 0;
    if (rc == 0 && compare) {
        snprintf(other, sizeof other, "%s/%s", ctx->case_dir, s.uncontrolled);
        rc = mf_list_snapshots(other, &idx, &nsnap);
        if (rc == 0)
            rc = fractions(other, idx, nsnap, &s, &free_run);
        free(idx);
        if (rc == 0 && free_run.n == 0)
            rc = MF_ERROR(MF_ERR_INPUT, "%s: the uncontrolled run has no snapshot (run it: "
                          "the tutorial's Allrun does)", other);
    }
    /* The uncontrolled fraction at the run's times (NaN where it has none). */
    double *matched = rc == 0 ? calloc(run.n, sizeof *matched) : NULL;
    if (rc == 0 && !matched)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    for (size_t k = 0; rc == 0 && k < run.n; k++) {
        matched[k] = NAN;
        for (size_t m = 0; m < free_run.n; m++)
            if (fabs(free_run.t[m] - run.t[k]) <= 1e-9 * fmax(1, fabs(run.t[k])))
                matched[k] = free_run.f[m];
    }
    char path[4400], comment[1024];
    if (rc == 0) {
        *value = run.f[run.n - 1];
        if (compare)
            snprintf(comment, sizeof comment,
                     "fraction of the fluid inside the %s target: %.6g at t = %g s; the "
                     "uncontrolled run (%s): %.6g at t = %g s", s.target.shape, *value,
                     run.t[run.n - 1], s.uncontrolled, free_run.f[free_run.n - 1],
                     free_run.t[free_run.n - 1]);
        else
            snprintf(comment, sizeof comment,
                     "fraction of the fluid inside the %s target: %.6g at t = %g s (no "
                     "uncontrolled run given)", s.target.shape, *value, run.t[run.n - 1]);
        snprintf(path, sizeof path, "%s/result.csv", ctx->out_dir);
        const double *cols[3] = {run.t, run.f, matched};
        rc = mf_report_csv(path, comment, "time,fraction,fraction_uncontrolled", 3, cols, run.n);
    }
    if (rc == 0) {
        snprintf(path, sizeof path, "%s/result.png", ctx->out_dir);
        char title[256];
        snprintf(title, sizeof title, "Fluid inside the target (%.3g at the end)", *value);
        mf_plot plot = {title, "t, s", "fraction inside the target", false, false, NULL};
        mf_series series[2] = {{"controlled", run.t, run.f, run.n, "linespoints pt 7", NULL},
                               {"uncontrolled", free_run.t, free_run.f, free_run.n,
                                "linespoints pt 6", NULL}};
        rc = mf_report_plot(path, &plot, series, compare ? 2 : 1);
    }
    if (rc == 0 && compare)
        printf("targetFraction: controlled %.6g, uncontrolled %.6g\n", *value,
               free_run.f[free_run.n - 1]);
    free(matched);
    series_free(&run);
    series_free(&free_run);
    return rc;
}

const mf_metric_ops mf_metric_target_fraction = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "targetFraction",
     "fraction of the fluid inside a target shape (control forces)",
     fraction_params, FRACTION_NPARAMS, sizeof(fraction_settings)},
    evaluate,
    NULL,
};
