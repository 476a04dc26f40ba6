/* metric_poiseuille.c: start-up of the flow between two plates driven by a
 * body force F along x (tutorials/poiseuille2D, periodic in x).
 *
 * Morris, Fox & Zhu (1997), J. Comput. Phys. 136, 214-226, eq. 21, with the
 * sign written so that F > 0 drives u > 0 (the series is the sine series of
 * the steady profile, so u = 0 at t = 0):
 *   u(y, t) = F/(2 nu) y (L - y)
 *           - sum_{n>=0} 4 F L^2 / (nu pi^3 (2n+1)^3) sin(pi y (2n+1)/L)
 *                          exp(-(2n+1)^2 pi^2 nu t / L^2),
 * y measured from the lower plate (the wall's surface, halfway between the
 * first fluid and the first wall particle layer). For the newest snapshot
 * (time t): error = RMS over the fluid particles of (u_x - u(y, t)) /
 * u(L/2, t). The CSV lists every fluid particle (y, u_x, u) by y; the PNG
 * plots the profile against the analytic one.
 *
 * The same file holds metric couette (tutorials/couette2D): the start-up of
 * the flow between a fixed plate at y = 0 and a lid at y = L sliding at U,
 * the fluid at rest at t = 0 (Morris, Fox & Zhu 1997, eq. 22):
 *   u(y, t) = U y / L + sum_{n>=1} 2 U (-1)^n / (n pi) sin(n pi y / L)
 *                          exp(-n^2 pi^2 nu t / L^2),
 * error = RMS over the fluid particles of (u_x - u(y, t)) / U. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_post.h"
#include "mf_report.h"

typedef struct poiseuille_settings {
    const char *metric;
    double force, nu, gap, bottom;
    double lid; /* couette: the lid's speed U (force unused) */
} poiseuille_settings;

static const mf_param poiseuille_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(poiseuille_settings, metric),
     "poiseuille"},
    {"bodyForce", MF_PARAM_SCALAR, NULL, -1e9, 1e9, NULL, offsetof(poiseuille_settings, force),
     "the driving body force F along x, m/s^2"},
    {"nu", MF_PARAM_SCALAR, NULL, 1e-12, 1e9, NULL, offsetof(poiseuille_settings, nu),
     "kinematic viscosity, m^2/s"},
    {"gap", MF_PARAM_SCALAR, NULL, 1e-12, 1e9, NULL, offsetof(poiseuille_settings, gap),
     "distance L between the plates, m"},
    {"bottom", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL, offsetof(poiseuille_settings, bottom),
     "y of the lower plate, m"},
};

static const mf_param couette_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(poiseuille_settings, metric),
     "couette"},
    {"lidVelocity", MF_PARAM_SCALAR, NULL, -1e9, 1e9, NULL, offsetof(poiseuille_settings, lid),
     "the speed U of the upper plate along x, m/s"},
    {"nu", MF_PARAM_SCALAR, NULL, 1e-12, 1e9, NULL, offsetof(poiseuille_settings, nu),
     "kinematic viscosity, m^2/s"},
    {"gap", MF_PARAM_SCALAR, NULL, 1e-12, 1e9, NULL, offsetof(poiseuille_settings, gap),
     "distance L between the plates, m"},
    {"bottom", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL, offsetof(poiseuille_settings, bottom),
     "y of the lower (fixed) plate, m"},
};

/* The analytic velocity at height y above the lower plate, time t. */
static double poiseuille_u(const poiseuille_settings *s, double y, double t)
{
    const double F = s->force, nu = s->nu, L = s->gap;
    double u = F / (2.0 * nu) * y * (L - y);
    for (int n = 0; n < 200; n++) {
        const double k = 2.0 * n + 1.0;
        const double decay = exp(-k * k * M_PI * M_PI * nu * t / (L * L));
        const double term = 4.0 * F * L * L / (nu * M_PI * M_PI * M_PI * k * k * k) *
                            sin(M_PI * y * k / L) * decay;
        u -= term;
        if (fabs(term) < 1e-17 * fabs(F * L * L / nu) && n > 3)
            break;
    }
    return u;
}

/* Couette start-up (Morris et al. 1997, eq. 22). */
static double couette_u(const poiseuille_settings *s, double y, double t)
{
    const double U = s->lid, nu = s->nu, L = s->gap;
    double u = U * y / L;
    for (int n = 1; n <= 400; n++) {
        const double decay = exp(-n * n * M_PI * M_PI * nu * t / (L * L));
        const double term = 2.0 * U * (n % 2 ? -1.0 : 1.0) / (n * M_PI) * sin(n * M_PI * y / L) *
                            decay;
        u += term;
        if (decay < 1e-17 && n > 3)
            break;
    }
    return u;
}

typedef struct channel_flow {
    const char *name;             /* for the report */
    const char *reference;        /* the analytic solution's source */
    double (*u)(const poiseuille_settings *s, double y, double t);
    double (*scale)(const poiseuille_settings *s, double t); /* the error's denominator */
} channel_flow;

static double poiseuille_scale(const poiseuille_settings *s, double t)
{
    return poiseuille_u(s, 0.5 * s->gap, t);
}
static double couette_scale(const poiseuille_settings *s, double t)
{
    (void)t;
    return s->lid;
}

static const channel_flow poiseuille_flow = {
    "Poiseuille", "Morris et al. (1997) eq. 21", poiseuille_u, poiseuille_scale};
static const channel_flow couette_flow = {
    "Couette", "Morris et al. (1997) eq. 22", couette_u, couette_scale};

typedef struct sample {
    double y, u, exact;
} sample;

static int by_y(const void *a, const void *b)
{
    const sample *p = a, *q = b;
    return (p->y > q->y) - (p->y < q->y);
}

static int write_report(const char *out_dir, const channel_flow *flow,
                        const poiseuille_settings *s, const sample *pts, size_t n, double t,
                        double error, double umax)
{
    double *col[3];
    for (int c = 0; c < 3; c++) {
        col[c] = malloc((n ? n : 1) * sizeof *col[c]);
        if (!col[c]) {
            for (int k = 0; k < c; k++)
                free(col[k]);
            return MF_ERROR(MF_ERR_MEMORY, "out of memory");
        }
    }
    for (size_t i = 0; i < n; i++) {
        col[0][i] = pts[i].y;
        col[1][i] = pts[i].u;
        col[2][i] = pts[i].exact;
    }
    char path[4400], comment[1024];
    snprintf(path, sizeof path, "%s/result.csv", out_dir);
    if (flow == &couette_flow)
        snprintf(comment, sizeof comment,
                 "Couette start-up: U = %g m/s, nu = %g m^2/s, L = %g m, time %g s, %zu fluid "
                 "particles\nexact: %s\nRMS of (u - u_exact)/U = %.6g",
                 s->lid, s->nu, s->gap, t, n, flow->reference, error);
    else
        snprintf(comment, sizeof comment,
                 "Poiseuille start-up: F = %g m/s^2, nu = %g m^2/s, L = %g m, time %g s, %zu "
                 "fluid particles\nexact: %s; centre-line speed %g m/s\n"
                 "RMS of (u - u_exact)/u_centre = %.6g",
                 s->force, s->nu, s->gap, t, n, flow->reference, umax, error);
    const double *const cols[3] = {col[0], col[1], col[2]};
    int rc = mf_report_csv(path, comment, "y,u,u_exact", 3, cols, n);
    if (rc == 0) {
        snprintf(path, sizeof path, "%s/result.png", out_dir);
        char title[256];
        snprintf(title, sizeof title, "%s start-up at t = %g s (relative RMS error %.3g)",
                 flow->name, t, error);
        mf_plot plot = {title, "y, m", "u_x, m/s", false, false, NULL};
        mf_series series[2] = {{"mpsflow", col[0], col[1], n, "points pt 7 ps 0.5", NULL},
                               {flow->reference, col[0], col[2], n, "lines lw 2", NULL}};
        rc = mf_report_plot(path, &plot, series, 2);
    }
    for (int c = 0; c < 3; c++)
        free(col[c]);
    return rc;
}

static int evaluate_flow(const channel_flow *flow, const void *settings,
                         const mf_metric_ctx *ctx, double *error)
{
    const char *case_dir = ctx->case_dir;
    poiseuille_settings s = *(const poiseuille_settings *)settings;
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
    const double t = snap.time;
    const double umax = flow->scale(&s, t);
    int rc = 0;
    if (!(fabs(umax) > 0))
        rc = MF_ERROR(MF_ERR_INPUT,
                      "%s: the analytic speed scale is 0 at t = %g s (bodyForce or lidVelocity "
                      "0, or the initial snapshot): nothing to compare",
                      path, t);
    sample *pts = rc == 0 ? malloc((p->n ? p->n : 1) * sizeof *pts) : NULL;
    if (rc == 0 && !pts)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    size_t n = 0;
    double sum = 0;
    for (size_t i = 0; rc == 0 && i < p->n; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        sample *q = &pts[n++];
        q->y = p->pos[3 * i + 1] - s.bottom;
        q->u = p->vel[3 * i];
        q->exact = flow->u(&s, q->y, t);
        const double e = (q->u - q->exact) / umax;
        sum += e * e;
    }
    if (rc == 0 && n == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no fluid particle", path);
    if (rc == 0) {
        *error = sqrt(sum / (double)n);
        if (!isfinite(*error))
            rc = MF_ERROR(MF_ERR_NUMERIC, "%s: the velocity holds NaN or Inf", path);
    }
    if (rc == 0) {
        qsort(pts, n, sizeof *pts, by_y);
        rc = write_report(ctx->out_dir, flow, &s, pts, n, t, *error, umax);
    }
    free(pts);
    mf_particles_destroy(snap.p);
    return rc;
}

static int evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    return evaluate_flow(&poiseuille_flow, settings, ctx, error);
}

static int evaluate_couette(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    return evaluate_flow(&couette_flow, settings, ctx, error);
}

const mf_metric_ops mf_metric_couette = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "couette",
     "start-up of plane Couette flow (a sliding lid) against Morris et al. (1997) eq. 22 "
    "(RMS of u over the lid speed)",
     couette_params, sizeof couette_params / sizeof couette_params[0], sizeof(poiseuille_settings)},
    evaluate_couette,
    NULL,
};

const mf_metric_ops mf_metric_poiseuille = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "poiseuille",
     "start-up of plane Poiseuille flow against Morris et al. (1997) eq. 21 (relative RMS of u)",
     poiseuille_params, sizeof poiseuille_params / sizeof poiseuille_params[0], sizeof(poiseuille_settings)},
    evaluate,
    NULL,
};
