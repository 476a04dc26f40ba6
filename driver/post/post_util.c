/* post_util.c: small helpers the metrics share (interpolation, two-column CSV). */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_post.h"

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
            if (mf_resize(a, cap, sizeof **a) || mf_resize(b, cap, sizeof **b))
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
