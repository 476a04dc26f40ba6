/* metric_sloshing.c: the free sloshing of a liquid in a rectangular tank
 * (tutorials/sloshingTank) against the linear sloshing frequency.
 *
 * A tank of width L (along x) filled to depth h; its first (antisymmetric)
 * mode has, by linear potential theory (Lamb, Hydrodynamics, art. 257;
 * Faltinsen & Timokha, Sloshing, 2009, eq. 4.8 with m = 1),
 *   omega_1^2 = g k tanh(k h),  k = pi / L,  T_1 = 2 pi / omega_1.
 * The signal is the horizontal offset of the liquid's centroid from the
 * tank's (the mean x of the fluid particles less the mean x of the wall and
 * dummy particles, which move with the tank), q(t), after startTime (when
 * the excitation has stopped); its period comes from the zero crossings of
 * q - mean(q). error = |T - T_1| / T_1. The CSV has (t, q); the PNG plots it. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_post.h"
#include "mf_report.h"

typedef struct sloshing_settings {
    const char *metric;
    double width, depth, g, start;
} sloshing_settings;

static const mf_param sloshing_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(sloshing_settings, metric),
     "sloshingPeriod"},
    {"width", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(sloshing_settings, width),
     "L, the tank's inner width along x, m"},
    {"depth", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(sloshing_settings, depth),
     "h, the depth of the liquid at rest, m"},
    {"gravity", MF_PARAM_SCALAR, "9.81", 1e-9, 1e9, NULL, offsetof(sloshing_settings, g),
     "g, m/s^2"},
    {"startTime", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(sloshing_settings, start),
     "ignore the snapshots before this time (the excitation), s"},
};
#define NSP (sizeof sloshing_params / sizeof sloshing_params[0])

/* q of one snapshot: the fluid's centroid x less the tank's. */
static int offset_of(const char *path, double *t, double *q)
{
    mf_sim snap;
    memset(&snap, 0, sizeof snap);
    MF_CALL(mf_hdf5_read_snapshot(path, &snap));
    const mf_particles *p = snap.p;
    double xf = 0, xw = 0;
    size_t nf = 0, nw = 0;
    for (size_t i = 0; i < p->n; i++) {
        if (p->kind[i] == MF_FLUID) {
            xf += p->pos[3 * i];
            nf++;
        } else {
            xw += p->pos[3 * i];
            nw++;
        }
    }
    *t = snap.time;
    mf_particles_destroy(snap.p);
    if (nf == 0 || nw == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: %s: the sloshing metric needs fluid and wall "
                        "particles", path, nf == 0 ? "no fluid particle" : "no wall particle");
    *q = xf / (double)nf - xw / (double)nw;
    return 0;
}

static int evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    sloshing_settings s = *(const sloshing_settings *)settings;
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    double *t = malloc(nsnap * sizeof *t), *q = malloc(nsnap * sizeof *q);
    double *cross = malloc(nsnap * sizeof *cross);
    int rc = t && q && cross ? 0 : MF_ERROR(MF_ERR_MEMORY, "out of memory");
    size_t n = 0;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        char path[4400];
        mf_snapshot_path(ctx->case_dir, idx[k], path, sizeof path);
        rc = offset_of(path, &t[n], &q[n]);
        if (rc == 0 && t[n] >= s.start)
            n++;
    }
    free(idx);
    double mean = 0;
    for (size_t k = 0; k < n; k++)
        mean += q[k] / (double)n;
    double *dq = rc == 0 ? malloc((n ? n : 1) * sizeof *dq) : NULL;
    if (rc == 0 && !dq)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    for (size_t k = 0; rc == 0 && k < n; k++)
        dq[k] = q[k] - mean;
    const double kw = M_PI / s.width;
    const double period_ref = 2 * M_PI / sqrt(s.g * kw * tanh(kw * s.depth));
    size_t nc = 0;
    const double period = rc == 0 ? mf_crossing_period(t, dq, n, cross, &nc) : NAN;
    if (rc == 0 && !isfinite(period))
        rc = MF_ERROR(MF_ERR_INPUT, "%s: fewer than two zero crossings of the centroid's offset "
                      "in %zu snapshots after startTime %g s: run longer (T_1 = %g s)",
                      ctx->case_dir, n, s.start, period_ref);
    if (rc == 0) {
        *error = fabs(period - period_ref) / period_ref;
        char path[4400], comment[1024];
        snprintf(path, sizeof path, "%s/result.csv", ctx->out_dir);
        snprintf(comment, sizeof comment,
                 "free sloshing, mode 1: L = %g m, h = %g m, g = %g m/s^2\n"
                 "linear theory omega^2 = g k tanh(k h), k = pi/L: T_1 = %.6g s\n"
                 "q = centroid x of the fluid less the tank's, after t = %g s: %zu zero "
                 "crossings, period %.6g s, relative error %.6g",
                 s.width, s.depth, s.g, period_ref, s.start, nc, period, *error);
        const double *const cols[2] = {t, q};
        rc = mf_report_csv(path, comment, "t,q", 2, cols, n);
        if (rc == 0) {
            snprintf(path, sizeof path, "%s/result.png", ctx->out_dir);
            char title[256];
            snprintf(title, sizeof title, "Sloshing: period %.4g s against linear %.4g s "
                     "(error %.3g)", period, period_ref, *error);
            mf_plot plot = {title, "t, s", "centroid offset q, m", false, false, NULL};
            mf_series series[1] = {{"mpsflow", t, q, n, "linespoints", NULL}};
            rc = mf_report_plot(path, &plot, series, 1);
        }
    }
    free(t);
    free(q);
    free(dq);
    free(cross);
    return rc;
}

const mf_metric_ops mf_metric_sloshing = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "sloshingPeriod",
     "period of free sloshing in a rectangular tank against the linear mode-1 period",
     sloshing_params, NSP, sizeof(sloshing_settings)},
    evaluate,
    NULL,
};
