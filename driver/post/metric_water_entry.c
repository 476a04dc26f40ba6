/* metric_water_entry.c: a 2-D circular cylinder's penetration into calm
 * water (tutorials/waterEntry) against an experiment and against the
 * momentum theory of water entry.
 *
 * The experiment this case copies, Greenhow & Lin (1983), "Nonlinear free
 * surface effects: experiments and theory", MIT Dept. of Ocean Engineering
 * report 83-19 (a half-buoyant cylinder, D = 0.11 m), gives its penetration
 * in figures; `reference` names a CSV in validation/ of T = t sqrt(g/D),
 * H = h/D (tutorials/waterEntry: points digitised from Sun et al. 2018's
 * replot, see the file). With it the error is the RMS over the reference's
 * points with T > 0 that the run covers of (h - h_exp)/D, the run's h
 * interpolated linearly in time; result_experiment.csv has both.
 *
 * The analytic model, reported in result.csv (and the error without a
 * reference): a body of mass m (per metre) and half-width c(h) of its
 * wetted section at penetration h (the depth of its lowest point below the
 * undisturbed surface) takes up the fluid's added mass a(h) = rho pi c^2 / 2,
 * the flat plate's of half-width c (von Karman 1929, "The impact on seaplane
 * floats during landing", NACA TN 321), and
 *
 *   d/dt [(m + a(h)) dh/dt] = m g - rho g A(h)
 *
 * (momentum of body and added mass; A(h) the section below the undisturbed
 * level, its buoyancy), from h = 0 at the CSV's first row with its speed.
 * von Karman's c^2 = 2 R h - h^2 (the section at the undisturbed level); the
 * Wagner (1932) wetting correction, the water piled up beside the body,
 * doubles it for small h: c^2 = 4 R h, up to R^2. Both hold while the
 * section is widening (h <= R); beyond it c = R is kept, the deep limit of
 * a half-submerged cylinder's added mass. The model's RMS is over the body's
 * rows with 0 < t <= endTime of (h - h_vonKarman) / D; result.csv has h,
 * both models and the fraction of rows between them.
 *
 * The body's centre y_c(t) comes from postProcessing/<body>/bodyState.csv
 * (its mass from the header): h = (surface + radius) - y_c. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_post.h"
#include "mf_report.h"

typedef struct entry_settings {
    const char *metric, *body, *reference;
    double radius, surface, rho, g, end;
} entry_settings;

static const mf_param entry_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(entry_settings, metric),
     "waterEntryDepth"},
    {"body", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(entry_settings, body),
     "the obstacle's name (postProcessing/<body>/bodyState.csv)"},
    {"radius", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(entry_settings, radius),
     "R, the cylinder's radius, m"},
    {"surface", MF_PARAM_SCALAR, NULL, -1e9, 1e9, NULL, offsetof(entry_settings, surface),
     "the undisturbed water level, m (the body's lowest point there at h = 0)"},
    {"rho", MF_PARAM_SCALAR, "1000", 1e-9, 1e9, NULL, offsetof(entry_settings, rho),
     "the water's density, kg/m^3"},
    {"gravity", MF_PARAM_SCALAR, "9.81", 0, 1e9, NULL, offsetof(entry_settings, g), "g, m/s^2"},
    {"endTime", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(entry_settings, end),
     "compare with the models up to this time, s (they hold while h <= R)"},
    {"reference", MF_PARAM_WORD, "", MF_NO_RANGE, NULL, offsetof(entry_settings, reference),
     "CSV file T = t sqrt(g/D), H = h/D in validation/ (an experiment): the error is the RMS "
     "of (h - h_ref)/D at its points; empty: against von Karman's model"},
};
#define NEP (sizeof entry_params / sizeof entry_params[0])

/* The body's rows: time, y_c, v_y; its mass from the header comment. */
static int read_rows(const char *path, double **t, double **y, size_t *n, double *mass,
                     double *v0)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return MF_ERROR(MF_ERR_IO, "cannot read %s (the body's trajectory): run the case first",
                        path);
    size_t cap = 0;
    *n = 0;
    *t = *y = NULL;
    *mass = NAN;
    *v0 = NAN;
    char line[4096];
    int rc = 0;
    while (rc == 0 && fgets(line, sizeof line, f)) {
        if (line[0] == '#') {
            const char *m = strstr(line, "mass ");
            if (m)
                *mass = atof(m + 5);
            continue;
        }
        double c[10];
        int k = 0;
        for (char *s = line, *e; k < 10; k++, s = e + 1) {
            c[k] = strtod(s, &e);
            if (e == s || *e != ',')
                break;
        }
        if (k < 10)
            continue;
        if (*n == cap) {
            const size_t grown = cap ? 2 * cap : 1024;
            if ((rc = mf_resize(t, grown, sizeof **t)) != 0 ||
                (rc = mf_resize(y, grown, sizeof **y)) != 0)
                break;
            cap = grown;
        }
        if (*n == 0)
            *v0 = c[9];
        (*t)[*n] = c[0];
        (*y)[*n] = c[2];
        (*n)++;
    }
    fclose(f);
    if (rc == 0 && (*n < 2 || !(*mass > 0)))
        rc = MF_ERROR(MF_ERR_INPUT, "%s: fewer than two rows or no 'mass' in its header", path);
    return rc;
}

/* The area of the circle's segment below the level at penetration h. */
static double segment_area(double R, double h)
{
    if (h <= 0)
        return 0;
    if (h >= 2 * R)
        return M_PI * R * R;
    return R * R * acos((R - h) / R) - (R - h) * sqrt(fmax(0, 2 * R * h - h * h));
}

typedef struct model {
    double R, m, rho, g;
    bool wagner;
} model;

static double added_mass(const model *md, double h)
{
    const double R = md->R;
    double c2 = h >= R ? R * R : md->wagner ? fmin(4 * R * h, R * R) : 2 * R * h - h * h;
    if (c2 < 0)
        c2 = 0;
    return 0.5 * md->rho * M_PI * c2;
}

/* d/dt (h, P = (m + a) dh/dt). */
static void rate(const model *md, const double s[2], double ds[2])
{
    ds[0] = s[1] / (md->m + added_mass(md, s[0]));
    ds[1] = md->m * md->g - md->rho * md->g * segment_area(md->R, s[0]);
}

/* h(t) at the times tq (ascending, from 0) by RK4 with steps of at most
 * 1e-5 s (the curves converge to 1e-9 m). */
static void integrate(const model *md, double speed, const double *tq, size_t n, double *h)
{
    double s[2] = {0, md->m * speed}, t = 0;
    for (size_t k = 0; k < n; k++) {
        while (t < tq[k]) {
            const double dt = fmin(1e-5, tq[k] - t);
            double k1[2], k2[2], k3[2], k4[2], u[2];
            rate(md, s, k1);
            for (int i = 0; i < 2; i++)
                u[i] = s[i] + 0.5 * dt * k1[i];
            rate(md, u, k2);
            for (int i = 0; i < 2; i++)
                u[i] = s[i] + 0.5 * dt * k2[i];
            rate(md, u, k3);
            for (int i = 0; i < 2; i++)
                u[i] = s[i] + dt * k3[i];
            rate(md, u, k4);
            for (int i = 0; i < 2; i++)
                s[i] += dt / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
            t += dt;
        }
        h[k] = s[0];
    }
}

/* The run's h/D at the reference's times T (= t sqrt(g/D)): hrun[i], linear
 * in time, NAN where the run does not reach T or T <= 0 (the contact, h = 0
 * by construction). *rms, *worst (the largest |h - h_ref|/D) and *at (its
 * T) over the *used points compared. */
typedef struct ref_fit {
    double rms, worst, at;
    size_t used;
} ref_fit;

static ref_fit fit_reference(const double *T, const double *H, size_t nref, const double *t,
                             const double *h, size_t n, double tscale, double D, double *hrun)
{
    ref_fit f = {NAN, 0, NAN, 0};
    double sum = 0;
    for (size_t i = 0; i < nref; i++) {
        hrun[i] = T[i] > 0 ? mf_interp(t, h, n, T[i] / tscale) / D : NAN;
        if (isnan(hrun[i]))
            continue;
        const double d = hrun[i] - H[i];
        sum += d * d;
        f.used++;
        if (fabs(d) > f.worst) {
            f.worst = fabs(d);
            f.at = T[i];
        }
    }
    if (f.used)
        f.rms = sqrt(sum / (double)f.used);
    return f;
}

/* The run against validation/<reference>: result_experiment.csv/.png and a
 * line of the summary; *error = the fit's RMS. */
static int against_reference(const entry_settings *s, const mf_metric_ctx *ctx, const double *t,
                             const double *h, size_t n, double *error, char *line, size_t len)
{
    char path[4400];
    snprintf(path, sizeof path, "%s/validation/%s", ctx->case_dir, s->reference);
    double *T = NULL, *H = NULL;
    size_t nref = 0;
    MF_CALL(mf_read_csv2(path, &T, &H, &nref));
    const double D = 2 * s->radius, tscale = sqrt(s->g / D);
    int rc = 0;
    double *hrun = malloc((nref + 1) * sizeof *hrun), *Trun = malloc(n * sizeof *Trun),
           *Hrun = malloc(n * sizeof *Hrun);
    if (!hrun || !Trun || !Hrun)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    ref_fit f = {NAN, 0, NAN, 0};
    if (rc == 0) {
        f = fit_reference(T, H, nref, t, h, n, tscale, D, hrun);
        if (f.used == 0)
            rc = MF_ERROR(MF_ERR_INPUT,
                          "%s: the run (to t = %g s, T = %g) covers none of its points with T > 0",
                          path, t[n - 1], t[n - 1] * tscale);
    }
    if (rc == 0) {
        *error = f.rms;
        snprintf(line, len,
                 "against %s (T = t sqrt(g/D), H = h/D): RMS of (h - h_ref)/D over %zu of %zu "
                 "points: %.9g; largest %.4g at T = %.4g",
                 s->reference, f.used, nref, f.rms, f.worst, f.at);
        char comment[1600];
        snprintf(comment, sizeof comment,
                 "water entry of '%s' against %s: the run's H = h/D at the reference's T "
                 "(linear in time; nan where the run does not reach T, and at T = 0)\n%s",
                 s->body, s->reference, line);
        snprintf(path, sizeof path, "%s/result_experiment.csv", ctx->out_dir);
        const double *const cols[3] = {T, H, hrun};
        rc = mf_report_csv(path, comment, "T,H_reference,H_run", 3, cols, nref);
    }
    if (rc == 0) {
        for (size_t k = 0; k < n; k++) {
            Trun[k] = t[k] * tscale;
            Hrun[k] = h[k] / D;
        }
        snprintf(path, sizeof path, "%s/result_experiment.png", ctx->out_dir);
        char title[256];
        snprintf(title, sizeof title, "Water entry: penetration against %s (RMS %.3g)",
                 s->reference, f.rms);
        mf_plot plot = {title, "T = t (g/D)^{1/2}", "H = h/D", false, false, NULL};
        mf_series series[2] = {{"mpsflow", Trun, Hrun, n, "lines", NULL},
                               {s->reference, T, H, nref, "points", NULL}};
        rc = mf_report_plot(path, &plot, series, 2);
    }
    free(hrun);
    free(Trun);
    free(Hrun);
    free(T);
    free(H);
    return rc;
}

static int evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    const entry_settings s = *(const entry_settings *)settings;
    char path[4400];
    snprintf(path, sizeof path, "%s/postProcessing/%s/bodyState.csv", ctx->case_dir, s.body);
    double *t = NULL, *y = NULL, mass = NAN, v0 = NAN;
    size_t n = 0;
    MF_CALL(read_rows(path, &t, &y, &n, &mass, &v0));
    int rc = 0;
    double *h = malloc(n * sizeof *h), *hk = malloc(n * sizeof *hk), *hw = malloc(n * sizeof *hw);
    if (!h || !hk || !hw)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    size_t m = 0; /* rows with t0 < t <= endTime, t from the first row */
    const double t0 = n ? t[0] : 0;
    for (size_t k = 0; rc == 0 && k < n; k++) {
        t[k] -= t0;
        h[k] = s.surface + s.radius - y[k];
        if (t[k] <= s.end * (1 + 1e-12))
            m = k + 1;
    }
    if (rc == 0 && m < 3)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: fewer than three rows up to endTime %g s", path, s.end);
    double model_rms = NAN;
    char ref_line[600] = "";
    if (rc == 0) {
        const model vk = {s.radius, mass, s.rho, s.g, false}, wg = {s.radius, mass, s.rho, s.g, true};
        integrate(&vk, -v0, t, m, hk);
        integrate(&wg, -v0, t, m, hw);
        const double D = 2 * s.radius;
        double sum = 0;
        size_t rows = 0, between = 0;
        for (size_t k = 1; k < m; k++) {
            const double d = (h[k] - hk[k]) / D;
            sum += d * d;
            rows++;
            between += h[k] >= fmin(hk[k], hw[k]) && h[k] <= fmax(hk[k], hw[k]);
        }
        model_rms = sqrt(sum / (double)rows);
        *error = model_rms;
        if (s.reference[0])
            rc = against_reference(&s, ctx, t, h, n, error, ref_line, sizeof ref_line);
        char comment[2200];
        snprintf(comment, sizeof comment,
                 "water entry of '%s': R = %g m, mass %.6g kg/m, entry speed %.6g m/s, level %g m\n"
                 "h = (level + R) - y_c against the momentum theory, added mass rho pi c^2/2: "
                 "von Karman (c^2 = 2Rh - h^2) and Wagner (c^2 = 4Rh), c = R beyond h = R\n"
                 "RMS of (h - h_vonKarman)/D over %zu rows to t = %g s: %.6g; at t = %.6g s h = "
                 "%.6g m, von Karman %.6g m, Wagner %.6g m; %zu of %zu rows between the two%s%s",
                 s.body, s.radius, mass, -v0, s.surface, rows, t[m - 1], model_rms, t[m - 1],
                 h[m - 1], hk[m - 1], hw[m - 1], between, rows, ref_line[0] ? "\n" : "",
                 ref_line);
        snprintf(path, sizeof path, "%s/result.csv", ctx->out_dir);
        const double *const cols[4] = {t, h, hk, hw};
        if (rc == 0)
            rc = mf_report_csv(path, comment, "t,h,h_vonKarman,h_Wagner", 4, cols, m);
        if (rc == 0) {
            snprintf(path, sizeof path, "%s/result.png", ctx->out_dir);
            char title[256];
            snprintf(title, sizeof title, "Water entry: penetration (RMS against von Karman %.3g D)",
                     model_rms);
            mf_plot plot = {title, "t, s", "penetration h, m", false, false, NULL};
            mf_series series[3] = {{"mpsflow", t, h, m, "linespoints", NULL},
                                   {"von Karman", t, hk, m, "lines", NULL},
                                   {"Wagner", t, hw, m, "lines", NULL}};
            rc = mf_report_plot(path, &plot, series, 3);
        }
    }
    free(h);
    free(hk);
    free(hw);
    free(t);
    free(y);
    return rc;
}

const mf_metric_ops mf_metric_water_entry = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "waterEntryDepth",
     "a cylinder's penetration into water against an experiment's (reference) or the momentum "
     "theory with von Karman's added mass (Wagner's in the report)",
     entry_params, NEP, sizeof(entry_settings)},
    evaluate,
    NULL,
};
