/* metric_droplet.c: the metrics of the multi-fluid cases.
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
 *   layering           two fluids settling: error = the fraction of light
 *                      particles below the interface height (the height the
 *                      heavy fluid would fill), time-averaged after
 *                      settleTime; the CSV has both mean heights.
 *   fluidSurgeFront    the dam-break front of one fluid among several (water
 *                      in air) against an experiment, as surgeFront.
 *   rayleighTaylor     the spike (lowest heavy particle) and bubble (highest
 *                      light particle) against time; error = the share of
 *                      the available potential energy not yet released at
 *                      the last snapshot (0: the fluids have swapped).
 *
 * Fluids are named as in constant/fluids (their order there is the FluidId);
 * with one fluid every fluid particle is the drop. Sources of the reference
 * answers: Laplace (1806); Rayleigh (1879), Lamb, Hydrodynamics, art. 275;
 * the Rayleigh-Taylor set-up of the PySPH examples (heavy 1.8 over light 1,
 * g = 1, interface y = 1 - 0.15 sin(2 pi x), Re = 420). */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_neighbours.h"
#include "mf_post.h"
#include "mf_report.h"
#include "mf_scene.h"

/* ---- shared helpers ------------------------------------------------------- */

/* Index of a fluid of the case by name (constant/fluids order). */
static int fluid_index(const char *case_dir, const char *name, int *index)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/constant/fluids", case_dir);
    mf_dict *d = NULL;
    MF_CALL(mf_dict_parse_file(path, &d));
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    int rc = mf_scene_read_fluids(d, &sim);
    if (rc == 0)
        rc = mf_scene_fluid_index(&sim, name, index);
    mf_dict_free(d);
    if (rc != 0)
        return MF_ERROR(rc, "%s/validation/metric: %s", case_dir, mf_error_message());
    return 0;
}

/* The densities of the case's fluids (constant/fluids order). */
static int fluid_densities(const char *case_dir, double rho[MF_MAX_FLUIDS])
{
    char path[4200];
    snprintf(path, sizeof path, "%s/constant/fluids", case_dir);
    mf_dict *d = NULL;
    MF_CALL(mf_dict_parse_file(path, &d));
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    int rc = mf_scene_read_fluids(d, &sim);
    for (int k = 0; rc == 0 && k < sim.nfluids; k++)
        rho[k] = sim.fluid[k].rho;
    mf_dict_free(d);
    return rc;
}

/* One snapshot: its particles (every stored field) and header. */
typedef struct snap {
    mf_sim sim;
    mf_hdf5_header h;
    const int32_t *fid;    /* NULL with one fluid */
    const double *p;       /* Pressure, or NULL */
} snap;

static int snap_load(const char *case_dir, int index, snap *s)
{
    char path[4400];
    memset(s, 0, sizeof *s);
    mf_snapshot_path(case_dir, index, path, sizeof path);
    MF_CALL(mf_hdf5_read_header(path, &s->h));
    MF_CALL(mf_hdf5_read_snapshot(path, &s->sim));
    int f = mf_particles_field_index(s->sim.p, "FluidId");
    s->fid = f >= 0 ? mf_particles_fi(s->sim.p, f) : NULL;
    f = mf_particles_field_index(s->sim.p, "Pressure");
    s->p = f >= 0 ? mf_particles_fd(s->sim.p, f) : NULL;
    return 0;
}

static void snap_free(snap *s) { mf_particles_destroy(s->sim.p); }

static inline bool is_of(const snap *s, size_t i, int fluid)
{
    return s->sim.p->kind[i] == MF_FLUID && (!s->fid || fluid < 0 || s->fid[i] == fluid);
}

/* Centroid of the particles of a fluid. */
static void centroid(const snap *s, int fluid, double c[3], size_t *count)
{
    const mf_particles *p = s->sim.p;
    c[0] = c[1] = c[2] = 0;
    *count = 0;
    for (size_t i = 0; i < p->n; i++)
        if (is_of(s, i, fluid)) {
            for (int a = 0; a < 3; a++)
                c[a] += p->pos[3 * i + a];
            (*count)++;
        }
    for (int a = 0; *count && a < 3; a++)
        c[a] /= (double)*count;
}

/* Growable columns for the CSV. */
typedef struct table {
    size_t n, cap, ncols;
    double *col[6];
} table;

static int table_add(table *t, const double *row)
{
    if (t->n == t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 64;
        for (size_t c = 0; c < t->ncols; c++) {
            double *g = realloc(t->col[c], cap * sizeof *g);
            if (!g)
                return MF_ERROR(MF_ERR_MEMORY, "out of memory");
            t->col[c] = g;
        }
        t->cap = cap;
    }
    for (size_t c = 0; c < t->ncols; c++)
        t->col[c][t->n] = row[c];
    t->n++;
    return 0;
}

static void table_free(table *t)
{
    for (size_t c = 0; c < t->ncols; c++)
        free(t->col[c]);
}

static int write_report(const char *out_dir, const char *comment, const char *header,
                        const table *t, const mf_plot *plot, const mf_series *series,
                        size_t nseries)
{
    char path[4400];
    snprintf(path, sizeof path, "%s/result.csv", out_dir);
    MF_CALL(mf_report_csv(path, comment, header, t->ncols, (const double *const *)t->col, t->n));
    snprintf(path, sizeof path, "%s/result.png", out_dir);
    MF_CALL(mf_report_plot(path, plot, series, nseries));
    return 0;
}

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
static const char *const metric_extra[] = {"FoamFile", NULL};

/* Roundness: the drop's outer radius in 36 angular sectors (2-D: angle in
 * the x-y plane); std / mean. A square gives about 0.12, a circle ~0.02.
 * Particles farther than 1.5 R from the centroid (shed droplets) are left
 * out. */
static double roundness(const snap *s, int fluid, const double c[3], double R)
{
    enum { NSEC = 36 };
    double rmax[NSEC] = {0};
    const mf_particles *p = s->sim.p;
    for (size_t i = 0; i < p->n; i++) {
        if (!is_of(s, i, fluid))
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

static int laplace_evaluate(const mf_metric_ctx *ctx, const mf_dict *md, double *error)
{
    const char *case_dir = ctx->case_dir;
    laplace_settings s;
    MF_CALL(mf_params_apply(laplace_params, 8, md, metric_extra, &s, NULL));
    double R = s.radius > 0 ? s.radius : s.side / sqrt(M_PI);
    if (!(R > 0))
        return MF_ERROR(MF_ERR_INPUT, "%s/validation/metric: give radius or squareSide",
                        case_dir);
    int drop = -1;
    if (s.drop[0])
        MF_CALL(fluid_index(case_dir, s.drop, &drop));
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    double rho[MF_MAX_FLUIDS] = {0};
    MF_CALL(fluid_densities(case_dir, rho));
    table t = {.ncols = 6};
    int rc = 0, dim = 2;
    double sum = 0, sum_force = 0, l0 = 0;
    size_t used = 0;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        snap sn;
        rc = snap_load(case_dir, idx[k], &sn);
        if (rc != 0)
            break;
        dim = sn.h.dim;
        l0 = sn.h.l0;
        const mf_particles *p = sn.sim.p;
        double c[3];
        size_t count = 0;
        centroid(&sn, drop, c, &count);
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
            if (is_of(&sn, i, drop) && r < s.inner * R) {
                pin += sn.p[i];
                nin++;
            } else if (!is_of(&sn, i, drop) && r > R + m && r < R + 2 * m) {
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
        rc = table_add(&t, row);
        if (rc == 0 && sn.h.time >= s.settle && nin > 0) {
            sum += pin - pout;
            sum_force += jump;
            used++;
        }
        snap_free(&sn);
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
        rc = write_report(ctx->out_dir, comment, "t,dp,p_in,p_out,roundness,dp_force", &t, &plot,
                          series, 3);
    }
    table_free(&t);
    return rc;
}

const mf_metric mf_metric_laplace = {"laplacePressure",
                                     "pressure jump of a droplet at rest against Laplace",
                                     laplace_evaluate,
    laplace_params, sizeof laplace_params / sizeof laplace_params[0]};

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

static int osc_evaluate(const mf_metric_ctx *ctx, const mf_dict *md, double *error)
{
    const char *case_dir = ctx->case_dir;
    osc_settings s;
    MF_CALL(mf_params_apply(osc_params, 6, md, metric_extra, &s, NULL));
    int drop = -1;
    if (s.drop[0])
        MF_CALL(fluid_index(case_dir, s.drop, &drop));
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    table t = {.ncols = 4};
    int rc = 0, dim = 2;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        snap sn;
        rc = snap_load(case_dir, idx[k], &sn);
        if (rc != 0)
            break;
        dim = sn.h.dim;
        double c[3];
        size_t count = 0;
        centroid(&sn, drop, c, &count);
        /* The drop's body: particles within 2 R of the centroid (a droplet
         * shed far away would dominate the second moment). */
        const mf_particles *p = sn.sim.p;
        double c2[3] = {0, 0, 0}, q = 0;
        size_t nb = 0;
        for (size_t i = 0; i < p->n; i++)
            if (is_of(&sn, i, drop) &&
                hypot(p->pos[3 * i] - c[0], p->pos[3 * i + 1] - c[1]) < 2 * s.radius) {
                c2[0] += p->pos[3 * i];
                c2[1] += p->pos[3 * i + 1];
                nb++;
            }
        for (int a = 0; nb && a < 2; a++)
            c2[a] /= (double)nb;
        double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
        for (size_t i = 0; i < p->n; i++)
            if (is_of(&sn, i, drop) &&
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
            rc = table_add(&t, row);
        snap_free(&sn);
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
        rc = write_report(ctx->out_dir, comment, "t,Q,x_extent,y_extent", &t, &plot, series, 1);
    }
    free(dext);
    free(cross);
    table_free(&t);
    return rc;
}

const mf_metric mf_metric_oscillation = {"oscillationPeriod",
                                         "mode-2 oscillation period of a drop against Rayleigh",
                                         osc_evaluate,
    osc_params, sizeof osc_params / sizeof osc_params[0]};

/* ---- layering ------------------------------------------------------------------ */

typedef struct layer_settings {
    const char *metric, *heavy, *light;
    double bottom, cross, settle;
} layer_settings;

static const mf_param layer_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(layer_settings, metric),
     "layering"},
    {"heavyFluid", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(layer_settings, heavy),
     "the denser fluid"},
    {"lightFluid", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(layer_settings, light),
     "the lighter fluid"},
    {"bottom", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL, offsetof(layer_settings, bottom),
     "height of the floor, m"},
    {"crossSection", MF_PARAM_SCALAR, NULL, 1e-12, 1e12, NULL,
     offsetof(layer_settings, cross), "width (2-D, m) or floor area (3-D, m^2) of the tank"},
    {"settleTime", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(layer_settings, settle),
     "average over the snapshots after this time, s"},
};

static int layer_evaluate(const mf_metric_ctx *ctx, const mf_dict *md, double *error)
{
    const char *case_dir = ctx->case_dir;
    layer_settings s;
    MF_CALL(mf_params_apply(layer_params, 6, md, metric_extra, &s, NULL));
    int heavy = 0, light = 0;
    MF_CALL(fluid_index(case_dir, s.heavy, &heavy));
    MF_CALL(fluid_index(case_dir, s.light, &light));
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    table t = {.ncols = 5};
    int rc = 0;
    double below_sum = 0, h_int = 0, yh_sum = 0, yl_sum = 0;
    size_t used = 0;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        snap sn;
        rc = snap_load(case_dir, idx[k], &sn);
        if (rc != 0)
            break;
        if (!sn.fid) {
            snap_free(&sn);
            rc = MF_ERROR(MF_ERR_INPUT, "%s: the snapshots have no FluidId (one fluid?)",
                          case_dir);
            break;
        }
        const mf_particles *p = sn.sim.p;
        double yh = 0, yl = 0;
        size_t nh = 0, nlight = 0, below = 0;
        for (size_t i = 0; i < p->n; i++) {
            if (p->kind[i] != MF_FLUID)
                continue;
            if (sn.fid[i] == heavy) {
                yh += p->pos[3 * i + 1];
                nh++;
            } else if (sn.fid[i] == light) {
                yl += p->pos[3 * i + 1];
                nlight++;
            }
        }
        /* The heavy fluid filling the bottom: N l0^d / crossSection high. */
        h_int = s.bottom + (double)nh * pow(sn.h.l0, sn.h.dim) / s.cross;
        for (size_t i = 0; i < p->n; i++)
            if (p->kind[i] == MF_FLUID && sn.fid[i] == light && p->pos[3 * i + 1] < h_int)
                below++;
        double frac = nlight ? (double)below / (double)nlight : 0;
        double row[5] = {sn.h.time, nh ? yh / (double)nh : 0, nlight ? yl / (double)nlight : 0,
                         h_int, 1 - frac};
        rc = table_add(&t, row);
        if (rc == 0 && sn.h.time >= s.settle) {
            below_sum += frac;
            yh_sum += row[1];
            yl_sum += row[2];
            used++;
        }
        snap_free(&sn);
    }
    free(idx);
    if (rc == 0 && used == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no snapshot after settleTime %g", case_dir, s.settle);
    if (rc == 0) {
        *error = below_sum / (double)used;
        char comment[768], title[256];
        snprintf(comment, sizeof comment,
                 "layering of %s (light) over %s (heavy): interface height h = bottom + "
                 "N_heavy l0^d / crossSection = %.6g m\nafter t = %g s (%zu snapshots): mean "
                 "height heavy %.6g m, light %.6g m; fraction of light particles below h "
                 "(the error) %.6g",
                 s.light, s.heavy, h_int, s.settle, used, yh_sum / (double)used,
                 yl_sum / (double)used, *error);
        snprintf(title, sizeof title, "Layering: %s over %s (light below h: %.3g)", s.light,
                 s.heavy, *error);
        mf_plot plot = {title, "t, s", "mean height, m", false, false, NULL};
        mf_series series[3] = {{s.heavy, t.col[0], t.col[1], t.n, "linespoints", NULL},
                               {s.light, t.col[0], t.col[2], t.n, "linespoints", NULL},
                               {"interface height", t.col[0], t.col[3], t.n, "lines", NULL}};
        rc = write_report(ctx->out_dir, comment, "t,y_heavy,y_light,h_interface,light_above",
                          &t, &plot, series, 3);
    }
    table_free(&t);
    return rc;
}

const mf_metric mf_metric_layering = {"layering",
                                      "two fluids settled: light above the interface height",
                                      layer_evaluate,
    layer_params, sizeof layer_params / sizeof layer_params[0]};

/* ---- rayleighTaylor -------------------------------------------------------------- */

typedef struct rt_settings {
    const char *metric, *heavy, *light;
    double bottom, height, gravity;
} rt_settings;

static const mf_param rt_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(rt_settings, metric),
     "rayleighTaylor"},
    {"heavyFluid", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(rt_settings, heavy),
     "the denser fluid (on top at the start)"},
    {"lightFluid", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(rt_settings, light),
     "the lighter fluid"},
    {"bottom", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL, offsetof(rt_settings, bottom),
     "height of the floor, m"},
    {"height", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(rt_settings, height),
     "height of the domain, m"},
    {"gravity", MF_PARAM_SCALAR, "1", 1e-9, 1e9, NULL, offsetof(rt_settings, gravity),
     "g, m/s^2"},
};

static int rt_evaluate(const mf_metric_ctx *ctx, const mf_dict *md, double *error)
{
    const char *case_dir = ctx->case_dir;
    rt_settings s;
    MF_CALL(mf_params_apply(rt_params, 6, md, metric_extra, &s, NULL));
    int heavy = 0, light = 0;
    MF_CALL(fluid_index(case_dir, s.heavy, &heavy));
    MF_CALL(fluid_index(case_dir, s.light, &light));
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    table t = {.ncols = 4};
    int rc = 0;
    double e0 = 0, e_end = 0, e_min = 0;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        snap sn;
        rc = snap_load(case_dir, idx[k], &sn);
        if (rc != 0)
            break;
        if (!sn.fid) {
            snap_free(&sn);
            rc = MF_ERROR(MF_ERR_INPUT, "%s: the snapshots have no FluidId", case_dir);
            break;
        }
        const mf_particles *p = sn.sim.p;
        double spike = INFINITY, bubble = -INFINITY, sh = 0;
        size_t nh = 0;
        for (size_t i = 0; i < p->n; i++) {
            if (p->kind[i] != MF_FLUID)
                continue;
            double y = p->pos[3 * i + 1];
            if (sn.fid[i] == heavy) {
                spike = fmin(spike, y);
                sh += y - s.bottom;
                nh++;
            } else if (sn.fid[i] == light) {
                bubble = fmax(bubble, y);
            }
        }
        /* Potential energy of the density excess: (rho_h - rho_l) g sum y V,
         * as a mean height of the heavy particles (the light ones fill the
         * rest). Fully overturned: the heavy fluid in the bottom layer. */
        double ybar = nh ? sh / (double)nh : 0;
        if (k == 0) {
            e0 = ybar;
            double frac = 0; /* heavy share of the domain height */
            size_t nall = 0;
            for (size_t i = 0; i < p->n; i++)
                nall += p->kind[i] == MF_FLUID;
            frac = nall ? (double)nh / (double)nall : 0;
            e_min = 0.5 * frac * s.height;
        }
        e_end = ybar;
        double row[4] = {sn.h.time, spike - s.bottom, bubble - s.bottom, ybar};
        rc = table_add(&t, row);
        snap_free(&sn);
    }
    free(idx);
    if (rc == 0 && t.n < 2)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: fewer than two snapshots", case_dir);
    if (rc == 0) {
        *error = e0 > e_min ? (e_end - e_min) / (e0 - e_min) : 0;
        char comment[768], title[256];
        snprintf(comment, sizeof comment,
                 "Rayleigh-Taylor: spike = lowest %s particle, bubble = highest %s particle "
                 "(heights above the floor)\nmean height of the heavy fluid: %.6g m at the "
                 "start, %.6g m at the end, %.6g m fully overturned; error = share of the "
                 "available potential energy left = %.6g",
                 s.heavy, s.light, e0, e_end, e_min, *error);
        snprintf(title, sizeof title, "Rayleigh-Taylor (potential energy left %.3g)", *error);
        mf_plot plot = {title, "t, s", "height, m", false, false, NULL};
        mf_series series[3] = {
            {"spike (heavy, lowest)", t.col[0], t.col[1], t.n, "lines lw 2", NULL},
            {"bubble (light, highest)", t.col[0], t.col[2], t.n, "lines lw 2", NULL},
            {"heavy mean height", t.col[0], t.col[3], t.n, "lines", NULL}};
        rc = write_report(ctx->out_dir, comment, "t,spike,bubble,heavy_mean_height", &t, &plot,
                          series, 3);
    }
    table_free(&t);
    return rc;
}

const mf_metric mf_metric_rayleigh_taylor = {
    "rayleighTaylor", "spike and bubble of a Rayleigh-Taylor instability", rt_evaluate,
    rt_params, sizeof rt_params / sizeof rt_params[0]};

/* ---- fluidSurgeFront ------------------------------------------------------------ */
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
static int fluid_front(const snap *sn, int fluid, double back_wall, double *z)
{
    const mf_particles *all = sn->sim.p;
    mf_particles *f = NULL;
    MF_CALL(mf_particles_create(all->dim, all->n + 1, &f));
    int rc = 0;
    for (size_t i = 0; i < all->n && rc == 0; i++)
        if (is_of(sn, i, fluid))
            rc = mf_particles_add(f, MF_FLUID, &all->pos[3 * i], &all->vel[3 * i], NULL);
    if (rc == 0)
        rc = mf_front_of_particles(f, sn->h.l0, back_wall, z);
    mf_particles_destroy(f);
    return rc;
}

static int front_evaluate(const mf_metric_ctx *ctx, const mf_dict *md, double *error)
{
    const char *case_dir = ctx->case_dir;
    front_settings s;
    MF_CALL(mf_params_apply(front_params, 7, md, metric_extra, &s, NULL));
    int fluid = 0;
    MF_CALL(fluid_index(case_dir, s.fluid, &fluid));
    char path[4400];
    snprintf(path, sizeof path, "%s/validation/%s", case_dir, s.reference);
    double *Tref = NULL, *Zref = NULL;
    size_t nref = 0;
    MF_CALL(mf_read_csv2(path, &Tref, &Zref, &nref));
    int *idx = NULL;
    size_t nsnap = 0;
    int rc = mf_metric_snapshots(ctx, &idx, &nsnap);
    table t = {.ncols = 2};
    const double tscale = sqrt(2 * s.g / s.a);
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        snap sn;
        rc = snap_load(case_dir, idx[k], &sn);
        if (rc != 0)
            break;
        double z = 0;
        rc = fluid_front(&sn, sn.fid ? fluid : -1, s.back_wall, &z);
        double row[2] = {sn.h.time * tscale, z / s.a};
        if (rc == 0 && (t.n == 0 || row[0] > t.col[0][t.n - 1]))
            rc = table_add(&t, row);
        snap_free(&sn);
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
    table_free(&t);
    return rc;
}

const mf_metric mf_metric_fluid_surge_front = {
    "fluidSurgeFront", "dam-break surge front of one fluid among several", front_evaluate,
    front_params, sizeof front_params / sizeof front_params[0]};
