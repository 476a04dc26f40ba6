/* st_normal.c: the normal model of the curvature, kappa = div n (Brackbill
 * et al. 1992): the interface normals smoothed, then their divergence. */
#include <math.h>
#include <string.h>

#include "surface_tension.h"

static void copy_mark_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    c->d->kappa_s[i] = c->d->fdir[3 * i];
}

typedef struct normal_acc {
    int x;
    double m[3];
} normal_acc;

static inline bool normal_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    normal_acc *a = acc;
    const size_t j = pr->j;
    if (c->p->kind[j] != MF_FLUID)
        return true;
    const double len = pr->len, rst = c->d->r;
    if (len >= rst || len <= 0)
        return true;
    double w = colour_weight(len, rst) * (fluid_of(c->fid, j) == a->x ? 1.0 : -1.0);
    for (int q = 0; q < 3; q++)
        a->m[q] += w * c->d->nrm[3 * j + q];
    return true;
}

static void normal_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    st_data *d = c->d;
    const double *ni = &d->nrm[3 * i];
    normal_acc a = {0, {ni[0], ni[1], ni[2]}};
    if (a.m[0] != 0 || a.m[1] != 0 || a.m[2] != 0) {
        a.x = fluid_of(c->fid, i);
        mf_pairs_row(c->v, i, NULL, normal_pair, c, &a);
        double len = sqrt(a.m[0] * a.m[0] + a.m[1] * a.m[1] + a.m[2] * a.m[2]);
        for (int q = 0; q < 3; q++)
            a.m[q] = len > 0 ? a.m[q] / len : 0.0;
    }
    for (int q = 0; q < 3; q++)
        d->fdir[3 * i + q] = a.m[q];
}

/* The normals averaged over the interface particles within r_st (weight
 * psi, another fluid's normal reversed) and renormalised: on a lattice the
 * raw normals follow the staircase of the particle rows, whose divergence
 * is noise of the order of 1 / l0. kappa_s is the scratch copy. */
void st_smooth_normals(const st_ctx *c)
{
    st_data *d = c->d;
    const long np = (long)c->p->n_owned;
    double *out = d->fdir; /* fdir[3i] (free-surface mark) is saved below */
    double *mark = d->kappa_s;
    mf_pairs_each(c->v, NULL, copy_mark_row, c);
    mf_pairs_each(c->v, NULL, normal_row, c);
    for (long i = 0; i < np; i++) {
        for (int q = 0; q < 3; q++) {
            double t = d->nrm[3 * i + q];
            d->nrm[3 * i + q] = out[3 * i + q];
            out[3 * i + q] = t;
        }
        out[3 * i] = mark[i];
    }
}

/* Inverse of a symmetric 2x2 or 3x3 matrix; false when nearly singular. */
static bool invert_sym(int dim, const double m[3][3], double inv[3][3])
{
    if (dim == 2) {
        double det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        double scale = m[0][0] * m[1][1];
        if (!(fabs(det) > 1e-6 * fabs(scale)) || det == 0)
            return false;
        memset(inv, 0, 9 * sizeof(double));
        inv[0][0] = m[1][1] / det;
        inv[1][1] = m[0][0] / det;
        inv[0][1] = inv[1][0] = -m[0][1] / det;
        return true;
    }
    double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1], c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2],
           c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    double scale = m[0][0] * m[1][1] * m[2][2];
    if (!(fabs(det) > 1e-6 * fabs(scale)) || det == 0)
        return false;
    inv[0][0] = c00 / det;
    inv[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
    inv[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
    inv[1][0] = c01 / det;
    inv[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
    inv[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
    inv[2][0] = c02 / det;
    inv[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
    inv[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
    return true;
}

typedef struct div_acc {
    int x;
    const double *ni;
    double A[3][3], M[3][3];
} div_acc;

static inline bool div_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    div_acc *a = acc;
    const size_t j = pr->j;
    if (c->p->kind[j] != MF_FLUID)
        return true;
    const double *nj = &c->d->nrm[3 * j];
    if (nj[0] == 0 && nj[1] == 0 && nj[2] == 0)
        return true;
    const double len = pr->len, rst = c->d->r, *r = pr->r;
    if (len >= rst || len <= 0)
        return true;
    double sign = fluid_of(c->fid, j) == a->x ? 1.0 : -1.0;
    double w = colour_weight(len, rst) / (len * len);
    const int dim = c->d->dim;
    for (int q = 0; q < dim; q++)
        for (int b = 0; b < dim; b++) {
            a->A[q][b] += w * (sign * nj[q] - a->ni[q]) * r[b];
            a->M[q][b] += w * r[q] * r[b];
        }
    return true;
}

static void div_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    st_data *d = c->d;
    if (isnan(d->kappa[i]))
        return;
    const double *ni = &d->nrm[3 * i];
    if (ni[0] == 0 && ni[1] == 0 && ni[2] == 0) {
        d->kappa[i] = 0;
        return;
    }
    div_acc a = {fluid_of(c->fid, i), ni, {{0}}, {{0}}};
    mf_pairs_row(c->v, i, NULL, div_pair, c, &a);
    const int dim = d->dim;
    const double rst = d->r;
    double inv[3][3];
    double kappa = 0;
    if (invert_sym(dim, a.M, inv))
        for (int q = 0; q < dim; q++)
            for (int b = 0; b < dim; b++)
                kappa += a.A[q][b] * inv[b][q];
    /* A particle cannot resolve a radius below r_st / 2 (the count
     * models' limit too): a corner's normals would ask for more. */
    const double kmax = (dim == 3 ? 4.0 : 2.0) / rst;
    d->kappa[i] = fmax(-kmax, fmin(kmax, kappa));
}

/* curvature normal: kappa = div n (n the outward unit normal; Brackbill et
 * al. 1992) from the MPS gradient (eq. 5) of n over the neighbours that
 * have a normal, corrected by the moment matrix of those neighbours,
 *   grad n = [sum_j psi (n_j - n_i) r_ij^T / r^2] [sum_j psi r_ij r_ij^T / r^2]^-1,
 * psi = (1 - r/r_st)^2, exact for a linear field whatever the neighbours (the
 * interface band is one-sided: the plain MPS divergence reads twice the
 * curvature there). A particle of another fluid contributes minus its normal
 * (the same interface seen from the other side). Insensitive to a change of
 * the particle density, which moves the counts of eq. 39. */
void st_normal_divergence(const st_ctx *c)
{
    mf_pairs_each(c->v, NULL, div_row, c);
}
