/* wall_weight.c: the tables of mf_wall_weight.h, built once from the
 * virtual lattice and read by multilinear interpolation. */
#include "mf_wall_weight.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_kernel.h"
#include "mf_wall_lattice.h"

/* Values stored per node, in the table's frame (constrained axes first). */
enum { V_ZN = 0, V_G = 1, V_M = 4, V_T = 7, NV = 13 };

typedef struct table {
    int c;        /* constrained axes */
    long n;       /* nodes per axis */
    double h;     /* node spacing */
    double *v;    /* n^c nodes x NV */
} table;

struct mf_wall_tables {
    int dim;
    double l0, re_nd, re_grad, re_lap, re_max;
    double d0;      /* offset of the first node (the same on every axis and table) */
    double d_hi;    /* beyond: the term adds nothing */
    double r_min;   /* virtual points closer than this count as this far */
    table tab[3];   /* c = 1, 2, 3 (3-D only) */
};

/* A virtual point at offset v (local frame) into the sums. */
static void add_point(const mf_wall_tables *t, const double v[3], double *out)
{
    const double r = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(r < t->re_max))
        return;
    const double re = r > t->r_min ? r : t->r_min;
    const double wn = mf_weight(re, t->re_nd), wg = mf_weight(re, t->re_grad),
                 wl = mf_weight(re, t->re_lap);
    out[V_ZN] += wn;
    const double gi = wg / (re * re);
    for (int a = 0; a < 3; a++) {
        out[V_G + a] += v[a] * gi;
        out[V_M + a] += v[a] * wl;
    }
    out[V_T + 0] += v[0] * v[0] * gi;
    out[V_T + 1] += v[1] * v[1] * gi;
    out[V_T + 2] += v[2] * v[2] * gi;
    out[V_T + 3] += v[0] * v[1] * gi;
    out[V_T + 4] += v[0] * v[2] * gi;
    out[V_T + 5] += v[1] * v[2] * gi;
}

typedef struct sums_ctx {
    const mf_wall_tables *t;
    double *out;
} sums_ctx;

static void add_lattice_point(void *ctx, const double v[3])
{
    const sums_ctx *s = ctx;
    add_point(s->t, v, s->out);
}

/* The sums of c constrained axes at offsets delta, the dim - c others free,
 * in the local frame, by brute force over the virtual lattice. */
static void local_sums(const mf_wall_tables *t, int c, const double *delta, double *out)
{
    memset(out, 0, NV * sizeof *out);
    sums_ctx s = {t, out};
    mf_wall_lattice_each(t->dim, t->l0, t->re_max, c, delta, add_lattice_point, &s);
}

static int build_table(mf_wall_tables *t, int c, double h)
{
    table *tb = &t->tab[c - 1];
    tb->c = c;
    tb->h = h;
    tb->n = (long)ceil((t->d_hi - t->d0) / h - 1e-9) + 1;
    size_t nodes = 1;
    for (int k = 0; k < c; k++)
        nodes *= (size_t)tb->n;
    tb->v = malloc(nodes * NV * sizeof *tb->v);
    if (!tb->v)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the wall weight tables");
#pragma omp parallel for schedule(dynamic, 16)
    for (size_t node = 0; node < nodes; node++) {
        double delta[3] = {0, 0, 0};
        size_t rest = node;
        for (int k = 0; k < c; k++) {
            delta[k] = t->d0 + (double)(rest % (size_t)tb->n) * h;
            rest /= (size_t)tb->n;
        }
        local_sums(t, c, delta, &tb->v[node * NV]);
    }
    return 0;
}

int mf_wall_tables_create(int dim, double l0, double re_nd, double re_grad, double re_lap,
                          mf_wall_tables **out)
{
    *out = NULL;
    if (dim != 2 && dim != 3)
        return MF_ERROR(MF_ERR_INPUT, "wall weight tables: dimension %d (2 or 3)", dim);
    if (!(l0 > 0) || !(re_nd > 0) || !(re_grad > 0) || !(re_lap > 0))
        return MF_ERROR(MF_ERR_INPUT, "wall weight tables: l0 and the radii must be positive");
    mf_wall_tables *t = calloc(1, sizeof *t);
    if (!t)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    t->dim = dim;
    t->l0 = l0;
    t->re_nd = re_nd;
    t->re_grad = re_grad;
    t->re_lap = re_lap;
    t->re_max = fmax(re_nd, fmax(re_grad, re_lap));
    t->r_min = 0.25 * l0;
    t->d_hi = t->re_max - 0.5 * l0;
    /* The finest spacing h1 divides l0/2, and d0 = l0/2 - K h1 lies past
     * -(free_beyond + l0): every table has its nodes on the lattice offsets. */
    const double h1 = l0 / 32;
    const long K = (long)ceil((0.5 * l0 + t->re_max + 1.5 * l0) / (l0 / 4));
    t->d0 = 0.5 * l0 - (double)K * (l0 / 4);
    int rc = build_table(t, 1, h1);
    if (rc == 0)
        rc = build_table(t, 2, dim == 2 ? l0 / 16 : l0 / 8);
    if (rc == 0 && dim == 3)
        rc = build_table(t, 3, l0 / 4);
    if (rc != 0) {
        mf_wall_tables_destroy(t);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    *out = t;
    return 0;
}

void mf_wall_tables_destroy(mf_wall_tables *t)
{
    if (!t)
        return;
    for (int c = 0; c < 3; c++)
        free(t->tab[c].v);
    free(t);
}

double mf_wall_tables_reach(const mf_wall_tables *t) { return t->d_hi; }

double mf_wall_tables_free_beyond(const mf_wall_tables *t) { return t->re_max + 0.5 * t->l0; }

size_t mf_wall_tables_memory(const mf_wall_tables *t)
{
    size_t bytes = sizeof *t;
    for (int c = 0; c < 3; c++) {
        size_t nodes = t->tab[c].v ? 1 : 0;
        for (int k = 0; k < t->tab[c].c; k++)
            nodes *= (size_t)t->tab[c].n;
        bytes += nodes * NV * sizeof(double);
    }
    return bytes;
}

/* Multilinear interpolation of table c at delta (local frame). */
static void interpolate(const mf_wall_tables *t, int c, const double *delta, double *out)
{
    const table *tb = &t->tab[c - 1];
    long base[3] = {0, 0, 0};
    double f[3] = {0, 0, 0};
    for (int k = 0; k < c; k++) {
        double x = (delta[k] - t->d0) / tb->h;
        if (x < 0) x = 0;
        if (x > (double)(tb->n - 1)) x = (double)(tb->n - 1);
        long b = (long)floor(x);
        if (b > tb->n - 2) b = tb->n - 2;
        base[k] = b;
        f[k] = x - (double)b;
    }
    memset(out, 0, NV * sizeof *out);
    for (int corner = 0; corner < (1 << c); corner++) {
        double wgt = 1;
        size_t node = 0, stride = 1;
        for (int k = 0; k < c; k++) {
            const int up = (corner >> k) & 1;
            wgt *= up ? f[k] : 1 - f[k];
            node += (size_t)(base[k] + up) * stride;
            stride *= (size_t)tb->n;
        }
        if (wgt == 0)
            continue;
        const double *v = &tb->v[node * NV];
        for (int q = 0; q < NV; q++)
            out[q] += wgt * v[q];
    }
}

/* Local sums into the world frame, times sign. */
static void to_world(const mf_wall_tables *t, const mf_wall_term *term, const double *loc,
                     mf_wall_sums *s)
{
    const int c = term->c, dim = t->dim;
    const double sg = term->sign;
    /* the local tensor, symmetric, full */
    const double T[3][3] = {{loc[V_T + 0], loc[V_T + 3], loc[V_T + 4]},
                            {loc[V_T + 3], loc[V_T + 1], loc[V_T + 5]},
                            {loc[V_T + 4], loc[V_T + 5], loc[V_T + 2]}};
    const double tf = c < dim ? T[c][c] : 0; /* each free axis' diagonal */
    s->zn += sg * loc[V_ZN];
    double visc = 0;
    for (int k = 0; k < c; k++) {
        for (int a = 0; a < 3; a++) {
            s->g[a] += sg * loc[V_G + k] * term->e[k][a];
            s->m[a] += sg * loc[V_M + k] * term->e[k][a];
        }
        const double d = term->delta[k] > t->r_min ? term->delta[k] : t->r_min;
        visc += loc[V_M + k] / d;
    }
    if (c > 0)
        s->visc += sg * visc / c;
    /* t = sum_kl T_kl e_k e_l^T + tf (P - sum_k e_k e_k^T), P the identity on
     * the dim axes */
    static const int ia[6] = {0, 1, 2, 0, 0, 1}, ib[6] = {0, 1, 2, 1, 2, 2};
    for (int q = 0; q < 6; q++) {
        const int a = ia[q], b = ib[q];
        if (a >= dim || b >= dim)
            continue;
        double v = a == b ? tf : 0;
        for (int k = 0; k < c; k++) {
            v -= tf * term->e[k][a] * term->e[k][b];
            for (int l = 0; l < c; l++)
                v += T[k][l] * term->e[k][a] * term->e[l][b];
        }
        s->t[q] += sg * v;
    }
}

bool mf_wall_term_add(const mf_wall_tables *t, const mf_wall_term *term, mf_wall_sums *s)
{
    for (int k = 0; k < term->c; k++)
        if (term->delta[k] >= t->d_hi)
            return false;
    double loc[NV];
    if (term->c == 0) /* every axis free: a particle deep inside the wall */
        local_sums(t, 0, term->delta, loc);
    else
        interpolate(t, term->c, term->delta, loc);
    to_world(t, term, loc, s);
    return true;
}

void mf_wall_term_direct(const mf_wall_tables *t, const mf_wall_term *term, mf_wall_sums *s)
{
    double loc[NV];
    local_sums(t, term->c, term->delta, loc);
    to_world(t, term, loc, s);
}
