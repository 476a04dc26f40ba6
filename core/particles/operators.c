/* operators.c: neighbour loops of the MPS operators. The pair physics is in
 * the inline helpers below and in mf_kernel.h; nothing here walks cells. */
#include "mf_operators.h"

#include <math.h>

/* r_ij = r_j - r_i and its length. */
static inline double pair_vector(const double *xi, const double *xj, double d[3])
{
    d[0] = xj[0] - xi[0];
    d[1] = xj[1] - xi[1];
    d[2] = xj[2] - xi[2];
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

static inline bool selected(const uint8_t *mask, size_t i) { return !mask || mask[i]; }

void mf_number_density(const mf_particles *p, const mf_nlist *nl, const uint8_t *imask,
                       const uint8_t *jmask, double *n)
{
    const double re = nl->radius;
    const long np = (long)p->n_owned;
#pragma omp parallel for schedule(static)
    for (long i = 0; i < np; i++) {
        if (!selected(imask, (size_t)i))
            continue;
        double sum = 0.0, d[3];
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            size_t j = nl->j[k];
            if (selected(jmask, j))
                sum += mf_weight(pair_vector(&p->pos[3 * i], &p->pos[3 * j], d), re);
        }
        n[i] = sum;
    }
}

void mf_gradient(const mf_particles *p, const mf_nlist *nl, const mf_kernel *kn, const double *f,
                 bool use_min, const uint8_t *imask, const uint8_t *jmask, double *out)
{
    const double re = nl->radius, coef = kn->dim / kn->n0;
    const long np = (long)p->n_owned;
#pragma omp parallel for schedule(static)
    for (long i = 0; i < np; i++) {
        if (!selected(imask, (size_t)i))
            continue;
        double fi = f[i];
        if (use_min)
            for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
                size_t j = nl->j[k];
                if (selected(jmask, j) && f[j] < fi)
                    fi = f[j];
            }
        double g[3] = {0.0, 0.0, 0.0}, d[3];
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            size_t j = nl->j[k];
            if (!selected(jmask, j))
                continue;
            double r = pair_vector(&p->pos[3 * i], &p->pos[3 * j], d);
            if (r <= 0.0)
                continue; /* coincident particles carry no direction */
            double s = (f[j] - fi) * mf_weight(r, re) / (r * r);
            g[0] += s * d[0];
            g[1] += s * d[1];
            g[2] += s * d[2];
        }
        out[3 * i + 0] = coef * g[0];
        out[3 * i + 1] = coef * g[1];
        out[3 * i + 2] = coef * g[2];
    }
}

void mf_laplacian(const mf_particles *p, const mf_nlist *nl, const mf_kernel *kn, const double *f,
                  int ncomp, const uint8_t *imask, const uint8_t *jmask, double *out)
{
    const double re = nl->radius, coef = 2.0 * kn->dim / (kn->lambda * kn->n0);
    const long np = (long)p->n_owned;
#pragma omp parallel for schedule(static)
    for (long i = 0; i < np; i++) {
        if (!selected(imask, (size_t)i))
            continue;
        double acc[3] = {0.0, 0.0, 0.0}, d[3];
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            size_t j = nl->j[k];
            if (!selected(jmask, j))
                continue;
            double w = mf_weight(pair_vector(&p->pos[3 * i], &p->pos[3 * j], d), re);
            for (int c = 0; c < ncomp; c++)
                acc[c] += (f[ncomp * j + c] - f[ncomp * i + c]) * w;
        }
        for (int c = 0; c < ncomp; c++)
            out[ncomp * i + c] = coef * acc[c];
    }
}

void mf_divergence(const mf_particles *p, const mf_nlist *nl, const mf_kernel *kn, const double *u,
                   const uint8_t *imask, const uint8_t *jmask, double *out)
{
    const double re = nl->radius, coef = kn->dim / kn->n0;
    const long np = (long)p->n_owned;
#pragma omp parallel for schedule(static)
    for (long i = 0; i < np; i++) {
        if (!selected(imask, (size_t)i))
            continue;
        double sum = 0.0, d[3];
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            size_t j = nl->j[k];
            if (!selected(jmask, j))
                continue;
            double r = pair_vector(&p->pos[3 * i], &p->pos[3 * j], d);
            if (r <= 0.0)
                continue;
            double du = (u[3 * j] - u[3 * i]) * d[0] + (u[3 * j + 1] - u[3 * i + 1]) * d[1] +
                        (u[3 * j + 2] - u[3 * i + 2]) * d[2];
            sum += du * mf_weight(r, re) / (r * r);
        }
        out[i] = coef * sum;
    }
}

void mf_free_surface(const double *n, size_t count, double beta, double n0, uint8_t *flag)
{
    for (size_t i = 0; i < count; i++)
        flag[i] = n[i] < beta * n0;
}
