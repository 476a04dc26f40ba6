/* metric_droplet.c: the metrics of a single drop (multi-fluid cases).
 *
 *   laplacePressure    a droplet at rest (surface tension, no gravity):
 *                      dp = p_in - p_out against sigma/R (2-D) or 2 sigma/R
 *                      (3-D), time-averaged after settleTime; the CSV also
 *                      follows the roundness of the drop (a square relaxes
 *                      to a circle of radius s / sqrt(pi)).
 *   oscillationPeriod  a drop oscillating in mode 2: the period of the
 *                      quadrupole moment Q = <(x-xc)^2 - (y-yc)^2> (from its
 *                      zero crossings; the x and y extents too) against
 *                      Rayleigh's, omega^2 = 6 sigma/(rho R^3) (2-D) or
 *                      8 sigma/(rho R^3) (3-D).
 *
 * Sources of the reference answers: Laplace (1806); Rayleigh (1879), Lamb,
 * Hydrodynamics, art. 275. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_snapshots.h"
#include "mf_error.h"
#include "mf_post.h"

/* ---- laplacePressure -------------------------------------------------------- */

typedef struct laplace_settings {
    const char *metric, *drop;
    double sigma, radius, side, settle, margin, inner;
} laplace_settings;

static const mf_param laplace_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(laplace_settings, metric),
     "laplacePressure"},
    {"dropFluid", MF_PARAM_WORD, "", MF_NO_RANGE, NULL, offsetof(laplace_settings, drop),
     "the drop's fluid (empty: every fluid particle)"},
    {"sigma", MF_PARAM_SCALAR, NULL, 0, 1e6, NULL, offsetof(laplace_settings, sigma),
     "surface tension of the drop's interface, N/m"},
    {"radius", MF_PARAM_SCALAR, "0", 0, 1e6, NULL, offsetof(laplace_settings, radius),
     "R of the drop, m (or give squareSide)"},
    {"squareSide", MF_PARAM_SCALAR, "0", 0, 1e6, NULL, offsetof(laplace_settings, side),
     "side s of a square (2-D) drop: R = s / sqrt(pi), s^2 the area its particles fill "
     "(N l0^2 at the first snapshot: s itself when l0 divides it)"},
    {"settleTime", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(laplace_settings, settle),
     "average dp over the snapshots after this time, s"},
    {"margin", MF_PARAM_SCALAR, "5", 0, 100, NULL, offsetof(laplace_settings, margin),
     "p_out over R + margin l0 < r < R + 2 margin l0 (another fluid around the drop)"},
    {"innerRadius", MF_PARAM_SCALAR, "0.5", 0.01, 1, NULL, offsetof(laplace_settings, inner),
     "p_in over r < innerRadius R (the drop's core, away from the interface band)"},
};

/* Roundness: the drop's outer radius in 36 angular sectors (2-D: angle in
 * the x-y plane); std / mean. A square gives about 0.12, a circle ~0.02.
 * Particles farther than 1.5 R from the centroid (shed droplets) are left
 * out. */
static double roundness(const mf_fsnap *s, int fluid, const double c[3], double R)
{
    enum { NSEC = 36 };
    double rmax[NSEC] = {0};
    const mf_particles *p = s->sim.p;
    for (size_t i = 0; i < p->n; i++) {
        if (!mf_fsnap_is_of(s, i, fluid))
            continue;
        double dx = p->pos[3 * i] - c[0], dy = p->pos[3 * i + 1] - c[1];
        int k = (int)floor((atan2(dy, dx) + M_PI) / (2 * M_PI) * NSEC) % NSEC;
        double r = hypot(dx, dy);
        if (r < 1.5 * R && r > rmax[k])
            rmax[k] = r;
    }
    double m = 0, v = 0;
    for (int k = 0; k < NSEC; k++)
        m += rmax[k] / NSEC;
    for (int k = 0; k < NSEC; k++)
        v += (rmax[k] - m) * (rmax[k] - m) / NSEC;
    return m > 0 ? sqrt(v) / m : 0;
}

static int laplace_evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    const char *case_dir = ctx->case_dir;
    laplace_settings s = *(const laplace_settings *)settings;
    double R = s.radius > 0 ? s.radius : s.side / sqrt(M_PI);
    if (!(R > 0))
        return MF_ERROR(MF_ERR_INPUT, "%s/validation/metric: give radius or squareSide",
                        case_dir);
    int drop = -1;
    if (s.drop[0])
        MF_CALL(mf_post_fluid_index(case_dir, s.drop, &drop));
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    double rho[MF_MAX_FLUIDS] = {0};
    MF_CALL(mf_post_fluid_densities(case_dir, rho));
    mf_table t = {.ncols = 6};
    int rc = 0, dim = 2;
    double sum = 0, sum_force = 0, l0 = 0;
    size_t used = 0;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        mf_fsnap sn;
        rc = mf_fsnap_load(case_dir, idx[k], &sn);
        if (rc != 0)
            break;
        dim = sn.h.dim;
        l0 = sn.h.l0;
        const mf_particles *p = sn.sim.p;
        double c[3];
        size_t count = 0;
        mf_fsnap_centroid(&sn, drop, c, &count);
        if (k == 0 && !(s.radius > 0) && dim == 2 && count > 0)
            R = sqrt((double)count * l0 * l0 / M_PI); /* the square the lattice filled */
        double pin = 0, pout = 0;
        size_t nin = 0, nout = 0;
        const double m = s.margin * l0;
        for (size_t i = 0; sn.p && i < p->n; i++) {
            if (p->kind[i] != MF_FLUID)
                continue;
            double r = 0;
            for (int a = 0; a < dim; a++)
                r += (p->pos[3 * i + a] - c[a]) * (p->pos[3 * i + a] - c[a]);
            r = sqrt(r);
            if (mf_fsnap_is_of(&sn, i, drop) && r < s.inner * R) {
                pin += sn.p[i];
                nin++;
            } else if (!mf_fsnap_is_of(&sn, i, drop) && r > R + m && r < R + 2 * m) {
                pout += sn.p[i];
                nout++;
            }
        }
        pin = nin ? pin / (double)nin : 0;
        pout = nout ? pout / (double)nout : 0; /* a free drop: p = 0 outside */
        /* The jump the surface-tension force makes: its normal component per
         * unit volume integrated across the interface (SurfaceTension field). */
        int fa = mf_particles_field_index(p, "SurfaceTension");
        double jump = 0;
        for (size_t i = 0; fa >= 0 && i < p->n; i++) {
            if (p->kind[i] != MF_FLUID)
                continue;
            const double *a = &mf_particles_fd(p, fa)[3 * i];
            double r[3] = {0, 0, 0}, len = 0, an = 0;
            for (int q = 0; q < dim; q++) {
                r[q] = p->pos[3 * i + q] - c[q];
                len += r[q] * r[q];
            }
            len = sqrt(len);
            for (int q = 0; len > 0 && q < dim; q++)
                an -= a[q] * r[q] / len;
            jump += rho[sn.fid ? sn.fid[i] : 0] * an * pow(l0, dim);
        }
        jump /= dim == 3 ? 4 * M_PI * R * R : 2 * M_PI * R;
        double row[6] = {sn.h.time, pin - pout, pin, pout, roundness(&sn, drop, c, R), jump};
        rc = mf_table_add(&t, row);
        if (rc == 0 && sn.h.time >= s.settle && nin > 0) {
            sum += pin - pout;
            sum_force += jump;
            used++;
        }
        mf_fsnap_free(&sn);
    }
    free(idx);
    const double laplace = (dim == 3 ? 2 : 1) * s.sigma / R;
    if (rc == 0 && used == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no snapshot after settleTime %g with particles inside "
                      "innerRadius R", case_dir, s.settle);
    if (rc == 0) {
        double dp = sum / (double)used, dpf = sum_force / (double)used;
        *error = fabs(dp - laplace) / laplace;
        char comment[1024], title[256];
        snprintf(comment, sizeof comment,
                 "Laplace pressure of a drop: dp = p_in - p_out against %s sigma / R = %.6g Pa "
                 "(sigma = %g N/m, R = %g m)\np_in: mean over the drop within %g R of its "
                 "centroid; p_out: other fluid between R + %g l0 and R + %g l0 (0 if none)\n"
                 "mean dp over %zu snapshots after t = %g s: %.6g Pa; relative error %.6g\n"
                 "roundness: std/mean of the outer radius in 36 sectors (square ~0.12)\n"
                 "dp_force: the surface-tension force per unit volume integrated across the "
                 "interface; mean %.6g Pa, relative error %.6g",
                 dim == 3 ? "2" : "", laplace, s.sigma, R, s.inner, s.margin, 2 * s.margin,
                 used, s.settle, dp, *error, dpf, fabs(dpf - laplace) / laplace);
        snprintf(title, sizeof title, "Droplet pressure jump (error %.3g)", *error);
        double tx[2] = {t.col[0][0], t.col[0][t.n - 1]}, ty[2] = {laplace, laplace};
        mf_plot plot = {title, "t, s", "p_in - p_out, Pa", false, false, NULL};
        mf_series series[3] = {{"p_in - p_out", t.col[0], t.col[1], t.n, "linespoints", NULL},
                               {"force across the interface", t.col[0], t.col[5], t.n, "lines",
                                NULL},
                               {"Laplace", tx, ty, 2, "lines lw 2", NULL}};
        rc = mf_table_report(ctx->out_dir, comment, "t,dp,p_in,p_out,roundness,dp_force", &t, &plot,
                          series, 3);
    }
    mf_table_free(&t);
    return rc;
}

const mf_metric_ops mf_metric_laplace = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "laplacePressure",
     "pressure jump of a droplet at rest against Laplace",
     laplace_params, sizeof laplace_params / sizeof laplace_params[0], sizeof(laplace_settings)},
    laplace_evaluate,
    NULL,
};

/* ---- oscillationPeriod ------------------------------------------------------ */

typedef struct osc_settings {
    const char *metric, *drop;
    double sigma, rho, radius, start;
} osc_settings;

static const mf_param osc_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(osc_settings, metric),
     "oscillationPeriod"},
    {"dropFluid", MF_PARAM_WORD, "", MF_NO_RANGE, NULL, offsetof(osc_settings, drop),
     "the drop's fluid (empty: every fluid particle)"},
    {"sigma", MF_PARAM_SCALAR, NULL, 0, 1e6, NULL, offsetof(osc_settings, sigma),
     "surface tension, N/m"},
    {"rho", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(osc_settings, rho),
     "density of the drop, kg/m^3"},
    {"radius", MF_PARAM_SCALAR, NULL, 1e-9, 1e6, NULL, offsetof(osc_settings, radius),
     "R, the radius of the drop at rest (of equal area or volume), m"},
    {"startTime", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(osc_settings, start),
     "ignore the snapshots before this time, s"},
};

static int osc_evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    const char *case_dir = ctx->case_dir;
    osc_settings s = *(const osc_settings *)settings;
    int drop = -1;
    if (s.drop[0])
        MF_CALL(mf_post_fluid_index(case_dir, s.drop, &drop));
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    mf_table t = {.ncols = 4};
    int rc = 0, dim = 2;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        mf_fsnap sn;
        rc = mf_fsnap_load(case_dir, idx[k], &sn);
        if (rc != 0)
            break;
        dim = sn.h.dim;
        double c[3];
        size_t count = 0;
        mf_fsnap_centroid(&sn, drop, c, &count);
        /* The drop's body: particles within 2 R of the centroid (a droplet
         * shed far away would dominate the second moment). */
        const mf_particles *p = sn.sim.p;
        double c2[3] = {0, 0, 0}, q = 0;
        size_t nb = 0;
        for (size_t i = 0; i < p->n; i++)
            if (mf_fsnap_is_of(&sn, i, drop) &&
                hypot(p->pos[3 * i] - c[0], p->pos[3 * i + 1] - c[1]) < 2 * s.radius) {
                c2[0] += p->pos[3 * i];
                c2[1] += p->pos[3 * i + 1];
                nb++;
            }
        for (int a = 0; nb && a < 2; a++)
            c2[a] /= (double)nb;
        double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
        for (size_t i = 0; i < p->n; i++)
            if (mf_fsnap_is_of(&sn, i, drop) &&
                hypot(p->pos[3 * i] - c[0], p->pos[3 * i + 1] - c[1]) < 2 * s.radius) {
                double dx = p->pos[3 * i] - c2[0], dy = p->pos[3 * i + 1] - c2[1];
                q += (dx * dx - dy * dy) / (double)nb;
                for (int a = 0; a < 2; a++) {
                    lo[a] = fmin(lo[a], p->pos[3 * i + a]);
                    hi[a] = fmax(hi[a], p->pos[3 * i + a]);
                }
            }
        double row[4] = {sn.h.time, q, hi[0] - lo[0], hi[1] - lo[1]};
        if (sn.h.time >= s.start)
            rc = mf_table_add(&t, row);
        mf_fsnap_free(&sn);
    }
    free(idx);
    const double omega = sqrt((dim == 3 ? 8.0 : 6.0) * s.sigma / (s.rho * pow(s.radius, 3)));
    const double period_ref = 2 * M_PI / omega;
    double *cross = t.n ? malloc(t.n * sizeof *cross) : NULL;
    double *dext = t.n ? malloc(t.n * sizeof *dext) : NULL;
    size_t nc = 0, ne = 0;
    double period = NAN, period_ext = NAN;
    if (cross && dext) {
        for (size_t k = 0; k < t.n; k++)
            dext[k] = t.col[2][k] - t.col[3][k];
        period_ext = mf_crossing_period(t.col[0], dext, t.n, cross, &ne);
        period = mf_crossing_period(t.col[0], t.col[1], t.n, cross, &nc);
    }
    if (rc == 0 && nc < 4)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: the quadrupole moment crosses zero %zu time(s): run "
                      "longer than two periods (Rayleigh: %.4g s)",
                      case_dir, nc, period_ref);
    if (rc == 0) {
        *error = fabs(period - period_ref) / period_ref;
        char comment[1024], title[256];
        snprintf(comment, sizeof comment,
                 "mode-2 oscillation of a drop: Q = <(x-xc)^2 - (y-yc)^2> over the drop; its "
                 "x and y extents\nperiod from %zu zero crossings of Q: %.6g s (from %zu of "
                 "x_extent - y_extent: %.6g s); Rayleigh (%d-D, omega^2 = %d sigma/(rho R^3), "
                 "sigma = %g, rho = %g, R = %g): %.6g s; relative error %.6g",
                 nc, period, ne, period_ext, dim, dim == 3 ? 8 : 6, s.sigma, s.rho, s.radius,
                 period_ref, *error);
        snprintf(title, sizeof title, "Droplet oscillation (period error %.3g)", *error);
        mf_plot plot = {title, "t, s", "Q, m^2", false, false, NULL};
        mf_series series[1] = {{"mpsflow", t.col[0], t.col[1], t.n, "linespoints", NULL}};
        rc = mf_table_report(ctx->out_dir, comment, "t,Q,x_extent,y_extent", &t, &plot, series, 1);
    }
    free(dext);
    free(cross);
    mf_table_free(&t);
    return rc;
}

const mf_metric_ops mf_metric_oscillation = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "oscillationPeriod",
     "mode-2 oscillation period of a drop against Rayleigh",
     osc_params, sizeof osc_params / sizeof osc_params[0], sizeof(osc_settings)},
    osc_evaluate,
    NULL,
};
