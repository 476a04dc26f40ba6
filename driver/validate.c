/* validate.c: `mpsflow validate -case DIR` runs the metric named in the
 * case's validation/metric on its snapshots. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_post.h"

extern const mf_metric mf_metric_scalar_advection; /* metric_scalar.c */
extern const mf_metric mf_metric_volume_flux;      /* metric_scalar.c */
extern const mf_metric mf_metric_poiseuille;       /* metric_poiseuille.c */

/* metric_droplet.c: the multi-fluid cases */
extern const mf_metric mf_metric_laplace, mf_metric_oscillation, mf_metric_layering,
    mf_metric_rayleigh_taylor, mf_metric_fluid_surge_front;

static const mf_metric *const metrics[] = {
    &mf_metric_surge_front,
    &mf_metric_hydrostatic,
    &mf_metric_scalar_advection,
    &mf_metric_volume_flux,
    &mf_metric_laplace,
    &mf_metric_oscillation,
    &mf_metric_layering,
    &mf_metric_rayleigh_taylor,
    &mf_metric_fluid_surge_front,
    &mf_metric_poiseuille,
};
#define NMETRICS (sizeof metrics / sizeof metrics[0])

double mf_interp(const double *x, const double *y, size_t n, double xq)
{
    if (n == 0 || xq < x[0] || xq > x[n - 1])
        return NAN;
    for (size_t i = 1; i < n; i++)
        if (xq <= x[i]) {
            double t = x[i] > x[i - 1] ? (xq - x[i - 1]) / (x[i] - x[i - 1]) : 0;
            return y[i - 1] + t * (y[i] - y[i - 1]);
        }
    return y[n - 1];
}

int mf_read_csv2(const char *path, double **a, double **b, size_t *n)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return MF_ERROR(MF_ERR_INPUT, "%s: cannot open (%s)", path, strerror(errno));
    size_t cap = 64, line = 0;
    *n = 0;
    *a = malloc(cap * sizeof **a);
    *b = malloc(cap * sizeof **b);
    char buf[1024];
    bool header = false;
    int rc = 0;
    while (rc == 0 && *a && *b && fgets(buf, sizeof buf, f)) {
        line++;
        if (buf[0] == '#' || buf[0] == '\n')
            continue;
        if (!header) {
            header = true;
            continue;
        }
        double x, y;
        if (sscanf(buf, "%lf,%lf", &x, &y) != 2) {
            rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: expected two numbers 'x,y'", path, line);
            break;
        }
        if (*n == cap) {
            cap *= 2;
            double *ga = realloc(*a, cap * sizeof **a), *gb = realloc(*b, cap * sizeof **b);
            if (ga) *a = ga;
            if (gb) *b = gb;
            if (!ga || !gb)
                break;
        }
        (*a)[*n] = x;
        (*b)[*n] = y;
        (*n)++;
    }
    fclose(f);
    if (rc == 0 && (!*a || !*b))
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory reading %s", path);
    if (rc == 0 && *n == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no data rows", path);
    if (rc != 0) {
        free(*a);
        free(*b);
        *a = *b = NULL;
    }
    return rc;
}

int mf_cmd_validate(const char *case_dir, double *error)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/validation/metric", case_dir);
    mf_dict *d = NULL;
    MF_CALL(mf_dict_parse_file(path, &d));
    const char *name = NULL;
    int rc = mf_dict_get_word(d, "metric", &name);
    const mf_metric *m = NULL;
    for (size_t k = 0; rc == 0 && k < NMETRICS; k++)
        if (strcmp(metrics[k]->name, name) == 0)
            m = metrics[k];
    if (rc == 0 && !m) {
        const char *names[NMETRICS];
        for (size_t k = 0; k < NMETRICS; k++)
            names[k] = metrics[k]->name;
        const char *hint = mf_did_you_mean(name, names, NMETRICS);
        rc = MF_ERROR(MF_ERR_INPUT, "%s: unknown metric '%s'%s%s%s; known: surgeFront, "
                      "hydrostaticPressure, scalarAdvection, volumeFlux, laplacePressure, "
                      "oscillationPeriod, layering, rayleighTaylor, fluidSurgeFront, poiseuille",
                      path, name, hint ? " (did you mean '" : "", hint ? hint : "",
                      hint ? "'?)" : "");
    }
    if (rc == 0)
        rc = m->evaluate(case_dir, d, error);
    if (rc == 0)
        printf("error %s = %.6g\n", m->name, *error);
    mf_dict_free(d);
    return rc;
}
