/* test_convection.c: the convection schemes of the MPS-MAFL Eulerian phase
 * (solvers/convection), through their module tables, on a 1-D periodic
 * lattice: the directional grid of a point whose streamline runs along a
 * lattice line (the grid points are lattice points, as in the Eulerian
 * limit of tests/test_mafl.c).
 *
 *   - registry: both schemes register, with their parameters;
 *   - exactness: upwind and eq. 25 reproduce linear profiles, QUICK with
 *     its streaming terms cubic ones, at any q;
 *   - order on a Gaussian at a fixed Courant number q = 0.2 (dt ~ dr), four
 *     resolutions: upwind about 1, QUICK at least 1.8; eq. 25 as printed
 *     (streamingTerms no) is measured and shown to be first order: its
 *     error per step is q^2 dr^2 f''/2, the time term (quick.c);
 *   - a top-hat: with the filter every scheme stays within [0, 1]; QUICK
 *     without the filter over- and undershoots;
 *   - stability: the L2 norm of a random profile never grows (QUICK, q in
 *     (0, 1]). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "convection/convection.h"
#include "mf_modules.h"
#include "mf_registry.h"
#include "mf_solvers.h"
#include "mf_test.h"

typedef struct scheme {
    mf_module m;
    const mf_convection_ops *ops;
} scheme;

/* The scheme `name` with its parameters from the text of a dictionary. */
static int make_scheme(const mf_registry *reg, const char *name, bool filter, bool streaming,
                       scheme *s)
{
    memset(s, 0, sizeof *s);
    mf_dict *d = mf_dict_new("", NULL);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    int rc = mf_dict_set_word(d, "filter", filter ? "yes" : "no");
    if (rc == 0 && strcmp(name, "QUICK") == 0)
        rc = mf_dict_set_word(d, "streamingTerms", streaming ? "yes" : "no");
    if (rc == 0)
        rc = mf_module_prepare(reg, MF_KIND_CONVECTION, name, d, NULL, NULL, &s->m);
    if (rc == 0) {
        s->ops = (const mf_convection_ops *)s->m.info;
        rc = s->ops->create(s->m.settings, &s->m.data);
    }
    mf_dict_free(d);
    return rc;
}

static void free_scheme(scheme *s)
{
    if (s->ops && s->m.data)
        s->ops->destroy(s->m.data);
    mf_module_release(&s->m);
}

/* One step on a periodic lattice of n points. */
static void step(const scheme *s, const double *f, double *g, size_t n, double q)
{
    for (size_t i = 0; i < n; i++) {
        const double st[4] = {f[(i + n - 2) % n], f[(i + n - 1) % n], f[i], f[(i + 1) % n]};
        g[i] = s->ops->convect(s->m.data, st, q);
    }
}

static double gaussian(double x, double centre, double width)
{
    double d = x - centre;
    d -= floor(d + 0.5); /* periodic on [0, 1) */
    return exp(-d * d / (2 * width * width));
}

/* RMS error after carrying a Gaussian a distance 0.3 at Courant number q. */
static double gaussian_error(const scheme *s, size_t n, double q)
{
    const double h = 1.0 / n, width = 0.08, travel = 0.3;
    const long steps = lround(travel / (q * h));
    double *f = malloc(n * sizeof *f), *g = malloc(n * sizeof *g);
    if (!f || !g) {
        free(f);
        free(g);
        return NAN;
    }
    for (size_t i = 0; i < n; i++)
        f[i] = gaussian((i + 0.5) * h, 0.35, width);
    for (long k = 0; k < steps; k++) {
        step(s, f, g, n, q);
        memcpy(f, g, n * sizeof *f);
    }
    double sum = 0;
    for (size_t i = 0; i < n; i++) {
        double e = f[i] - gaussian((i + 0.5) * h - steps * q * h, 0.35, width);
        sum += e * e;
    }
    free(f);
    free(g);
    return sqrt(sum / n);
}

/* Least-squares slope of log(error) against log(1/h). */
static double fitted_order(const double *err, const size_t *n, int count)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int k = 0; k < count; k++) {
        double x = log((double)n[k]), y = log(err[k]);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    return -(count * sxy - sx * sy) / (count * sxx - sx * sx);
}

static double measure_order(const scheme *s, const char *label)
{
    static const size_t n[4] = {50, 100, 200, 400};
    double err[4];
    printf("%-26s", label);
    for (int k = 0; k < 4; k++) {
        err[k] = gaussian_error(s, n[k], 0.2);
        printf(" %.3e", err[k]);
    }
    double p = fitted_order(err, n, 4);
    printf("  order %.2f (last pair %.2f)\n", p, log2(err[2] / err[3]));
    return p;
}

/* A polynomial of degree `deg` sampled at -2, -1, 0, 1: the scheme must
 * return its value at -q. */
static double polynomial_defect(const scheme *s, int deg, double q)
{
    double worst = 0;
    for (int trial = 0; trial < 5; trial++) {
        double c[4] = {0, 0, 0, 0};
        for (int k = 0; k <= deg; k++)
            c[k] = cos(1.7 * trial + k);
        double f[4];
        for (int k = 0; k < 4; k++) {
            double x = k - 2;
            f[k] = c[0] + x * (c[1] + x * (c[2] + x * c[3]));
        }
        double x = -q, exact = c[0] + x * (c[1] + x * (c[2] + x * c[3]));
        double d = fabs(s->ops->convect(s->m.data, f, q) - exact);
        worst = d > worst ? d : worst;
    }
    return worst;
}

/* Carry a top-hat once around; the range of the result. */
static void tophat_range(const scheme *s, double q, double *lo, double *hi)
{
    const size_t n = 200;
    const long steps = lround(1.0 / (q / n));
    double *f = malloc(n * sizeof *f), *g = malloc(n * sizeof *g);
    *lo = INFINITY;
    *hi = -INFINITY;
    if (!f || !g) {
        free(f);
        free(g);
        return;
    }
    for (size_t i = 0; i < n; i++)
        f[i] = (i >= 40 && i < 80) ? 1.0 : 0.0;
    for (long k = 0; k < steps; k++) {
        step(s, f, g, n, q);
        memcpy(f, g, n * sizeof *f);
        for (size_t i = 0; i < n; i++) {
            *lo = f[i] < *lo ? f[i] : *lo;
            *hi = f[i] > *hi ? f[i] : *hi;
        }
    }
    free(f);
    free(g);
}

static double norm2(const double *f, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; i++)
        s += f[i] * f[i];
    return sqrt(s);
}

int main(void)
{
    mf_registry *reg = NULL;
    CHECK_OK(mf_registry_create(&reg));
    CHECK_OK(mf_solvers_register_all(reg));
    if (!reg)
        return mf_test_summary("convection");
    CHECK(mf_registry_count(reg, MF_KIND_CONVECTION) >= 2);
    const mf_module_info *info = NULL;
    CHECK_OK(mf_registry_find(reg, MF_KIND_CONVECTION, "upwind", &info));
    CHECK_OK(mf_registry_find(reg, MF_KIND_CONVECTION, "QUICK", &info));

    scheme upwind, quick, quick_filter, eq25, upwind_filter;
    CHECK_OK(make_scheme(reg, "upwind", false, false, &upwind));
    CHECK_OK(make_scheme(reg, "upwind", true, false, &upwind_filter));
    CHECK_OK(make_scheme(reg, "QUICK", false, true, &quick));
    CHECK_OK(make_scheme(reg, "QUICK", true, true, &quick_filter));
    CHECK_OK(make_scheme(reg, "QUICK", false, false, &eq25));
    if (!upwind.ops || !quick.ops || !eq25.ops || !quick_filter.ops || !upwind_filter.ops) {
        mf_registry_destroy(reg);
        return mf_test_summary("convection");
    }

    /* Exactness. */
    for (double q = 0.1; q <= 1.0; q += 0.3) {
        CHECK_MSG(polynomial_defect(&upwind, 1, q) < 1e-13, "upwind, linear, q = %g", q);
        CHECK_MSG(polynomial_defect(&eq25, 1, q) < 1e-13, "eq. 25, linear, q = %g", q);
        CHECK_MSG(polynomial_defect(&quick, 3, q) < 1e-12, "QUICK, cubic, q = %g", q);
        /* eq. 25 misses the q^2 f''/2 of the departure point. */
        CHECK_MSG(polynomial_defect(&eq25, 2, q) > 1e-3 * q * q, "eq. 25, quadratic, q = %g", q);
    }
    /* q = 0 leaves f alone; q = 1 copies the upstream neighbour. */
    const double f4[4] = {0.3, -1.2, 2.5, 0.7};
    CHECK_NEAR(quick.ops->convect(quick.m.data, f4, 0.0), 2.5, 1e-15);
    CHECK_NEAR(quick.ops->convect(quick.m.data, f4, 1.0), -1.2, 1e-14);
    CHECK_NEAR(upwind.ops->convect(upwind.m.data, f4, 1.0), -1.2, 1e-15);

    /* Order on a Gaussian at a fixed Courant number. */
    printf("RMS error on a Gaussian (width 0.08, carried 0.3 at q = 0.2), N = 50, 100, 200, 400:\n");
    double p_up = measure_order(&upwind, "upwind (eq. 24)");
    double p_quick = measure_order(&quick, "QUICK (streaming terms)");
    double p_quickf = measure_order(&quick_filter, "QUICK + filter (eq. 26)");
    double p_eq25 = measure_order(&eq25, "QUICK, eq. 25 as printed");
    CHECK_MSG(p_up > 0.7 && p_up < 1.3, "upwind order %.2f, expected about 1", p_up);
    CHECK_MSG(p_quick >= 1.8, "QUICK order %.2f, expected at least 1.8", p_quick);
    CHECK_MSG(p_quickf >= 1.5, "QUICK with the filter: order %.2f", p_quickf);
    CHECK_MSG(p_eq25 < 1.3, "eq. 25 as printed: order %.2f; the analysis says 1", p_eq25);

    /* Top-hat: bounded with the filter, not without. */
    for (double q = 0.1; q < 1.0; q += 0.4) {
        double lo, hi;
        tophat_range(&quick_filter, q, &lo, &hi);
        CHECK_MSG(lo >= -1e-15 && hi <= 1 + 1e-15, "QUICK + filter, q = %g: range [%g, %g]", q,
                  lo, hi);
        tophat_range(&upwind_filter, q, &lo, &hi);
        CHECK_MSG(lo >= -1e-15 && hi <= 1 + 1e-15, "upwind + filter, q = %g: range [%g, %g]", q,
                  lo, hi);
        tophat_range(&upwind, q, &lo, &hi);
        CHECK_MSG(lo >= -1e-15 && hi <= 1 + 1e-15, "upwind, q = %g: range [%g, %g]", q, lo, hi);
        tophat_range(&quick, q, &lo, &hi);
        printf("top-hat, q = %.1f: QUICK without the filter spans [%.4f, %.4f]\n", q, lo, hi);
        CHECK_MSG(lo < -0.01 && hi > 1.01, "QUICK without the filter, q = %g: range [%g, %g] "
                                           "(expected over- and undershoots)", q, lo, hi);
    }

    /* Stability of QUICK with the streaming terms. */
    const size_t n = 128;
    double f[128], g[128];
    for (double q = 0.05; q <= 1.0; q += 0.15) {
        for (size_t i = 0; i < n; i++)
            f[i] = sin(12.9898 * i + 78.233 * q) * 43758.5453 - floor(sin(12.9898 * i + 78.233 * q) * 43758.5453);
        double start = norm2(f, n), worst = 0;
        for (int k = 0; k < 500; k++) {
            step(&quick, f, g, n, q);
            memcpy(f, g, sizeof f);
            double r = norm2(f, n) / start;
            worst = r > worst ? r : worst;
        }
        CHECK_MSG(worst <= 1 + 1e-12, "QUICK, q = %g: the L2 norm grew by %g", q, worst);
    }

    free_scheme(&upwind);
    free_scheme(&upwind_filter);
    free_scheme(&quick);
    free_scheme(&quick_filter);
    free_scheme(&eq25);
    mf_registry_destroy(reg);
    return mf_test_summary("convection");
}
