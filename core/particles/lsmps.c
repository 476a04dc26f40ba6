/* lsmps.c: the least-squares MPS operators of mf_lsmps.h as pair kernels.
 *
 * Basis (Tamai & Koshizuka 2014, eq. 16), x = r_ij / l0: in 2-D (x, y, x^2,
 * xy, y^2), in 3-D (x, y, z, x^2, xy, xz, y^2, yz, z^2); the linear terms
 * first, so that the linear fit is the leading block of the quadratic one.
 * With a = M^-1 b: df/dx_a = a_a / l0, d2f/dx_a^2 = 2 a_aa / l0^2. */
#include "mf_lsmps.h"

#include <math.h>
#include <string.h>

#define LS_MAX 9   /* basis terms in 3-D */
#define LS_COMP 3  /* components of the fitted field */

typedef struct {
    const mf_pairs *v;
    const uint8_t *jmask;
    const double *f;
    int dim, nb;   /* dimension, basis terms (5 or 9) */
    double inv_l0;
    double scale;
    double *out;
    uint8_t *failed;
    mf_lsmps_extra_fn extra; /* extra points of each fit (NULL: none) */
    const void *extra_ctx;
} ls_ctx;

typedef struct {
    double m[LS_MAX][LS_MAX]; /* lower triangle used */
    double b[LS_MAX][LS_COMP];
    const ls_ctx *c; /* for the extra points */
} ls_acc;

/* The basis at x (scaled): the linear terms, then the quadratic ones. */
static inline int ls_basis(int dim, const double x[3], double p[LS_MAX])
{
    if (dim == 2) {
        p[0] = x[0];
        p[1] = x[1];
        p[2] = x[0] * x[0];
        p[3] = x[0] * x[1];
        p[4] = x[1] * x[1];
        return 5;
    }
    p[0] = x[0];
    p[1] = x[1];
    p[2] = x[2];
    p[3] = x[0] * x[0];
    p[4] = x[0] * x[1];
    p[5] = x[0] * x[2];
    p[6] = x[1] * x[1];
    p[7] = x[1] * x[2];
    p[8] = x[2] * x[2];
    return 9;
}

/* One pair into M and b (ncomp components of f, a literal). */
static inline bool ls_pair(void *acc, const void *ctx, const mf_pair *pr, int ncomp)
{
    const ls_ctx *c = ctx;
    ls_acc *a = acc;
    const double w = mf_weight_ls(pr->len, c->v->radius);
    if (w <= 0.0)
        return true;
    const double x[3] = {pr->r[0] * c->inv_l0, pr->r[1] * c->inv_l0, pr->r[2] * c->inv_l0};
    double p[LS_MAX];
    const int nb = ls_basis(c->dim, x, p);
    for (int r = 0; r < nb; r++)
        for (int s = 0; s <= r; s++)
            a->m[r][s] += w * p[r] * p[s];
    const double *f = c->f;
    for (int q = 0; q < ncomp; q++) {
        const double df = ncomp == 1 ? f[pr->j] - f[pr->i]
                                     : f[3 * pr->j + q] - f[3 * pr->i + q];
        for (int r = 0; r < nb; r++)
            a->b[r][q] += w * p[r] * df;
    }
    return true;
}

/* One extra point (mf_lsmps_point_fn) into M and b, as a pair at r with
 * field difference df, times sign. */
static void ls_extra_point(void *acc, const double r[3], const double df[3], double sign)
{
    ls_acc *a = acc;
    const ls_ctx *c = a->c;
    const double len = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    const double w = sign * mf_weight_ls(len, c->v->radius);
    if (w == 0.0)
        return;
    const double x[3] = {r[0] * c->inv_l0, r[1] * c->inv_l0, r[2] * c->inv_l0};
    double p[LS_MAX];
    const int nb = ls_basis(c->dim, x, p);
    for (int q = 0; q < nb; q++)
        for (int s = 0; s <= q; s++)
            a->m[q][s] += w * p[q] * p[s];
    for (int q = 0; q < LS_COMP; q++)
        for (int s = 0; s < nb; s++)
            a->b[s][q] += w * p[s] * df[q];
}

static inline bool ls1_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    return ls_pair(acc, ctx, pr, 1);
}

static inline bool ls3_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    return ls_pair(acc, ctx, pr, 3);
}

/* Solve the leading n x n block of M a = b (ncomp right-hand sides) in place
 * by Cholesky; false when a pivot falls below 1e-10 of its diagonal entry
 * (M is singular or nearly so: the neighbours do not determine the fit). */
static bool ls_solve(ls_acc *a, int n, int ncomp, double x[LS_MAX][LS_COMP])
{
    double l[LS_MAX][LS_MAX];
    for (int r = 0; r < n; r++) {
        for (int s = 0; s <= r; s++) {
            double sum = a->m[r][s];
            for (int k = 0; k < s; k++)
                sum -= l[r][k] * l[s][k];
            if (r == s) {
                if (!(sum > 1e-10 * a->m[r][r]))
                    return false;
                l[r][r] = sqrt(sum);
            } else {
                l[r][s] = sum / l[s][s];
            }
        }
    }
    for (int q = 0; q < ncomp; q++) {
        double y[LS_MAX];
        for (int r = 0; r < n; r++) {
            double sum = a->b[r][q];
            for (int k = 0; k < r; k++)
                sum -= l[r][k] * y[k];
            y[r] = sum / l[r][r];
        }
        for (int r = n - 1; r >= 0; r--) {
            double sum = y[r];
            for (int k = r + 1; k < n; k++)
                sum -= l[k][r] * x[k][q];
            x[r][q] = sum / l[r][r];
        }
    }
    return true;
}

static void grad_row(const void *ctx, size_t i)
{
    const ls_ctx *c = ctx;
    ls_acc a;
    memset(&a, 0, sizeof a);
    mf_pairs_row(c->v, i, c->jmask, ls1_pair, c, &a);
    double x[LS_MAX][LS_COMP];
    /* quadratic fit, else linear (the leading block) */
    if (!ls_solve(&a, c->nb, 1, x) && !ls_solve(&a, c->dim, 1, x)) {
        c->failed[i] = 1;
        return;
    }
    c->failed[i] = 0;
    for (int q = 0; q < 3; q++)
        c->out[3 * i + q] = q < c->dim ? x[q][0] * c->inv_l0 : 0.0;
}

static void lap_row(const void *ctx, size_t i)
{
    const ls_ctx *c = ctx;
    ls_acc a;
    memset(&a, 0, sizeof a);
    mf_pairs_row(c->v, i, c->jmask, ls3_pair, c, &a);
    if (c->extra) {
        a.c = c;
        c->extra(c->extra_ctx, i, ls_extra_point, &a);
    }
    double x[LS_MAX][LS_COMP];
    if (!ls_solve(&a, c->nb, 3, x)) {
        c->failed[i] = 1;
        return;
    }
    c->failed[i] = 0;
    /* the squares' coefficients: 2-D x^2 at 2, y^2 at 4; 3-D at 3, 6, 8 */
    static const int sq2[2] = {2, 4}, sq3[3] = {3, 6, 8};
    const int *sq = c->dim == 2 ? sq2 : sq3;
    const double s = 2.0 * c->inv_l0 * c->inv_l0;
    for (int q = 0; q < 3; q++) {
        double lap = 0.0;
        for (int d = 0; d < c->dim; d++)
            lap += x[sq[d]][q];
        c->out[3 * i + q] += c->scale * (s * lap);
    }
}

static size_t count_failed(const mf_pairs *v, const uint8_t *imask, const uint8_t *failed)
{
    size_t n = 0;
    for (size_t i = 0; i < v->ni; i++)
        n += (!imask || imask[i]) && failed[i];
    return n;
}

size_t mf_lsmps_gradient(const mf_pairs *v, const mf_kernel *k, const double *f,
                         const uint8_t *imask, const uint8_t *jmask, double *out,
                         uint8_t *failed)
{
    const ls_ctx c = {.v = v, .jmask = jmask, .f = f, .dim = k->dim,
                      .nb = k->dim == 2 ? 5 : 9, .inv_l0 = 1.0 / k->l0, .out = out,
                      .failed = failed};
    mf_pairs_each(v, imask, grad_row, &c);
    return count_failed(v, imask, failed);
}

size_t mf_lsmps_laplacian_add(const mf_pairs *v, const mf_kernel *k, const double *u,
                              double scale, const uint8_t *imask, const uint8_t *jmask,
                              double *out, uint8_t *failed)
{
    return mf_lsmps_laplacian_add_extra(v, k, u, scale, imask, jmask, NULL, NULL, out, failed);
}

size_t mf_lsmps_laplacian_add_extra(const mf_pairs *v, const mf_kernel *k, const double *u,
                                    double scale, const uint8_t *imask, const uint8_t *jmask,
                                    mf_lsmps_extra_fn extra, const void *extra_ctx, double *out,
                                    uint8_t *failed)
{
    const ls_ctx c = {.v = v, .jmask = jmask, .f = u, .dim = k->dim,
                      .nb = k->dim == 2 ? 5 : 9, .inv_l0 = 1.0 / k->l0, .scale = scale,
                      .out = out, .failed = failed, .extra = extra, .extra_ctx = extra_ctx};
    mf_pairs_each(v, imask, lap_row, &c);
    return count_failed(v, imask, failed);
}
