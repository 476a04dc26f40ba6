/* test_pairs: the pair engine (core/particles/mf_pairs.h), the MPS pair
 * kernels (operators.c) and the neighbour service (neighbours.c) against
 * brute force, on random sets and lattices in 2-D and 3-D.
 *
 * Brute force here is the O(N^2) search: for each particle every other one,
 * kept when closer than the radius, sorted in the order the service
 * promises (ascending cell key, then index: mf_grid_keys). Each operator is
 * then written out again from its equation, summing over those pairs in
 * that order: the engine's result must be the same bit for bit. Summed in
 * index order instead, it must agree to 1e-12 (relative): the two checks
 * together say that the engine visits exactly the right pairs, in the
 * promised order, and applies the right formula.
 *
 * The service is checked after small moves (the list is kept and re-sorted)
 * and after large ones (rebuilt): the pairs and their order must be those
 * of the brute force at the current positions in both cases. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_kernel.h"
#include "mf_neighbours.h"
#include "mf_operators.h"
#include "mf_pairs.h"
#include "mf_test.h"

static unsigned long long rng = 424242;
static double uniform(void) /* [0, 1) */
{
    rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}

/* n particles uniform in [0, L)^dim, kinds fluid, wall or dummy at random. */
static mf_particles *random_set(int dim, size_t n, double L)
{
    mf_particles *p = NULL;
    if (mf_particles_create(dim, n, &p) != 0)
        return NULL;
    for (size_t k = 0; k < n; k++) {
        double x[3] = {L * uniform(), L * uniform(), dim == 3 ? L * uniform() : 0};
        double v[3] = {uniform() - 0.5, uniform() - 0.5, dim == 3 ? uniform() - 0.5 : 0};
        double u = uniform();
        int kind = u < 0.7 ? MF_FLUID : u < 0.85 ? MF_WALL : MF_DUMMY;
        mf_particles_add(p, kind, x, v, NULL);
    }
    return p;
}

/* A lattice of m^dim points of spacing l0, jittered by jitter l0. */
static mf_particles *lattice_set(int dim, int m, double l0, double jitter)
{
    mf_particles *p = NULL;
    if (mf_particles_create(dim, 1024, &p) != 0)
        return NULL;
    for (int k = 0; k < (dim == 3 ? m : 1); k++)
        for (int j = 0; j < m; j++)
            for (int i = 0; i < m; i++) {
                double x[3] = {i * l0, j * l0, dim == 3 ? k * l0 : 0};
                for (int c = 0; c < dim; c++)
                    x[c] += jitter * l0 * (uniform() - 0.5);
                double v[3] = {uniform() - 0.5, uniform() - 0.5, dim == 3 ? uniform() - 0.5 : 0};
                int kind = (i == 0 || j == 0) ? MF_WALL : (i == 1 || j == 1) ? MF_DUMMY : MF_FLUID;
                mf_particles_add(p, kind, x, v, NULL);
            }
    return p;
}

/* ---- brute force ------------------------------------------------------- */

typedef struct brute {
    size_t n;
    size_t *start; /* n + 1 */
    uint32_t *j;
} brute;

static const uint64_t *sort_keys;
static bool sort_packed;
static int by_key(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    uint64_t kx = sort_keys[x], ky = sort_keys[y];
    if (kx != ky)
        return kx < ky ? -1 : 1;
    return sort_packed ? 0 : (x > y) - (x < y);
}

static double dist2(const mf_particles *p, size_t i, size_t j)
{
    const double *a = &p->pos[3 * i], *b = &p->pos[3 * j];
    double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
    return dx * dx + dy * dy + dz * dz;
}

/* Every pair closer than radius, in (cell key of cell, index) order; or in
 * index order with cell 0. */
static brute brute_pairs(const mf_particles *p, double radius, double cell)
{
    brute b = {p->n, calloc(p->n + 1, sizeof(size_t)), NULL};
    size_t cap = 1024, used = 0;
    b.j = malloc(cap * sizeof *b.j);
    for (size_t i = 0; i < p->n; i++) {
        for (size_t j = 0; j < p->n; j++) {
            if (j == i || !(dist2(p, i, j) < radius * radius))
                continue;
            if (used == cap && mf_resize(&b.j, cap *= 2, sizeof *b.j))
                abort();
            b.j[used++] = (uint32_t)j;
        }
        b.start[i + 1] = used;
    }
    if (cell > 0) {
        uint64_t *keys = malloc((p->n + 1) * sizeof *keys);
        CHECK_OK(mf_grid_keys(p, cell, keys, &sort_packed));
        sort_keys = keys;
        for (size_t i = 0; i < p->n; i++)
            qsort(b.j + b.start[i], b.start[i + 1] - b.start[i], sizeof *b.j, by_key);
        free(keys);
    }
    return b;
}

static void brute_free(brute *b)
{
    free(b->start);
    free(b->j);
}

/* The pairs the engine visits for i, in its order. */
typedef struct seen {
    uint32_t j[4096];
    size_t n;
} seen;

static inline bool collect(void *acc, const void *ctx, const mf_pair *pr)
{
    (void)ctx;
    seen *s = acc;
    if (s->n < 4096)
        s->j[s->n] = (uint32_t)pr->j;
    s->n++;
    return true;
}

/* The view's pairs are the brute force's, in the same order. */
static void check_view(const mf_pairs *v, const brute *b, const char *what)
{
    size_t bad = 0;
    seen s;
    for (size_t i = 0; i < v->ni; i++) {
        s.n = 0;
        mf_pairs_row(v, i, NULL, collect, NULL, &s);
        size_t m = b->start[i + 1] - b->start[i];
        if (s.n != m || memcmp(s.j, b->j + b->start[i], m * sizeof *s.j) != 0)
            bad++;
    }
    CHECK_MSG(bad == 0, "%s: %zu particles with other pairs or another order", what, bad);
}

/* ---- operators, written out from their equations ------------------------ */

typedef struct fields {
    double *f, *u, *mu, *rho, *ex;
    uint8_t *fluid, *not_dummy, *own;
} fields;

static fields make_fields(const mf_particles *p)
{
    size_t n = p->n;
    fields F = {malloc(n * sizeof(double)), malloc(3 * n * sizeof(double)),
                malloc(n * sizeof(double)),     malloc(n * sizeof(double)),
                malloc(3 * n * sizeof(double)), malloc(n),
                malloc(n),                       malloc(n)};
    for (size_t i = 0; i < n; i++) {
        const double *x = &p->pos[3 * i];
        F.f[i] = 1.0 + 3.0 * x[0] - 2.0 * x[1] + x[0] * x[1] + uniform() * 1e-3;
        for (int c = 0; c < 3; c++)
            F.u[3 * i + c] = p->vel[3 * i + c];
        F.mu[i] = 1e-3 * (1 + uniform());
        F.rho[i] = 500 + 1000 * uniform();
        F.fluid[i] = p->kind[i] == MF_FLUID;
        F.not_dummy[i] = p->kind[i] != MF_DUMMY;
        F.own[i] = uniform() < 0.2;
    }
    return F;
}

static void free_fields(fields *F)
{
    free(F->f);
    free(F->u);
    free(F->mu);
    free(F->rho);
    free(F->ex);
    free(F->fluid);
    free(F->not_dummy);
    free(F->own);
}

/* r_ij and |r_ij| as the engine computes them. */
static double pair_r(const mf_particles *p, size_t i, size_t j, double r[3])
{
    for (int c = 0; c < 3; c++)
        r[c] = p->pos[3 * j + c] - p->pos[3 * i + c];
    return sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
}

/* One operator at particle i by brute force, into out (up to 3 values).
 * The expressions keep the order of operations of mf_kernel.h. */
enum { OP_ND, OP_GRAD, OP_GRAD_PMIN, OP_GRAD_RHO, OP_LAP1, OP_LAP3, OP_LAP_ADD, OP_LAP_MU,
       OP_DIV, OP_COLL, OP_COUNT };
static const char *const op_name[OP_COUNT] = {
    "number density", "gradient", "gradient p_min", "gradient 1/rho_ij", "Laplacian",
    "Laplacian of a vector", "Laplacian added", "Laplacian with mu_ij", "divergence",
    "collision"};

static void brute_op(int op, const mf_particles *p, const brute *b, const mf_kernel *k,
                     const fields *F, size_t i, double re, double *out)
{
    const uint32_t *js = b->j + b->start[i];
    const size_t m = b->start[i + 1] - b->start[i];
    const double cg = k->dim / k->n0, cl = 2.0 * k->dim / (k->lambda * k->n0);
    double acc[3] = {0, 0, 0}, r[3];
    switch (op) {
    case OP_ND:
        for (size_t q = 0; q < m; q++)
            acc[0] += mf_weight(pair_r(p, i, js[q], r), re);
        out[0] = acc[0];
        return;
    case OP_GRAD:
    case OP_GRAD_PMIN:
    case OP_GRAD_RHO: {
        double fhat = F->f[i];
        const bool pmin = op == OP_GRAD_PMIN || (op == OP_GRAD_RHO && !F->own[i]);
        if (pmin) /* Koshizuka et al. 1998: the neighbourhood's minimum */
            for (size_t q = 0; q < m; q++)
                if (F->not_dummy[js[q]] && F->f[js[q]] < fhat)
                    fhat = F->f[js[q]];
        for (size_t q = 0; q < m; q++) {
            size_t j = js[q];
            if (!F->not_dummy[j])
                continue;
            double len = pair_r(p, i, j, r);
            if (len <= 0)
                continue;
            double c = op == OP_GRAD_RHO ? 0.5 * (1.0 / F->rho[i] + 1.0 / F->rho[j]) : 1.0;
            double s = (F->f[j] - fhat) * c * mf_weight(len, re) / (len * len); /* eq. 5 */
            for (int a = 0; a < 3; a++)
                acc[a] += s * r[a];
        }
        for (int a = 0; a < 3; a++)
            out[a] = cg * acc[a];
        return;
    }
    case OP_LAP1:
    case OP_LAP3:
    case OP_LAP_ADD:
    case OP_LAP_MU: {
        const int nc = op == OP_LAP1 ? 1 : 3;
        const double *f = op == OP_LAP1 ? F->f : F->u;
        for (size_t q = 0; q < m; q++) {
            size_t j = js[q];
            double w = mf_weight(pair_r(p, i, j, r), re);
            if (w <= 0)
                continue;
            double c = 1.0;
            if (op == OP_LAP_MU) /* harmonic mean where j is fluid, mu_i elsewhere */
                c = F->fluid[j] ? (F->mu[i] + F->mu[j] > 0
                                       ? 2.0 * F->mu[i] * F->mu[j] / (F->mu[i] + F->mu[j])
                                       : 0.0)
                                : F->mu[i];
            for (int a = 0; a < nc; a++)
                acc[a] += c * (f[nc * j + a] - f[nc * i + a]) * w; /* eq. 7 */
        }
        for (int a = 0; a < nc; a++) {
            if (op == OP_LAP_ADD)
                out[a] = F->ex[3 * i + a] + 0.25 * (cl * acc[a]);
            else if (op == OP_LAP_MU)
                out[a] = F->ex[3 * i + a] + cl * acc[a] / F->rho[i];
            else
                out[a] = cl * acc[a];
        }
        return;
    }
    case OP_DIV:
        for (size_t q = 0; q < m; q++) {
            size_t j = js[q];
            double len = pair_r(p, i, j, r);
            if (len <= 0)
                continue;
            double du = (F->u[3 * j] - F->u[3 * i]) * r[0] +
                        (F->u[3 * j + 1] - F->u[3 * i + 1]) * r[1] +
                        (F->u[3 * j + 2] - F->u[3 * i + 2]) * r[2];
            acc[0] += du * mf_weight(len, re) / (len * len); /* eq. 6 */
        }
        out[0] = cg * acc[0];
        return;
    case OP_COLL: {
        double vi[3] = {F->u[3 * i], F->u[3 * i + 1], F->u[3 * i + 2]};
        for (size_t q = 0; q < m; q++) {
            size_t j = js[q];
            double len = pair_r(p, i, j, r);
            if (len <= 0)
                continue;
            double approach = 0;
            for (int a = 0; a < 3; a++)
                approach += (vi[a] - F->u[3 * j + a]) * r[a] / len;
            if (approach <= 0)
                continue;
            double share = !F->fluid[j] ? 1.0 : F->rho[j] / (F->rho[i] + F->rho[j]);
            for (int a = 0; a < 3; a++)
                vi[a] -= share * (1 + 0.2) * approach * r[a] / len;
        }
        memcpy(out, vi, sizeof vi);
        return;
    }
    }
}

/* Which particles an operator writes, as the engine is asked below. */
static bool op_selects(int op, const fields *F, size_t i)
{
    switch (op) {
    case OP_ND:
        return F->not_dummy[i];
    case OP_GRAD:
    case OP_GRAD_PMIN:
    case OP_GRAD_RHO:
    case OP_LAP_ADD:
    case OP_LAP_MU:
    case OP_COLL:
        return F->fluid[i];
    default:
        return true;
    }
}

static int op_width(int op)
{
    return op == OP_ND || op == OP_LAP1 || op == OP_DIV ? 1 : 3;
}

static void engine_op(int op, const mf_pairs *v, const mf_kernel *k, const fields *F,
                      double *out)
{
    const size_t n = v->n;
    memcpy(out, F->ex, 3 * n * sizeof *out);
    switch (op) {
    case OP_ND:
        mf_number_density(v, F->not_dummy, NULL, out);
        return;
    case OP_GRAD:
    case OP_GRAD_PMIN:
        mf_gradient(v, k, F->f, op == OP_GRAD_PMIN, F->fluid, F->not_dummy, out);
        return;
    case OP_GRAD_RHO: {
        const mf_gradient_opts o = {.f = F->f, .use_min = true, .own_reference = F->own,
                                    .rho = F->rho, .rho_average = MF_AVERAGE_HARMONIC};
        mf_gradient_ex(v, k, &o, F->fluid, F->not_dummy, out);
        return;
    }
    case OP_LAP1:
        mf_laplacian(v, k, F->f, 1, NULL, NULL, out);
        return;
    case OP_LAP3:
        mf_laplacian(v, k, F->u, 3, NULL, NULL, out);
        return;
    case OP_LAP_ADD:
        mf_laplacian_add(v, k, F->u, 0.25, F->fluid, NULL, out);
        return;
    case OP_LAP_MU:
        mf_laplacian_mu(v, k, F->u, F->mu, MF_AVERAGE_HARMONIC, F->fluid, F->rho, F->fluid, out);
        return;
    case OP_DIV:
        mf_divergence(v, k, F->u, NULL, NULL, out);
        return;
    case OP_COLL:
        mf_collision(v, F->fluid, F->rho, 0.2, F->u, out);
        return;
    }
}

/* Every operator through the engine against brute force in the service's
 * order (exact) and in index order (1e-12 relative). */
static void check_operators(const mf_particles *p, const mf_pairs *v, double cell,
                            const char *what)
{
    const double re = v->radius;
    mf_kernel k;
    CHECK_OK(mf_kernel_init(&k, p->dim, 0.1, 2.1 * 0.1));
    fields F = make_fields(p);
    for (size_t i = 0; i < 3 * p->n; i++)
        F.ex[i] = uniform();
    brute ordered = brute_pairs(p, re, cell), plain = brute_pairs(p, re, 0);
    double *out = malloc(3 * p->n * sizeof *out);
    for (int op = 0; op < OP_COUNT; op++) {
        engine_op(op, v, &k, &F, out);
        size_t exact_bad = 0, near_bad = 0, untouched_bad = 0;
        const int w = op_width(op);
        for (size_t i = 0; i < p->n; i++) {
            double want[3], loose[3];
            if (!op_selects(op, &F, i)) {
                for (int a = 0; a < w; a++)
                    untouched_bad += out[w * i + a] != F.ex[w * i + a];
                continue;
            }
            brute_op(op, p, &ordered, &k, &F, i, re, want);
            brute_op(op, p, &plain, &k, &F, i, re, loose);
            for (int a = 0; a < w; a++) {
                double got = out[w * i + a];
                exact_bad += got != want[a];
                /* The collision model is sequential: its order is its
                 * definition, not a rounding matter. */
                double scale = fabs(loose[a]) > 1 ? fabs(loose[a]) : 1;
                near_bad += op != OP_COLL && !(fabs(got - loose[a]) <= 1e-12 * scale);
            }
        }
        CHECK_MSG(exact_bad == 0, "%s, %s: %zu values differ from brute force in list order",
                  what, op_name[op], exact_bad);
        CHECK_MSG(near_bad == 0, "%s, %s: %zu values off brute force in index order", what,
                  op_name[op], near_bad);
        CHECK_MSG(untouched_bad == 0, "%s, %s: %zu values outside imask changed", what,
                  op_name[op], untouched_bad);
    }
    /* The fused pass gives both operators' values bit for bit, and leaves
     * the asymmetry of rows outside its mask alone. */
    double *n1 = malloc(p->n * sizeof *n1), *n2 = malloc(p->n * sizeof *n2);
    double *a1 = malloc(3 * p->n * sizeof *a1), *a2 = malloc(3 * p->n * sizeof *a2);
    for (size_t i = 0; i < 3 * p->n; i++)
        a1[i] = a2[i] = F.ex[i];
    for (size_t i = 0; i < p->n; i++)
        n1[i] = n2[i] = F.ex[i];
    mf_number_density(v, F.not_dummy, NULL, n1);
    mf_neighbour_asymmetry(v, &k, F.fluid, NULL, a1);
    mf_number_density_asymmetry(v, &k, F.not_dummy, F.fluid, n2, a2);
    size_t fused_bad = 0;
    for (size_t i = 0; i < p->n; i++)
        fused_bad += memcmp(&n1[i], &n2[i], sizeof n1[i]) != 0 ||
                     memcmp(&a1[3 * i], &a2[3 * i], 3 * sizeof a1[0]) != 0;
    CHECK_MSG(fused_bad == 0, "%s: number density + asymmetry in one pass differs from the two "
              "operators at %zu particles", what, fused_bad);
    /* The same for the number density with the viscous term (out +=). */
    for (size_t i = 0; i < 3 * p->n; i++)
        a1[i] = a2[i] = F.ex[i];
    for (size_t i = 0; i < p->n; i++)
        n1[i] = n2[i] = F.ex[i];
    mf_number_density(v, F.not_dummy, NULL, n1);
    mf_laplacian_add(v, &k, F.u, 1.3e-3, F.fluid, NULL, a1);
    mf_laplacian_add_number_density(v, &k, F.u, 1.3e-3, F.not_dummy, F.fluid, a2, n2);
    fused_bad = 0;
    for (size_t i = 0; i < p->n; i++)
        fused_bad += memcmp(&n1[i], &n2[i], sizeof n1[i]) != 0 ||
                     memcmp(&a1[3 * i], &a2[3 * i], 3 * sizeof a1[0]) != 0;
    CHECK_MSG(fused_bad == 0, "%s: number density + viscous term in one pass differs from the "
              "two operators at %zu particles", what, fused_bad);
    free(n1);
    free(n2);
    free(a1);
    free(a2);
    free(out);
    brute_free(&ordered);
    brute_free(&plain);
    free_fields(&F);
}

/* ---- the assemble sink -------------------------------------------------- */

typedef struct lap_rows {
    mf_pairs v;
    mf_rows rows;
    const double *known_value;
    double *known;    /* per row */
    double *diag_sum; /* per row */
    size_t cap;
} lap_rows;

static inline double w_coef(const void *ctx, const mf_pair *pr)
{
    const lap_rows *c = ctx;
    return 2.0 * mf_weight(pr->len, c->v.radius);
}

static inline void w_known(void *acc, const void *ctx, const mf_pair *pr, double a)
{
    const lap_rows *c = ctx;
    *(double *)acc += a * c->known_value[pr->j];
}

static int w_sized(void *ctx, size_t nnz)
{
    lap_rows *c = ctx;
    c->rows.col = malloc((nnz + 1) * sizeof *c->rows.col);
    c->rows.val = malloc((nnz + 1) * sizeof *c->rows.val);
    c->cap = nnz;
    return c->rows.col && c->rows.val ? 0 : MF_ERR_MEMORY;
}

static size_t w_row(const void *ctx, size_t i, size_t r)
{
    const lap_rows *c = ctx;
    double known = 0;
    size_t entries = 0;
    double sum = mf_pairs_row_assemble(&c->v, i, NULL, NULL, w_coef, w_known, c, &known,
                                       &c->rows, r, &entries);
    c->rows.val[c->rows.rowptr[r]] = 1.0 + sum;
    c->diag_sum[r] = sum;
    c->known[r] = known;
    return entries;
}

/* Rows of the unknowns (fluid here): diagonal first, -a_ij in unknown j's
 * column in list order, symmetric, diagonal 1 + sum of a_ij over every
 * neighbour, known values of the others on the right. */
static void check_assembly(const mf_particles *p, const mf_pairs *v, double cell,
                           const char *what)
{
    const size_t n = p->n;
    long *col_of = malloc(n * sizeof *col_of);
    double *value = malloc(n * sizeof *value);
    size_t rows = 0;
    for (size_t i = 0; i < n; i++) {
        col_of[i] = p->kind[i] == MF_FLUID ? (long)rows++ : -1;
        value[i] = uniform();
    }
    lap_rows c = {*v, {col_of, 7, calloc(rows + 1, sizeof(size_t)), NULL, NULL, NULL}, value,
                  calloc(rows + 1, sizeof(double)), calloc(rows + 1, sizeof(double)), 0};
    size_t failed = 0;
    CHECK_OK(mf_pairs_assemble(v, &c.rows, rows, w_sized, w_row, &c, &failed));
    CHECK(failed == SIZE_MAX);
    brute b = brute_pairs(p, v->radius, cell);
    size_t bad_rows = 0, asym = 0;
    for (size_t i = 0; i < n; i++) {
        if (col_of[i] < 0)
            continue;
        const size_t r = (size_t)col_of[i], k0 = c.rows.rowptr[r], k1 = c.rows.rowptr[r + 1];
        bool ok = c.rows.col[k0] == 7 + (int64_t)r;
        size_t at = k0 + 1;
        double sum = 0, known = 0, rr[3];
        for (size_t q = b.start[i]; q < b.start[i + 1]; q++) {
            size_t j = b.j[q];
            double a = 2.0 * mf_weight(pair_r(p, i, j, rr), v->radius);
            sum += a;
            if (col_of[j] >= 0) {
                ok = ok && at < k1 && c.rows.col[at] == 7 + col_of[j] && c.rows.val[at] == -a;
                at++;
            } else {
                known += a * value[j];
            }
        }
        ok = ok && at == k1 && c.rows.val[k0] == 1.0 + sum && c.diag_sum[r] == sum &&
             c.known[r] == known;
        bad_rows += !ok;
        /* A_ij = A_ji: find the transposed entry. */
        for (size_t q = k0 + 1; q < k1; q++) {
            size_t s = (size_t)(c.rows.col[q] - 7);
            bool found = false;
            for (size_t t = c.rows.rowptr[s] + 1; t < c.rows.rowptr[s + 1]; t++)
                if (c.rows.col[t] == 7 + (int64_t)r)
                    found = c.rows.val[t] == c.rows.val[q];
            asym += !found;
        }
    }
    CHECK_MSG(bad_rows == 0, "%s: %zu rows differ from brute force", what, bad_rows);
    CHECK_MSG(asym == 0, "%s: %zu entries without an equal transposed entry", what, asym);
    brute_free(&b);
    free(c.rows.rowptr);
    free(c.rows.col);
    free(c.rows.val);
    free(c.known);
    free(c.diag_sum);
    free(col_of);
    free(value);
}

/* ---- point queries ------------------------------------------------------ */

typedef struct near_acc {
    uint8_t *hit;
    size_t visits;
} near_acc;

static inline bool near_point(void *acc, const void *ctx, size_t j, const double r[3], double d2)
{
    (void)ctx;
    near_acc *a = acc;
    a->hit[j] = 1;
    a->visits++;
    CHECK(fabs(d2 - (r[0] * r[0] + r[1] * r[1] + r[2] * r[2])) <= 0);
    return true;
}

/* mf_grid_near visits every particle closer than the cell size to x, once. */
static void check_near(mf_neighbours *nb, const mf_particles *p, double cell, const char *what)
{
    const mf_grid *g = NULL;
    CHECK_OK(mf_neighbours_grid(nb, p, cell, &g));
    uint8_t *hit = malloc(p->n);
    size_t missed = 0, twice = 0;
    for (int t = 0; t < 50; t++) {
        double x[3] = {uniform(), uniform(), p->dim == 3 ? uniform() : 0};
        memset(hit, 0, p->n);
        near_acc a = {hit, 0};
        mf_grid_near(g, x, near_point, NULL, &a);
        size_t distinct = 0;
        for (size_t j = 0; j < p->n; j++) {
            distinct += hit[j];
            const double *y = &p->pos[3 * j];
            double d2 = (y[0] - x[0]) * (y[0] - x[0]) + (y[1] - x[1]) * (y[1] - x[1]) +
                        (y[2] - x[2]) * (y[2] - x[2]);
            missed += d2 < cell * cell && !hit[j];
        }
        twice += a.visits != distinct;
    }
    CHECK_MSG(missed == 0 && twice == 0, "%s: point queries missed %zu, repeated %zu", what,
              missed, twice);
    free(hit);
}

/* ---- the service over moves ---------------------------------------------- */

static void move_all(mf_particles *p, double amount)
{
    for (size_t i = 0; i < p->n; i++)
        for (int c = 0; c < p->dim; c++)
            p->pos[3 * i + c] += amount * (uniform() - 0.5);
}

static void check_set(mf_particles *p, double cell, const char *name)
{
    char what[160];
    mf_neighbours *nb = NULL;
    CHECK_OK(mf_neighbours_create(&nb));
    /* The solver's radii (the largest is the cell), a smaller one, a
     * collision-like one, and a shared request. */
    const double radii[4] = {cell, 0.68 * cell, 0.16 * cell, 0.5 * cell};
    int h[4];
    for (int r = 0; r < 3; r++)
        CHECK_OK(mf_neighbours_request(nb, radii[r], cell, &h[r]));
    CHECK_OK(mf_neighbours_request(nb, radii[3], 0, &h[3]));
    mf_neighbours_stats st0, st1;
    for (int stage = 0; stage < 4; stage++) {
        /* 0: first build; 1, 2: small moves (kept, re-sorted); 3: large move */
        if (stage == 1 || stage == 2)
            move_all(p, 0.004 * cell);
        if (stage == 3)
            move_all(p, 0.6 * cell);
        mf_neighbours_get_stats(nb, &st0);
        mf_neighbours_moved(nb);
        for (int r = 0; r < 4; r++) {
            mf_pairs v;
            CHECK_OK(mf_neighbours_pairs(nb, p, h[r], &v));
            CHECK(v.radius == radii[r] && v.ni == p->n_owned);
            snprintf(what, sizeof what, "%s, stage %d, radius %.2f cell", name, stage,
                     radii[r] / cell);
            brute b = brute_pairs(p, radii[r], cell);
            check_view(&v, &b, what);
            brute_free(&b);
            if (stage == 2 && r == 1)
                check_operators(p, &v, cell, what);
            if (stage == 2 && r == 0)
                check_assembly(p, &v, cell, what);
        }
        mf_neighbours_get_stats(nb, &st1);
        if (stage == 1 || stage == 2)
            CHECK_MSG(st1.builds == st0.builds && st1.sorts > st0.sorts,
                      "%s, stage %d: a small move rebuilt (%ld builds, %ld sorts)", name, stage,
                      st1.builds - st0.builds, st1.sorts - st0.sorts);
        if (stage == 3)
            CHECK_MSG(st1.builds > st0.builds, "%s: a large move kept the list", name);
    }
    snprintf(what, sizeof what, "%s, point queries", name);
    check_near(nb, p, cell, what);
    /* Another store in the same slots: rebuilt, never kept. */
    mf_particles *q = NULL;
    CHECK_OK(mf_particles_create(p->dim, p->n, &q));
    for (size_t i = 0; i < p->n; i++)
        CHECK_OK(mf_particles_add(q, p->kind[i], &p->pos[3 * i], &p->vel[3 * i], NULL));
    mf_neighbours_get_stats(nb, &st0);
    mf_pairs v;
    CHECK_OK(mf_neighbours_pairs(nb, q, h[0], &v));
    mf_neighbours_get_stats(nb, &st1);
    CHECK(st1.builds == st0.builds + 1);
    mf_particles_destroy(q);
    mf_neighbours_destroy(nb);
}

/* A non-finite position is an error that names the particle, not a crash. */
static void test_bad_input(void)
{
    mf_particles *p = random_set(2, 50, 1.0);
    mf_neighbours *nb = NULL;
    CHECK_OK(mf_neighbours_create(&nb));
    int h = -1;
    CHECK(mf_neighbours_request(nb, 0.3, 0.2, &h) == MF_ERR_INPUT); /* radius > cell */
    CHECK(mf_neighbours_request(nb, -1, 0, &h) == MF_ERR_INPUT);
    CHECK_OK(mf_neighbours_request(nb, 0.2, 0.2, &h));
    mf_pairs v;
    CHECK(mf_neighbours_pairs(nb, p, h + 7, &v) == MF_ERR_INPUT); /* not requested */
    CHECK_OK(mf_neighbours_pairs(nb, p, h, &v));
    p->pos[3 * 17] = NAN;
    mf_neighbours_moved(nb);
    CHECK(mf_neighbours_pairs(nb, p, h, &v) == MF_ERR_NUMERIC);
    mf_error_clear();
    mf_neighbours_destroy(nb);
    mf_particles_destroy(p);
}

int main(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        char name[64];
        /* Random: about 40 neighbours within the cell in 2-D, 60 in 3-D. */
        mf_particles *p = random_set(dim, dim == 2 ? 1500 : 2000, 1.0);
        snprintf(name, sizeof name, "%d-D random", dim);
        check_set(p, dim == 2 ? 0.09 : 0.2, name);
        mf_particles_destroy(p);
        /* Lattice, l0 = 0.1, cell 3.1 l0 (2-D) or 2.1 l0 (3-D): ties of
         * distance everywhere, as in a real start. */
        p = lattice_set(dim, dim == 2 ? 30 : 12, 0.1, 0.0);
        snprintf(name, sizeof name, "%d-D lattice", dim);
        check_set(p, dim == 2 ? 0.31 : 0.21, name);
        mf_particles_destroy(p);
        p = lattice_set(dim, dim == 2 ? 30 : 12, 0.1, 0.3);
        snprintf(name, sizeof name, "%d-D jittered lattice", dim);
        check_set(p, dim == 2 ? 0.31 : 0.21, name);
        mf_particles_destroy(p);
    }
    test_bad_input();
    return mf_test_summary("pairs");
}
