/* metric_scalar.c: the MPS-MAFL validation metrics: scalarAdvection (a
 * transported scalar against its exact, shifted profile) and volumeFlux
 * (the flow rate through cross-sections of a channel, below).
 *
 * In a uniform flow U the scalar only moves: f(x, t) = f0(x - U t), f0 the
 * initial profile the case declares in constant/geometry (the `scalars`
 * entry of a fluid block; the inlet's value must continue it upstream).
 * For the newest snapshot (time t): error = RMS over the fluid points of
 * f - f0(x - U t). The CSV lists every fluid point (x, y, f, f_exact) by x,
 * with the error, the largest deviation and the range of f in its comment;
 * the PNG plots f and the exact profile against x. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_dictio.h"
#include "mf_emitter.h"
#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_post.h"
#include "mf_report.h"

typedef struct scalar_settings {
    const char *metric, *field, *block;
    double velocity[3];
} scalar_settings;

static const mf_param scalar_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(scalar_settings, metric),
     "scalarAdvection"},
    {"field", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(scalar_settings, field),
     "the transported scalar (a field of the snapshots)"},
    {"velocity", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(scalar_settings, velocity),
     "the uniform velocity U that carries it, m/s"},
    {"block", MF_PARAM_WORD, "", MF_NO_RANGE, NULL, offsetof(scalar_settings, block),
     "fluid block whose profile is f0 (empty: the first that declares the field)"},
};

/* f0: the field's entry in a fluid block of constant/geometry. */
static int initial_profile(const char *case_dir, const scalar_settings *s, int dim,
                           mf_scalar_profile *prof)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/constant/geometry", case_dir);
    mf_dict *geo = NULL;
    MF_CALL(mf_dict_parse_file(path, &geo));
    const mf_dict *blocks = mf_dict_subdict(geo, "fluidBlocks");
    const mf_entry *entry = NULL;
    for (size_t k = 0; blocks && k < blocks->n && !entry; k++) {
        const mf_entry *b = blocks->entries[k];
        if (s->block[0] && strcmp(b->key, s->block) != 0)
            continue;
        if (b->n != 1 || b->items[0]->kind != MF_VAL_DICT)
            continue;
        const mf_dict *scalars = mf_dict_subdict(b->items[0]->dict, "scalars");
        if (scalars)
            entry = mf_dict_find(scalars, s->field);
    }
    int rc = entry ? mf_scalar_profile_read(entry, dim, prof, NULL)
                   : MF_ERROR(MF_ERR_INPUT,
                              "%s: no fluid block%s%s declares the scalar '%s' (fluidBlocks { "
                              "NAME { scalars { %s ...; } } })",
                              path, s->block[0] ? " named " : "", s->block, s->field, s->field);
    mf_dict_free(geo);
    return rc;
}

typedef struct point {
    double x, y, f, exact;
} point;

static int by_x(const void *a, const void *b)
{
    const point *p = a, *q = b;
    if (p->x != q->x)
        return (p->x > q->x) - (p->x < q->x);
    return (p->y > q->y) - (p->y < q->y);
}

static int write_report(const char *out_dir, const scalar_settings *s, const point *pts,
                        size_t n, double t, double error, double worst, double fmin,
                        double fmax)
{
    double *col[4];
    for (int c = 0; c < 4; c++) {
        col[c] = malloc((n ? n : 1) * sizeof *col[c]);
        if (!col[c]) {
            for (int k = 0; k < c; k++)
                free(col[k]);
            return MF_ERROR(MF_ERR_MEMORY, "out of memory");
        }
    }
    for (size_t i = 0; i < n; i++) {
        col[0][i] = pts[i].x;
        col[1][i] = pts[i].y;
        col[2][i] = pts[i].f;
        col[3][i] = pts[i].exact;
    }
    char path[4400], comment[1024];
    snprintf(path, sizeof path, "%s/result.csv", out_dir);
    snprintf(comment, sizeof comment,
             "scalar %s carried by U = (%g %g %g) m/s, time %g s, %zu fluid points\n"
             "exact: the initial profile shifted by U t\n"
             "RMS error = %.6g; largest |f - f_exact| = %.6g; f in [%.6g, %.6g]",
             s->field, s->velocity[0], s->velocity[1], s->velocity[2], t, n, error, worst, fmin,
             fmax);
    const double *const cols[4] = {col[0], col[1], col[2], col[3]};
    int rc = mf_report_csv(path, comment, "x,y,f,f_exact", 4, cols, n);
    if (rc == 0) {
        snprintf(path, sizeof path, "%s/result.png", out_dir);
        char title[256], ylabel[96];
        snprintf(title, sizeof title, "%s at t = %g s (RMS error %.3g)", s->field, t, error);
        snprintf(ylabel, sizeof ylabel, "%s", s->field);
        mf_plot plot = {title, "x, m", ylabel, false, false, NULL};
        mf_series series[2] = {{"mpsflow", col[0], col[2], n, "points pt 7 ps 0.5", NULL},
                               {"exact: f0(x - U t)", col[0], col[3], n, "lines lw 2", NULL}};
        rc = mf_report_plot(path, &plot, series, 2);
    }
    for (int c = 0; c < 4; c++)
        free(col[c]);
    return rc;
}

static int evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    const char *case_dir = ctx->case_dir;
    scalar_settings s = *(const scalar_settings *)settings;
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    char path[4400];
    mf_snapshot_path(case_dir, idx[nsnap - 1], path, sizeof path);
    free(idx);
    mf_sim snap;
    memset(&snap, 0, sizeof snap);
    MF_CALL(mf_hdf5_read_snapshot(path, &snap));
    const mf_particles *p = snap.p;
    mf_scalar_profile prof;
    int rc = initial_profile(case_dir, &s, p->dim, &prof);
    int ff = mf_particles_field_index(p, s.field);
    if (rc == 0 && (ff < 0 || p->field[ff].type != MF_FIELD_DOUBLE || p->field[ff].ncomp != 1))
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no scalar field '%s' (is it declared in the case?)",
                      path, s.field);
    point *pts = rc == 0 ? malloc((p->n ? p->n : 1) * sizeof *pts) : NULL;
    if (rc == 0 && !pts)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    size_t n = 0;
    double sum = 0, worst = 0, fmin = INFINITY, fmax = -INFINITY;
    const double t = snap.time;
    for (size_t i = 0; rc == 0 && i < p->n; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *x = &p->pos[3 * i];
        double x0[3] = {x[0] - s.velocity[0] * t, x[1] - s.velocity[1] * t,
                        p->dim == 3 ? x[2] - s.velocity[2] * t : 0.0};
        point *q = &pts[n++];
        q->x = x[0];
        q->y = x[1];
        q->f = mf_particles_fd(p, ff)[i];
        q->exact = mf_scalar_profile_eval(&prof, x0);
        double e = q->f - q->exact;
        sum += e * e;
        worst = fabs(e) > worst ? fabs(e) : worst;
        fmin = q->f < fmin ? q->f : fmin;
        fmax = q->f > fmax ? q->f : fmax;
    }
    if (rc == 0 && n == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no fluid point", path);
    if (rc == 0) {
        *error = sqrt(sum / (double)n);
        qsort(pts, n, sizeof *pts, by_x);
        rc = write_report(ctx->out_dir, &s, pts, n, t, *error, worst, fmin, fmax);
    }
    free(pts);
    mf_particles_destroy(snap.p);
    return rc;
}

const mf_metric_ops mf_metric_scalar_advection = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "scalarAdvection",
     "a transported scalar against its initial profile shifted by U t",
     scalar_params, sizeof scalar_params / sizeof scalar_params[0], sizeof(scalar_settings)},
    evaluate,
    NULL,
};

/* ---- volumeFlux: the flow rate through cross-sections of a channel ------
 * Continuity says every cross-section of a channel carries the inflow,
 * Q(x) = Q_in, whatever the flow does between (the channelInflow tutorial:
 * an inlet, a backward-facing step, an outlet). For the newest snapshot,
 * Q at each station x_s is the sum of u_x l0^(dim-1) over the fluid points
 * with x_s - l0/2 <= x < x_s + l0/2 (one column of points); error = RMS over the stations of (Q - Q_in)/Q_in.
 * The comment of the CSV also gives how steady the run is (RMS change of
 * the velocity of points kept from the snapshot before, over the inflow
 * speed) and, with stepX, the reattachment length behind the step: the
 * first x past the step where the velocity along the floor row turns
 * positive again. */
typedef struct flux_settings {
    const char *metric;
    double rate, step_x, floor_y, height;
} flux_settings;

static const mf_param flux_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(flux_settings, metric),
     "volumeFlux"},
    {"flowRate", MF_PARAM_SCALAR, NULL, 1e-12, 1e12, NULL, offsetof(flux_settings, rate),
     "Q_in, the inflow (m^2/s in 2-D, m^3/s in 3-D)"},
    {"stepX", MF_PARAM_SCALAR, "-1e30", MF_NO_RANGE, NULL, offsetof(flux_settings, step_x),
     "x of a backward-facing step's face, for the reattachment length (none: -1e30)"},
    {"floorY", MF_PARAM_SCALAR, "0", MF_NO_RANGE, NULL, offsetof(flux_settings, floor_y),
     "y of the floor behind the step, m"},
    {"height", MF_PARAM_SCALAR, "1", 1e-12, 1e12, NULL, offsetof(flux_settings, height),
     "step height S, m: the reattachment length is also given in S"},
};
static const char *const flux_extra[] = {"stations", NULL};

static int read_stations(const mf_dict *md, double **x, size_t *n)
{
    char where[512];
    mf_entry *e = mf_dict_find(md, "stations");
    if (!e || e->n != 1 || e->items[0]->kind != MF_VAL_LIST || e->items[0]->n == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: volumeFlux needs 'stations (x1 x2 ...)', the x of "
                                      "the cross-sections",
                        mf_loc_str(e ? e->loc : md->loc, where, sizeof where));
    e->used = true;
    const mf_value *list = e->items[0];
    *x = malloc(list->n * sizeof **x);
    if (!*x)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    for (size_t k = 0; k < list->n; k++) {
        int rc = mf_value_number(list->items[k], "stations", &(*x)[k]);
        if (rc != 0) {
            free(*x);
            *x = NULL;
            return mf_error_trace(rc, __FILE__, __LINE__, __func__);
        }
    }
    *n = list->n;
    return 0;
}

/* RMS change of velocity between two snapshots, over the points (by id) in both. */
static double unsteadiness(const mf_particles *a, const mf_particles *b, double speed)
{
    int64_t max_id = 0;
    for (size_t i = 0; i < a->n; i++)
        max_id = a->id[i] > max_id ? a->id[i] : max_id;
    long *where = malloc((size_t)(max_id + 1) * sizeof *where);
    if (!where)
        return NAN;
    for (int64_t k = 0; k <= max_id; k++)
        where[k] = -1;
    for (size_t i = 0; i < a->n; i++)
        if (a->kind[i] == MF_FLUID && a->id[i] >= 0)
            where[a->id[i]] = (long)i;
    double sum = 0;
    size_t count = 0;
    for (size_t i = 0; i < b->n; i++) {
        if (b->kind[i] != MF_FLUID || b->id[i] < 0 || b->id[i] > max_id || where[b->id[i]] < 0)
            continue;
        const double *u = &b->vel[3 * i], *v = &a->vel[3 * where[b->id[i]]];
        for (int c = 0; c < 3; c++)
            sum += (u[c] - v[c]) * (u[c] - v[c]);
        count++;
    }
    free(where);
    return count ? sqrt(sum / (double)count) / speed : NAN;
}

static int flux_evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    const char *case_dir = ctx->case_dir;
    flux_settings s = *(const flux_settings *)settings;
    double *xs = NULL;
    size_t ns = 0;
    MF_CALL(read_stations(ctx->dict, &xs, &ns));
    int *idx = NULL;
    size_t nsnap = 0;
    int rc = mf_metric_snapshots(ctx, &idx, &nsnap);
    mf_sim last, before;
    memset(&last, 0, sizeof last);
    memset(&before, 0, sizeof before);
    char path[4400];
    if (rc == 0) {
        mf_snapshot_path(case_dir, idx[nsnap - 1], path, sizeof path);
        rc = mf_hdf5_read_snapshot(path, &last);
    }
    if (rc == 0 && nsnap > 1) {
        char prev[4400];
        mf_snapshot_path(case_dir, idx[nsnap - 2], prev, sizeof prev);
        rc = mf_hdf5_read_snapshot(prev, &before);
    }
    free(idx);
    double *q = calloc(ns, sizeof *q), *qin = calloc(ns, sizeof *qin), *rel = calloc(ns, sizeof *rel);
    if (rc == 0 && (!q || !qin || !rel))
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    double sum = 0, reattach = NAN;
    if (rc == 0) {
        const mf_particles *p = last.p;
        const double l0 = last.l0, area = pow(l0, p->dim - 1);
        for (size_t i = 0; i < p->n; i++) {
            if (p->kind[i] != MF_FLUID)
                continue;
            for (size_t k = 0; k < ns; k++) /* half-open: one column per station */
                if (p->pos[3 * i] >= xs[k] - 0.5 * l0 && p->pos[3 * i] < xs[k] + 0.5 * l0)
                    q[k] += p->vel[3 * i] * area;
        }
        for (size_t k = 0; k < ns; k++) {
            qin[k] = s.rate;
            rel[k] = (q[k] - s.rate) / s.rate;
            sum += rel[k] * rel[k];
        }
        *error = sqrt(sum / (double)ns);
        /* Reattachment: the floor row (centres within l0 of the floor),
         * sorted by x, from the step on: the first x where u_x turns >= 0
         * after having been negative. */
        if (s.step_x > -1e29) {
            size_t nrow = 0;
            point *row = malloc((p->n ? p->n : 1) * sizeof *row);
            for (size_t i = 0; row && i < p->n; i++)
                if (p->kind[i] == MF_FLUID && p->pos[3 * i] > s.step_x &&
                    p->pos[3 * i + 1] - s.floor_y < l0)
                    row[nrow++] = (point){p->pos[3 * i], p->pos[3 * i + 1], p->vel[3 * i], 0};
            if (row) {
                qsort(row, nrow, sizeof *row, by_x);
                bool back = false;
                for (size_t k = 0; k < nrow && isnan(reattach); k++) {
                    if (row[k].f < 0)
                        back = true;
                    else if (back && k > 0) /* between the two points, linearly */
                        reattach = row[k - 1].x + (row[k].x - row[k - 1].x) * (-row[k - 1].f) /
                                                      (row[k].f - row[k - 1].f) - s.step_x;
                }
            }
            free(row);
        }
    }
    if (rc == 0) {
        double unsteady = before.p ? unsteadiness(before.p, last.p, s.rate / s.height) : NAN;
        snprintf(path, sizeof path, "%s/result.csv", ctx->out_dir);
        char comment[1024];
        snprintf(comment, sizeof comment,
                 "flow rate through cross-sections at t = %g s; continuity: Q = Q_in = %g\n"
                 "RMS relative error = %.6g\n"
                 "unsteadiness (RMS velocity change since the snapshot before, over Q_in/S) = "
                 "%.3g\n"
                 "reattachment length behind the step = %.4g m = %.3g S (S = %g m)",
                 last.time, s.rate, *error, unsteady, reattach, reattach / s.height, s.height);
        const double *cols[4] = {xs, q, qin, rel};
        rc = mf_report_csv(path, comment, "x,Q,Q_in,relative_error", 4, cols, ns);
        printf("volumeFlux: unsteadiness %.3g, reattachment length %.4g m (%.3g S)\n", unsteady,
               reattach, reattach / s.height);
    }
    if (rc == 0) {
        snprintf(path, sizeof path, "%s/result.png", ctx->out_dir);
        char title[256];
        snprintf(title, sizeof title, "Flow rate through cross-sections (RMS error %.3g)", *error);
        mf_plot plot = {title, "x, m", "Q", false, false, NULL};
        mf_series series[2] = {{"mpsflow", xs, q, ns, "linespoints pt 7", NULL},
                               {"inflow Q_in", xs, qin, ns, "lines lw 2", NULL}};
        rc = mf_report_plot(path, &plot, series, 2);
    }
    free(q);
    free(qin);
    free(rel);
    free(xs);
    mf_particles_destroy(last.p);
    mf_particles_destroy(before.p);
    return rc;
}

const mf_metric_ops mf_metric_volume_flux = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "volumeFlux",
     "flow rate through cross-sections of a channel against the inflow",
     flux_params, sizeof flux_params / sizeof flux_params[0], sizeof(flux_settings)},
    flux_evaluate,
    flux_extra,
};
