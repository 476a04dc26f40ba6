/* metric_floating.c: a floating body's equilibrium draft (tutorials/
 * floatingBox) against Archimedes, and its heave period against the linear
 * estimate.
 *
 * A 2-D box of height H and width B and density ratio s = rho_b / rho floats
 * with draft d = s H (Archimedes). The body's centre y_c(t) comes from
 * postProcessing/<body>/bodyState.csv; the water level from each snapshot
 * after startTime: the top fluid particle of each column (bins l0 wide)
 * farther than `clearance` from the body's centre along x, plus l0/2,
 * averaged over the columns. The draft of a snapshot is level - (y_c - H/2)
 * (the box upright); error = |mean draft - s H| / (s H).
 *
 * Heave: the period T of y_c - mean(y_c) after startTime from its zero
 * crossings, against the linear estimate of a spring rho g B and a mass
 * m + a_33: T_0 = 2 pi sqrt(m / (rho g B)) without added mass, and T_a with
 * the high-frequency added mass of a floating flat-bottomed section,
 * a_33 = rho pi B^2 / 8 (half the double body's, a plate of width B in
 * unbounded fluid: Newman, Marine Hydrodynamics, 1977, section 4.13). Both
 * are written in result.csv's comment, with T. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_post.h"
#include "mf_report.h"

typedef struct floating_settings {
    const char *metric, *body;
    double height, width, ratio, rho, g, start, clearance;
} floating_settings;

static const mf_param floating_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(floating_settings, metric),
     "floatingDraft"},
    {"body", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(floating_settings, body),
     "the obstacle's name (postProcessing/<body>/bodyState.csv)"},
    {"height", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(floating_settings, height),
     "H, the box's height, m"},
    {"width", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(floating_settings, width),
     "B, the box's width, m (for the heave period)"},
    {"densityRatio", MF_PARAM_SCALAR, NULL, 1e-6, 1, NULL, offsetof(floating_settings, ratio),
     "rho_body / rho_water: the draft is densityRatio H"},
    {"rho", MF_PARAM_SCALAR, "1000", 1e-9, 1e9, NULL, offsetof(floating_settings, rho),
     "the water's density, kg/m^3"},
    {"gravity", MF_PARAM_SCALAR, "9.81", 1e-9, 1e9, NULL, offsetof(floating_settings, g),
     "g, m/s^2"},
    {"startTime", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(floating_settings, start),
     "average the draft and take the period after this time, s"},
    {"clearance", MF_PARAM_SCALAR, NULL, 0, 1e9, NULL, offsetof(floating_settings, clearance),
     "the water level from the columns farther than this from the body's centre along x, m"},
};
#define NFP (sizeof floating_params / sizeof floating_params[0])

/* Columns (time, x, y) of bodyState.csv. */
static int read_track(const char *path, double **t, double **x, double **y, size_t *n)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return MF_ERROR(MF_ERR_IO, "cannot read %s (the body's trajectory): run the case first",
                        path);
    size_t cap = 0;
    *n = 0;
    *t = *x = *y = NULL;
    char line[2048];
    int rc = 0;
    while (rc == 0 && fgets(line, sizeof line, f)) {
        double a, b, c;
        if (line[0] == '#' || sscanf(line, "%lf,%lf,%lf", &a, &b, &c) != 3)
            continue;
        if (*n == cap) {
            const size_t grown = cap ? 2 * cap : 1024;
            if ((rc = mf_resize(t, grown, sizeof **t)) != 0 ||
                (rc = mf_resize(x, grown, sizeof **x)) != 0 ||
                (rc = mf_resize(y, grown, sizeof **y)) != 0)
                break;
            cap = grown;
        }
        (*t)[*n] = a;
        (*x)[*n] = b;
        (*y)[*n] = c;
        (*n)++;
    }
    fclose(f);
    if (rc == 0 && *n < 2)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: fewer than two rows", path);
    return rc;
}

/* The water level of one snapshot away from the body (x_c its centre). */
static int level_of(const char *path, double x_c, double clearance, double *t, double *level)
{
    mf_sim snap;
    memset(&snap, 0, sizeof snap);
    MF_CALL(mf_hdf5_read_snapshot(path, &snap));
    const mf_particles *p = snap.p;
    const double l0 = snap.l0;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < p->n; i++)
        if (p->kind[i] == MF_FLUID) {
            lo = fmin(lo, p->pos[3 * i]);
            hi = fmax(hi, p->pos[3 * i]);
        }
    const size_t nb = isfinite(lo) ? (size_t)((hi - lo) / l0) + 1 : 0;
    double *top = malloc((nb ? nb : 1) * sizeof *top);
    if (!top) {
        mf_particles_destroy(snap.p);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    }
    for (size_t b = 0; b < nb; b++)
        top[b] = -INFINITY;
    for (size_t i = 0; i < p->n; i++) {
        const double *x = &p->pos[3 * i];
        if (p->kind[i] != MF_FLUID || fabs(x[0] - x_c) <= clearance)
            continue;
        size_t b = (size_t)((x[0] - lo) / l0);
        if (b < nb)
            top[b] = fmax(top[b], x[1]);
    }
    double sum = 0;
    size_t count = 0;
    for (size_t b = 0; b < nb; b++)
        if (isfinite(top[b])) {
            sum += top[b] + 0.5 * l0;
            count++;
        }
    *t = snap.time;
    free(top);
    mf_particles_destroy(snap.p);
    if (count == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: no fluid farther than clearance %g m from the body",
                        path, clearance);
    *level = sum / (double)count;
    return 0;
}

static int evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    floating_settings s = *(const floating_settings *)settings;
    char path[4400];
    snprintf(path, sizeof path, "%s/postProcessing/%s/bodyState.csv", ctx->case_dir, s.body);
    double *tt = NULL, *xc = NULL, *yc = NULL;
    size_t nt = 0;
    MF_CALL(read_track(path, &tt, &xc, &yc, &nt));
    int *idx = NULL;
    size_t nsnap = 0;
    int rc = mf_metric_snapshots(ctx, &idx, &nsnap);
    double *ts = rc == 0 ? malloc((nsnap ? nsnap : 1) * sizeof *ts) : NULL;
    double *draft = rc == 0 ? malloc((nsnap ? nsnap : 1) * sizeof *draft) : NULL;
    double *dy = rc == 0 ? malloc(nt * sizeof *dy) : NULL;
    double *cross = rc == 0 ? malloc(nt * sizeof *cross) : NULL;
    if (rc == 0 && !(ts && draft && dy && cross))
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    size_t n = 0;
    double mean_draft = 0;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        mf_snapshot_path(ctx->case_dir, idx[k], path, sizeof path);
        double t = NAN, level = NAN;
        const double x_now = xc[nt - 1];
        rc = level_of(path, x_now, s.clearance, &t, &level);
        if (rc != 0 || t < s.start)
            continue;
        const double y = mf_interp(tt, yc, nt, t);
        if (!isfinite(y))
            continue;
        ts[n] = t;
        draft[n] = level - (y - 0.5 * s.height);
        mean_draft += draft[n];
        n++;
    }
    if (rc == 0 && n == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no snapshot after startTime %g s", ctx->case_dir,
                      s.start);
    const double ref = s.ratio * s.height;
    double period = NAN;
    size_t nc = 0, ny = 0;
    if (rc == 0) {
        mean_draft /= (double)n;
        *error = fabs(mean_draft - ref) / ref;
        double mean_y = 0;
        for (size_t k = 0; k < nt; k++)
            if (tt[k] >= s.start) {
                mean_y += yc[k];
                ny++;
            }
        mean_y /= (double)(ny ? ny : 1);
        size_t m = 0;
        for (size_t k = 0; k < nt; k++)
            if (tt[k] >= s.start) {
                tt[m] = tt[k];
                dy[m++] = yc[k] - mean_y;
            }
        period = mf_crossing_period(tt, dy, m, cross, &nc);
        ny = m;
    }
    if (rc == 0) {
        const double mass = s.ratio * s.rho * s.width * s.height;
        const double spring = s.rho * s.g * s.width;
        const double a33 = s.rho * M_PI * s.width * s.width / 8;
        const double T0 = 2 * M_PI * sqrt(mass / spring), Ta = 2 * M_PI * sqrt((mass + a33) / spring);
        char comment[1400];
        snprintf(comment, sizeof comment,
                 "floating box '%s': H = %g m, B = %g m, rho_b/rho = %g: Archimedes' draft %.6g m\n"
                 "mean draft after t = %g s over %zu snapshots: %.6g m, relative error %.6g\n"
                 "heave: period %.6g s from %zu zero crossings of y_c - mean after t = %g s; "
                 "linear estimate T_0 = 2 pi sqrt(m/(rho g B)) = %.6g s (no added mass), "
                 "T_a = %.6g s with a_33 = rho pi B^2/8; T/T_0 = %.4g, T/T_a = %.4g",
                 s.body, s.height, s.width, s.ratio, ref, s.start, n, mean_draft, *error,
                 period, nc, s.start, T0, Ta, period / T0, period / Ta);
        snprintf(path, sizeof path, "%s/result.csv", ctx->out_dir);
        const double *const cols[2] = {ts, draft};
        rc = mf_report_csv(path, comment, "t,draft", 2, cols, n);
        if (rc == 0) {
            snprintf(path, sizeof path, "%s/result.png", ctx->out_dir);
            char title[256];
            snprintf(title, sizeof title, "Floating box: draft %.4g m against %.4g m (error %.3g)",
                     mean_draft, ref, *error);
            mf_plot plot = {title, "t, s", "draft, m", false, false, NULL};
            mf_series series[1] = {{"mpsflow", ts, draft, n, "linespoints", NULL}};
            rc = mf_report_plot(path, &plot, series, 1);
        }
    }
    (void)ny;
    free(idx);
    free(ts);
    free(draft);
    free(dy);
    free(cross);
    free(tt);
    free(xc);
    free(yc);
    return rc;
}

const mf_metric_ops mf_metric_floating = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "floatingDraft",
     "a floating box's mean draft against Archimedes (its heave period against the linear "
     "estimate in the report)",
     floating_params, NFP, sizeof(floating_settings)},
    evaluate,
    NULL,
};
