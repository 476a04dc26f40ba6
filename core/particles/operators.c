/* operators.c: the MPS operators of mf_operators.h as pair kernels (the
 * terms of mf_kernel.h) handed to the pair engine (mf_pairs.h). Each
 * operator is a kernel (one pair into a per-i accumulator) and a row
 * function (the accumulator into the output: the apply sink); the engine
 * owns the loops. */
#include "mf_operators.h"

#include <math.h>

/* ---- number density ------------------------------------------------------ */

typedef struct {
    const mf_pairs *v;
    const uint8_t *jmask;
    double *out;
} nd_ctx;

static inline bool nd_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const nd_ctx *c = ctx;
    *(double *)acc += mf_weight(pr->len, c->v->radius);
    return true;
}

static void nd_row(const void *ctx, size_t i)
{
    const nd_ctx *c = ctx;
    double sum = 0.0;
    mf_pairs_row(c->v, i, c->jmask, nd_pair, c, &sum);
    c->out[i] = sum;
}

/* The same with every neighbour (jmask NULL, a literal: no test a pair). */
static void nd_row_all(const void *ctx, size_t i)
{
    const nd_ctx *c = ctx;
    double sum = 0.0;
    mf_pairs_row(c->v, i, NULL, nd_pair, c, &sum);
    c->out[i] = sum;
}

void mf_number_density(const mf_pairs *v, const uint8_t *imask, const uint8_t *jmask,
                       double *n)
{
    const nd_ctx c = {v, jmask, n};
    mf_pairs_each(v, imask, jmask ? nd_row : nd_row_all, &c);
}

/* ---- gradient ------------------------------------------------------------ */

typedef struct {
    const mf_pairs *v;
    const mf_gradient_opts *o;
    const uint8_t *jmask;
    double coef; /* d / n0_g */
    int weight;  /* mf_grad_weight */
    double *out;
} grad_ctx;

typedef struct {
    double fhat;
    double g[3];
} grad_acc;

/* p_min: the smallest f of the neighbourhood. */
static inline bool min_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const grad_ctx *c = ctx;
    double *fhat = acc;
    const double fj = c->o->f[pr->j];
    if (fj < *fhat)
        *fhat = fj;
    return true;
}

/* The pair coefficient c_ij of the gradient: 1, a constant, or 1/rho_ij
 * (a literal at the call sites: each compiles to its own loop). */
enum { COEF_ONE, COEF_CONSTANT, COEF_RHO };

/* shape: the weight's (mf_grad_weight), or SHAPE_OF_CTX for c->weight's
 * (a literal: the paper's weight compiles to a loop without the test). */
#define SHAPE_OF_CTX (-1)

static inline bool grad_pair_as(void *acc, const void *ctx, const mf_pair *pr, int mode,
                                int shape)
{
    const grad_ctx *c = ctx;
    const mf_gradient_opts *o = c->o;
    grad_acc *a = acc;
    if (pr->len <= 0.0)
        return true; /* coincident particles carry no direction */
    const double cij = mode == COEF_RHO ? mf_inv_rho_pair(o->rho[pr->i], o->rho[pr->j],
                                                          o->rho_average)
                       : mode == COEF_CONSTANT ? o->coef
                                               : 1.0;
    const double s = mf_gradient_term(
        o->f[pr->j] - a->fhat, cij,
        mf_weight_gradient(pr->len, c->v->radius, shape == SHAPE_OF_CTX ? c->weight : shape),
        pr->len);
    a->g[0] += s * pr->r[0];
    a->g[1] += s * pr->r[1];
    a->g[2] += s * pr->r[2];
    return true;
}

static inline bool grad_pair(void *acc, const void *ctx, const mf_pair *pr, int mode)
{
    return grad_pair_as(acc, ctx, pr, mode, SHAPE_OF_CTX);
}

static inline bool grad_pair_one(void *acc, const void *ctx, const mf_pair *pr)
{
    return grad_pair(acc, ctx, pr, COEF_ONE);
}

static inline bool grad_pair_one_paper(void *acc, const void *ctx, const mf_pair *pr)
{
    return grad_pair_as(acc, ctx, pr, COEF_ONE, MF_GRAD_WEIGHT_PAPER);
}

static inline bool grad_pair_constant(void *acc, const void *ctx, const mf_pair *pr)
{
    return grad_pair(acc, ctx, pr, COEF_CONSTANT);
}

static inline bool grad_pair_rho(void *acc, const void *ctx, const mf_pair *pr)
{
    return grad_pair(acc, ctx, pr, COEF_RHO);
}

/* The corrected gradient (CMPS, Khayyer & Gotoh 2008, Coastal Eng. 55,
 * 236-250, eq. 11): ((f_i + f_j) - (f^_i + f^_j)) c_ij w / |r_ij|^2 r_ij,
 * antisymmetric in i and j, so that the pair forces cancel (linear and
 * angular momentum). f^ is o->fhat (mf_neighbour_min). */
static inline bool cgrad_pair(void *acc, const void *ctx, const mf_pair *pr, int mode)
{
    const grad_ctx *c = ctx;
    const mf_gradient_opts *o = c->o;
    grad_acc *a = acc;
    if (pr->len <= 0.0)
        return true;
    const double cij = mode == COEF_RHO ? mf_inv_rho_pair(o->rho[pr->i], o->rho[pr->j],
                                                          o->rho_average)
                       : mode == COEF_CONSTANT ? o->coef
                                               : 1.0;
    const double df = (o->f[pr->i] + o->f[pr->j]) - (o->fhat[pr->i] + o->fhat[pr->j]);
    const double s =
        mf_gradient_term(df, cij, mf_weight_gradient(pr->len, c->v->radius, c->weight), pr->len);
    a->g[0] += s * pr->r[0];
    a->g[1] += s * pr->r[1];
    a->g[2] += s * pr->r[2];
    return true;
}

static inline bool cgrad_pair_one(void *acc, const void *ctx, const mf_pair *pr)
{
    return cgrad_pair(acc, ctx, pr, COEF_ONE);
}

static inline bool cgrad_pair_constant(void *acc, const void *ctx, const mf_pair *pr)
{
    return cgrad_pair(acc, ctx, pr, COEF_CONSTANT);
}

static inline bool cgrad_pair_rho(void *acc, const void *ctx, const mf_pair *pr)
{
    return cgrad_pair(acc, ctx, pr, COEF_RHO);
}

static inline void cgrad_row(const void *ctx, size_t i, int mode)
{
    const grad_ctx *c = ctx;
    grad_acc a = {0.0, {0.0, 0.0, 0.0}};
    if (mode == COEF_RHO)
        mf_pairs_row(c->v, i, c->jmask, cgrad_pair_rho, c, &a);
    else if (mode == COEF_CONSTANT)
        mf_pairs_row(c->v, i, c->jmask, cgrad_pair_constant, c, &a);
    else
        mf_pairs_row(c->v, i, c->jmask, cgrad_pair_one, c, &a);
    c->out[3 * i + 0] = c->coef * a.g[0];
    c->out[3 * i + 1] = c->coef * a.g[1];
    c->out[3 * i + 2] = c->coef * a.g[2];
}

static void cgrad_row_one(const void *ctx, size_t i) { cgrad_row(ctx, i, COEF_ONE); }
static void cgrad_row_constant(const void *ctx, size_t i) { cgrad_row(ctx, i, COEF_CONSTANT); }
static void cgrad_row_rho(const void *ctx, size_t i) { cgrad_row(ctx, i, COEF_RHO); }

/* mode: COEF_*; paper: the paper's weight (with COEF_ONE only). */
static inline __attribute__((always_inline)) void grad_row_as(const void *ctx, size_t i,
                                                              int mode, bool paper)
{
    const grad_ctx *c = ctx;
    const mf_gradient_opts *o = c->o;
    grad_acc a = {o->f[i], {0.0, 0.0, 0.0}};
    if (o->use_min && !(o->own_reference && o->own_reference[i]))
        mf_pairs_row_r2(c->v, i, c->jmask, min_pair, c, &a.fhat);
    if (mode == COEF_RHO)
        mf_pairs_row(c->v, i, c->jmask, grad_pair_rho, c, &a);
    else if (mode == COEF_CONSTANT)
        mf_pairs_row(c->v, i, c->jmask, grad_pair_constant, c, &a);
    else if (paper)
        mf_pairs_row(c->v, i, c->jmask, grad_pair_one_paper, c, &a);
    else
        mf_pairs_row(c->v, i, c->jmask, grad_pair_one, c, &a);
    c->out[3 * i + 0] = c->coef * a.g[0];
    c->out[3 * i + 1] = c->coef * a.g[1];
    c->out[3 * i + 2] = c->coef * a.g[2];
}

static inline void grad_row(const void *ctx, size_t i, int mode)
{
    grad_row_as(ctx, i, mode, false);
}

static void grad_row_one(const void *ctx, size_t i) { grad_row(ctx, i, COEF_ONE); }
static void grad_row_one_paper(const void *ctx, size_t i) { grad_row_as(ctx, i, COEF_ONE, true); }
static void grad_row_constant(const void *ctx, size_t i) { grad_row(ctx, i, COEF_CONSTANT); }
static void grad_row_rho(const void *ctx, size_t i) { grad_row(ctx, i, COEF_RHO); }

void mf_gradient_ex(const mf_pairs *v, const mf_kernel *k, const mf_gradient_opts *o,
                    const uint8_t *imask, const uint8_t *jmask, double *out)
{
    const grad_ctx c = {v, o, jmask, k->dim / k->n0_grad, k->grad_weight, out};
    if (o->fhat) { /* corrected (CMPS) */
        if (o->rho)
            mf_pairs_each(v, imask, cgrad_row_rho, &c);
        else if (o->coef == 1.0)
            mf_pairs_each(v, imask, cgrad_row_one, &c);
        else
            mf_pairs_each(v, imask, cgrad_row_constant, &c);
    } else if (o->rho)
        mf_pairs_each(v, imask, grad_row_rho, &c);
    else if (o->coef == 1.0 && c.weight == MF_GRAD_WEIGHT_PAPER)
        mf_pairs_each(v, imask, grad_row_one_paper, &c);
    else if (o->coef == 1.0)
        mf_pairs_each(v, imask, grad_row_one, &c);
    else
        mf_pairs_each(v, imask, grad_row_constant, &c);
}

void mf_gradient(const mf_pairs *v, const mf_kernel *k, const double *f, bool use_min,
                 const uint8_t *imask, const uint8_t *jmask, double *out)
{
    const mf_gradient_opts o = {.f = f, .use_min = use_min, .coef = 1.0};
    mf_gradient_ex(v, k, &o, imask, jmask, out);
}

/* f^_i: f_i, or the minimum of f over i and its neighbours (the p_min of
 * eq. 5), except for the particles of own_reference. */
typedef struct {
    const mf_pairs *v;
    const double *f;
    const uint8_t *jmask, *own_reference;
    bool use_min;
    double *out;
} min_ctx;

static inline bool fmin_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const min_ctx *c = ctx;
    double *fhat = acc;
    const double fj = c->f[pr->j];
    if (fj < *fhat)
        *fhat = fj;
    return true;
}

static void fmin_row(const void *ctx, size_t i)
{
    const min_ctx *c = ctx;
    double fhat = c->f[i];
    if (c->use_min && !(c->own_reference && c->own_reference[i]))
        mf_pairs_row_r2(c->v, i, c->jmask, fmin_pair, c, &fhat);
    c->out[i] = fhat;
}

void mf_neighbour_min(const mf_pairs *v, const double *f, bool use_min,
                      const uint8_t *own_reference, const uint8_t *imask, const uint8_t *jmask,
                      double *fhat)
{
    const min_ctx c = {v, f, jmask, own_reference, use_min, fhat};
    mf_pairs_each(v, imask, fmin_row, &c);
}

/* ---- Laplacian ----------------------------------------------------------- */

typedef struct {
    const mf_pairs *v;
    const uint8_t *jmask;
    const double *f;
    int ncomp;
    double coef;  /* 2d / (lambda n0) */
    double scale; /* mf_laplacian_add */
    /* mf_laplacian_mu */
    const double *mu, *rho;
    const uint8_t *mu_mask;
    int mu_average;
    int dim;      /* the higher-order Laplacian's weight */
    double *out;
} lap_ctx;

/* c_ij (f_j - f_i) w for ncomp components (literals at the call sites, as
 * hl); c_ij = 1, or mu_ij with a pair viscosity; w the weight of eq. 3, or
 * with hl that of the higher-order Laplacian (mf_weight_hl). Always
 * inlined: with nine callers GCC kept one generic copy, called once a pair
 * with ncomp, mu and hl tested at run time (a third of the viscous term's
 * instructions on the bench 2-D case, docs/notes/speed.md). */
static inline __attribute__((always_inline)) bool lap_pair_as(void *acc, const void *ctx,
                                                              const mf_pair *pr, int ncomp,
                                                              bool mu, bool hl)
{
    const lap_ctx *c = ctx;
    double *a = acc;
    const double w = hl ? mf_weight_hl(pr->len, c->v->radius, c->dim)
                        : mf_weight(pr->len, c->v->radius);
    if (w <= 0.0)
        return true; /* its term is zero */
    const size_t i = pr->i, j = pr->j;
    double cij = 1.0;
    if (mu)
        cij = c->mu_mask[j] ? mf_mu_pair(c->mu[i], c->mu[j], c->mu_average) : c->mu[i];
    const double *f = c->f;
    if (ncomp == 3) { /* written out: the sums stay in registers */
        a[0] += mf_laplacian_term(cij, f[3 * j] - f[3 * i], w);
        a[1] += mf_laplacian_term(cij, f[3 * j + 1] - f[3 * i + 1], w);
        a[2] += mf_laplacian_term(cij, f[3 * j + 2] - f[3 * i + 2], w);
    } else {
        a[0] += mf_laplacian_term(cij, f[j] - f[i], w);
    }
    return true;
}

static inline bool lap_pair(void *acc, const void *ctx, const mf_pair *pr, int ncomp, bool mu)
{
    return lap_pair_as(acc, ctx, pr, ncomp, mu, false);
}

static inline bool lap1_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    return lap_pair(acc, ctx, pr, 1, false);
}

static inline bool lap3_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    return lap_pair(acc, ctx, pr, 3, false);
}

static inline bool lap3_mu_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    return lap_pair(acc, ctx, pr, 3, true);
}

static void lap1_row(const void *ctx, size_t i)
{
    const lap_ctx *c = ctx;
    double a = 0.0;
    mf_pairs_row(c->v, i, c->jmask, lap1_pair, c, &a);
    c->out[i] = c->coef * a;
}

static void lap3_row(const void *ctx, size_t i)
{
    const lap_ctx *c = ctx;
    double a[3] = {0.0, 0.0, 0.0};
    mf_pairs_row(c->v, i, c->jmask, lap3_pair, c, a);
    for (int q = 0; q < 3; q++)
        c->out[3 * i + q] = c->coef * a[q];
}

static inline __attribute__((always_inline)) void lap3_add_row_as(const void *ctx, size_t i,
                                                                  const uint8_t *jmask)
{
    const lap_ctx *c = ctx;
    double a[3] = {0.0, 0.0, 0.0};
    mf_pairs_row(c->v, i, jmask, lap3_pair, c, a);
    for (int q = 0; q < 3; q++) {
        const double lap = c->coef * a[q];
        c->out[3 * i + q] += c->scale * lap;
    }
}

static void lap3_add_row(const void *ctx, size_t i)
{
    lap3_add_row_as(ctx, i, ((const lap_ctx *)ctx)->jmask);
}

/* The same with every neighbour (jmask NULL, a literal: no test a pair). */
static void lap3_add_row_all(const void *ctx, size_t i)
{
    lap3_add_row_as(ctx, i, NULL);
}

static void lap3_mu_row(const void *ctx, size_t i)
{
    const lap_ctx *c = ctx;
    double a[3] = {0.0, 0.0, 0.0};
    mf_pairs_row(c->v, i, NULL, lap3_mu_pair, c, a);
    for (int q = 0; q < 3; q++)
        c->out[3 * i + q] += c->coef * a[q] / c->rho[i];
}

/* ---- the higher-order Laplacian (mf_weight_hl) ---------------------------- */

static inline bool hl1_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    return lap_pair_as(acc, ctx, pr, 1, false, true);
}

static inline bool hl3_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    return lap_pair_as(acc, ctx, pr, 3, false, true);
}

static inline bool hl3_mu_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    return lap_pair_as(acc, ctx, pr, 3, true, true);
}

static void hl1_row(const void *ctx, size_t i)
{
    const lap_ctx *c = ctx;
    double a = 0.0;
    mf_pairs_row(c->v, i, c->jmask, hl1_pair, c, &a);
    c->out[i] = c->coef * a;
}

static void hl3_row(const void *ctx, size_t i)
{
    const lap_ctx *c = ctx;
    double a[3] = {0.0, 0.0, 0.0};
    mf_pairs_row(c->v, i, c->jmask, hl3_pair, c, a);
    for (int q = 0; q < 3; q++)
        c->out[3 * i + q] = c->coef * a[q];
}

static void hl3_add_row(const void *ctx, size_t i)
{
    const lap_ctx *c = ctx;
    double a[3] = {0.0, 0.0, 0.0};
    mf_pairs_row(c->v, i, c->jmask, hl3_pair, c, a);
    for (int q = 0; q < 3; q++)
        c->out[3 * i + q] += c->scale * (c->coef * a[q]);
}

static void hl3_mu_row(const void *ctx, size_t i)
{
    const lap_ctx *c = ctx;
    double a[3] = {0.0, 0.0, 0.0};
    mf_pairs_row(c->v, i, NULL, hl3_mu_pair, c, a);
    for (int q = 0; q < 3; q++)
        c->out[3 * i + q] += c->coef * a[q] / c->rho[i];
}

void mf_laplacian_hl(const mf_pairs *v, const mf_kernel *k, const double *f, int ncomp,
                     const uint8_t *imask, const uint8_t *jmask, double *out)
{
    const lap_ctx c = {.v = v, .jmask = jmask, .f = f, .ncomp = ncomp, .coef = k->hl_coef,
                       .dim = k->dim, .out = out};
    if (ncomp == 3)
        mf_pairs_each(v, imask, hl3_row, &c);
    else
        mf_pairs_each(v, imask, hl1_row, &c);
}

void mf_laplacian_hl_add(const mf_pairs *v, const mf_kernel *k, const double *f, double scale,
                         const uint8_t *imask, const uint8_t *jmask, double *out)
{
    const lap_ctx c = {.v = v, .jmask = jmask, .f = f, .ncomp = 3, .coef = k->hl_coef,
                       .scale = scale, .dim = k->dim, .out = out};
    mf_pairs_each(v, imask, hl3_add_row, &c);
}

void mf_laplacian_hl_mu(const mf_pairs *v, const mf_kernel *k, const double *f, const double *mu,
                        int mu_average, const uint8_t *mu_mask, const double *rho,
                        const uint8_t *imask, double *out)
{
    const lap_ctx c = {.v = v, .f = f, .ncomp = 3, .coef = k->hl_coef, .mu = mu, .rho = rho,
                       .mu_mask = mu_mask, .mu_average = mu_average, .dim = k->dim, .out = out};
    mf_pairs_each(v, imask, hl3_mu_row, &c);
}

static double lap_coef(const mf_kernel *k)
{
    return 2.0 * k->dim / (k->lambda * k->n0);
}

void mf_laplacian(const mf_pairs *v, const mf_kernel *k, const double *f, int ncomp,
                  const uint8_t *imask, const uint8_t *jmask, double *out)
{
    const lap_ctx c = {.v = v, .jmask = jmask, .f = f, .ncomp = ncomp, .coef = lap_coef(k),
                       .out = out};
    if (ncomp == 3)
        mf_pairs_each(v, imask, lap3_row, &c);
    else
        mf_pairs_each(v, imask, lap1_row, &c);
}

void mf_laplacian_add(const mf_pairs *v, const mf_kernel *k, const double *f, double scale,
                      const uint8_t *imask, const uint8_t *jmask, double *out)
{
    const lap_ctx c = {.v = v, .jmask = jmask, .f = f, .ncomp = 3, .coef = lap_coef(k),
                       .scale = scale, .out = out};
    mf_pairs_each(v, imask, jmask ? lap3_add_row : lap3_add_row_all, &c);
}

/* The number density and, in the same pass over each row, the viscous
 * term: each sum gets the pairs in the order the two operators alone give
 * them (a pair of zero weight adds nothing to either), so the results are
 * theirs bit for bit. */
typedef struct {
    lap_ctx lap;              /* mf_laplacian_add's (jmask NULL) */
    const uint8_t *lmask;     /* rows that also want the Laplacian */
    double *n;
} lap_nd_ctx;

typedef struct {
    double a[3];
    double n;
} lap_nd_acc;

static inline bool lap3_nd_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const lap_nd_ctx *c = ctx;
    lap_nd_acc *s = acc;
    s->n += mf_weight(pr->len, c->lap.v->radius);
    return lap3_pair(s->a, &c->lap, pr);
}

static void lap3_add_nd_row(const void *ctx, size_t i)
{
    const lap_nd_ctx *c = ctx;
    if (!c->lmask[i]) {
        const nd_ctx nd = {c->lap.v, NULL, c->n};
        nd_row(&nd, i);
        return;
    }
    lap_nd_acc s = {{0.0, 0.0, 0.0}, 0.0};
    mf_pairs_row(c->lap.v, i, NULL, lap3_nd_pair, c, &s);
    c->n[i] = s.n;
    for (int q = 0; q < 3; q++) {
        const double lap = c->lap.coef * s.a[q];
        c->lap.out[3 * i + q] += c->lap.scale * lap;
    }
}

void mf_laplacian_add_number_density(const mf_pairs *v, const mf_kernel *k, const double *f,
                                     double scale, const uint8_t *imask, const uint8_t *lmask,
                                     double *out, double *n)
{
    const lap_nd_ctx c = {{.v = v, .jmask = NULL, .f = f, .ncomp = 3, .coef = lap_coef(k),
                           .scale = scale, .out = out},
                          lmask, n};
    mf_pairs_each(v, imask, lap3_add_nd_row, &c);
}

void mf_laplacian_mu(const mf_pairs *v, const mf_kernel *k, const double *f, const double *mu,
                     int mu_average, const uint8_t *mu_mask, const double *rho,
                     const uint8_t *imask, double *out)
{
    const lap_ctx c = {.v = v, .f = f, .ncomp = 3, .coef = lap_coef(k), .mu = mu, .rho = rho,
                       .mu_mask = mu_mask, .mu_average = mu_average, .out = out};
    mf_pairs_each(v, imask, lap3_mu_row, &c);
}

/* ---- divergence ---------------------------------------------------------- */

typedef struct {
    const mf_pairs *v;
    const uint8_t *jmask;
    const double *u;
    double coef;
    double *out;
} div_ctx;

static inline bool div_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const div_ctx *c = ctx;
    if (pr->len <= 0.0)
        return true;
    const double *ui = c->u + 3 * pr->i, *uj = c->u + 3 * pr->j;
    const double du = (uj[0] - ui[0]) * pr->r[0] + (uj[1] - ui[1]) * pr->r[1] +
                      (uj[2] - ui[2]) * pr->r[2];
    *(double *)acc += mf_divergence_term(du, mf_weight(pr->len, c->v->radius), pr->len);
    return true;
}

static void div_row(const void *ctx, size_t i)
{
    const div_ctx *c = ctx;
    double sum = 0.0;
    mf_pairs_row(c->v, i, c->jmask, div_pair, c, &sum);
    c->out[i] = c->coef * sum;
}

void mf_divergence(const mf_pairs *v, const mf_kernel *k, const double *u,
                   const uint8_t *imask, const uint8_t *jmask, double *out)
{
    const div_ctx c = {v, jmask, u, k->dim / k->n0, out};
    mf_pairs_each(v, imask, div_row, &c);
}

/* ---- rate of the number density (Khayyer & Gotoh 2009) ------------------- */

typedef struct {
    const mf_pairs *v;
    const uint8_t *jmask;
    const double *u;
    double *out;
} rate_ctx;

static inline bool rate_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const rate_ctx *c = ctx;
    const double *ui = c->u + 3 * pr->i, *uj = c->u + 3 * pr->j;
    const double du = (uj[0] - ui[0]) * pr->r[0] + (uj[1] - ui[1]) * pr->r[1] +
                      (uj[2] - ui[2]) * pr->r[2];
    *(double *)acc += mf_weight_rate_term(du, pr->len, c->v->radius);
    return true;
}

static void rate_row(const void *ctx, size_t i)
{
    const rate_ctx *c = ctx;
    double sum = 0.0;
    mf_pairs_row(c->v, i, c->jmask, rate_pair, c, &sum);
    c->out[i] = sum;
}

void mf_number_density_rate(const mf_pairs *v, const double *u, const uint8_t *imask,
                            const uint8_t *jmask, double *out)
{
    const rate_ctx c = {v, jmask, u, out};
    mf_pairs_each(v, imask, rate_row, &c);
}

/* ---- sums of directions: asymmetry, concentration gradient --------------- */

typedef struct {
    const mf_pairs *v;
    const uint8_t *jmask;
    double coef;
    double *out;
} dir_ctx;

/* r_ij/|r_ij| w_ij (unit) or r_ij w_ij/|r_ij|^2 (inverse) (a literal). */
static inline bool dir_pair(void *acc, const void *ctx, const mf_pair *pr, bool inverse)
{
    const dir_ctx *c = ctx;
    double *a = acc;
    if (pr->len <= 0.0)
        return true;
    const double w = mf_weight(pr->len, c->v->radius);
    const double s = inverse ? w / pr->r2 : w / pr->len;
    a[0] += s * pr->r[0];
    a[1] += s * pr->r[1];
    a[2] += s * pr->r[2];
    return true;
}

static inline bool unit_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    return dir_pair(acc, ctx, pr, false);
}

static inline bool inverse_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    return dir_pair(acc, ctx, pr, true);
}

static void unit_row(const void *ctx, size_t i)
{
    const dir_ctx *c = ctx;
    double a[3] = {0.0, 0.0, 0.0};
    mf_pairs_row(c->v, i, c->jmask, unit_pair, c, a);
    for (int q = 0; q < 3; q++)
        c->out[3 * i + q] = c->coef * a[q];
}

static void inverse_row(const void *ctx, size_t i)
{
    const dir_ctx *c = ctx;
    double a[3] = {0.0, 0.0, 0.0};
    mf_pairs_row(c->v, i, c->jmask, inverse_pair, c, a);
    for (int q = 0; q < 3; q++)
        c->out[3 * i + q] = c->coef * a[q];
}

void mf_neighbour_asymmetry(const mf_pairs *v, const mf_kernel *k, const uint8_t *imask,
                            const uint8_t *jmask, double *out)
{
    const dir_ctx c = {v, jmask, 1.0 / k->n0, out};
    mf_pairs_each(v, imask, unit_row, &c);
}

/* The number density and, in the same pass over each row, the asymmetry:
 * each sum gets the pairs in the order the two operators alone give them,
 * so the results are theirs bit for bit. */
typedef struct {
    dir_ctx dir;              /* the asymmetry's (jmask NULL) */
    const uint8_t *amask;     /* rows that also want the asymmetry */
    double *n;
} nd_asym_ctx;

typedef struct {
    double n;
    double a[3];
} nd_asym_acc;

static inline bool nd_asym_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const nd_asym_ctx *c = ctx;
    nd_asym_acc *s = acc;
    s->n += mf_weight(pr->len, c->dir.v->radius);
    return unit_pair(s->a, &c->dir, pr);
}

static void nd_asym_row(const void *ctx, size_t i)
{
    const nd_asym_ctx *c = ctx;
    if (!c->amask[i]) {
        const nd_ctx nd = {c->dir.v, NULL, c->n};
        nd_row(&nd, i);
        return;
    }
    nd_asym_acc s = {0.0, {0.0, 0.0, 0.0}};
    mf_pairs_row(c->dir.v, i, NULL, nd_asym_pair, c, &s);
    c->n[i] = s.n;
    for (int q = 0; q < 3; q++)
        c->dir.out[3 * i + q] = c->dir.coef * s.a[q];
}

void mf_number_density_asymmetry(const mf_pairs *v, const mf_kernel *k, const uint8_t *imask,
                                 const uint8_t *amask, double *n, double *asym)
{
    const nd_asym_ctx c = {{v, NULL, 1.0 / k->n0, asym}, amask, n};
    mf_pairs_each(v, imask, nd_asym_row, &c);
}

void mf_concentration_gradient(const mf_pairs *v, const mf_kernel *k, const uint8_t *imask,
                               const uint8_t *jmask, double *out)
{
    const dir_ctx c = {v, jmask, k->dim / k->n0, out};
    mf_pairs_each(v, imask, inverse_row, &c);
}

/* ---- velocity gradient ----------------------------------------------------- */

typedef struct {
    const mf_pairs *v;
    const uint8_t *jmask;
    const double *u;
    double coef;
    double *out;
} vgrad_ctx;

static inline bool vgrad_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const vgrad_ctx *c = ctx;
    double *g = acc;
    if (pr->len <= 0.0)
        return true;
    const double s = mf_weight(pr->len, c->v->radius) / pr->r2;
    const double *ui = c->u + 3 * pr->i, *uj = c->u + 3 * pr->j;
    for (int a = 0; a < 3; a++) {
        const double du = s * (uj[a] - ui[a]);
        g[3 * a + 0] += du * pr->r[0];
        g[3 * a + 1] += du * pr->r[1];
        g[3 * a + 2] += du * pr->r[2];
    }
    return true;
}

static void vgrad_row(const void *ctx, size_t i)
{
    const vgrad_ctx *c = ctx;
    double g[9] = {0};
    mf_pairs_row(c->v, i, c->jmask, vgrad_pair, c, g);
    for (int q = 0; q < 9; q++)
        c->out[9 * i + q] = c->coef * g[q];
}

void mf_velocity_gradient(const mf_pairs *v, const mf_kernel *k, const double *u,
                          const uint8_t *imask, const uint8_t *jmask, double *out)
{
    const vgrad_ctx c = {v, jmask, u, k->dim / k->n0, out};
    mf_pairs_each(v, imask, vgrad_row, &c);
}

/* ---- collision ----------------------------------------------------------- */

typedef struct {
    const mf_pairs *v;
    const uint8_t *movable;
    const double *rho, *vel;
    double e;
    double *out;
} coll_ctx;

/* One approaching pair: i's velocity (acc) loses the share of j's mass of
 * (1 + e) times the approach speed along r_ij. */
static inline bool coll_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const coll_ctx *c = ctx;
    double *vi = acc;
    if (pr->r2 <= 0)
        return true;
    const double len = pr->len, *vj = c->vel + 3 * pr->j, *r = pr->r;
    double approach = 0;
    approach += (vi[0] - vj[0]) * r[0] / len;
    approach += (vi[1] - vj[1]) * r[1] / len;
    approach += (vi[2] - vj[2]) * r[2] / len;
    if (approach <= 0)
        return true;
    const size_t i = pr->i, j = pr->j;
    const double share = !c->movable[j] ? 1.0
                         : c->rho       ? c->rho[j] / (c->rho[i] + c->rho[j])
                                        : 0.5;
    vi[0] -= share * (1 + c->e) * approach * r[0] / len;
    vi[1] -= share * (1 + c->e) * approach * r[1] / len;
    vi[2] -= share * (1 + c->e) * approach * r[2] / len;
    return true;
}

static void coll_row(const void *ctx, size_t i)
{
    const coll_ctx *c = ctx;
    double vi[3] = {c->vel[3 * i], c->vel[3 * i + 1], c->vel[3 * i + 2]};
    mf_pairs_row(c->v, i, NULL, coll_pair, c, vi);
    for (int q = 0; q < 3; q++)
        c->out[3 * i + q] = vi[q];
}

void mf_collision(const mf_pairs *v, const uint8_t *movable, const double *rho, double e,
                  const double *vel, double *out)
{
    const coll_ctx c = {v, movable, rho, vel, e, out};
    mf_pairs_each(v, movable, coll_row, &c);
}

void mf_free_surface(const double *n, size_t count, double beta, double n0, uint8_t *flag)
{
    for (size_t i = 0; i < count; i++)
        flag[i] = n[i] < beta * n0;
}
