/* mf_pairs.h: the pair engine. Every loop over particle pairs in the code is
 * one of the loops below; the physics of a pair is a small function (a pair
 * kernel) that the loop is handed (STYLE.md, "The shape of a pair kernel").
 *
 *   mf_pairs_row       the pairs (i, j) of one particle i, j in a neighbour
 *                      view (mf_neighbours_pairs) and in jmask, closer than
 *                      the view's radius, in the view's order: the kernel
 *                      adds to a per-i accumulator (the apply sink);
 *   mf_pairs_each      the rows of the owned particles i in imask, in
 *                      parallel (OpenMP): the operator's row function calls
 *                      mf_pairs_row and stores its result;
 *   mf_pairs_row_assemble / mf_pairs_assemble
 *                      matrix rows from a coefficient kernel a_ij (the
 *                      assemble sink): diagonal first, -a_ij for a neighbour
 *                      with a column, a known value otherwise, in one pass;
 *   mf_grid_near       the particles of a grid near any point (point
 *                      queries: MPS-MAFL's grid points and lattice sites).
 *
 * The i-loop covers owned particles [0, n_owned); j runs over any particle
 * of the view, halo and periodic images [n_owned, n) included, so that the
 * kernels need not know about them (DESIGN.md section 9).
 *
 * Loops are static inline and always inlined, and take the kernel as a
 * function: called with a literal kernel, each loop compiles to its own
 * specialised code, as nlist.c does with its literal arguments (no macro
 * stamping). A kernel sees the pair as mf_pair: r_ij = r_j - r_i computed
 * from the positions exactly as the list build does, |r_ij|^2 and |r_ij|.
 */
#ifndef MF_PAIRS_H
#define MF_PAIRS_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "mf_neighbours.h"
#include "mf_particles.h"

#define MF_ENGINE static inline __attribute__((always_inline))

/* Threads on a machine that has other work. A loop's iterations are dealt
 * dynamically, MF_PAIRS_CHUNK rows (of pairs) or MF_STREAM_CHUNK items (of
 * a few operations each) at a time: a thread that another process holds
 * off its core then delays the loop by one chunk, not by its static half
 * (with a static schedule the loop lasts as long as the slowest thread's
 * half, and two threads with the second core busy were no faster than
 * one). Small loops stay parallel too: run on one thread they were slower
 * on a loaded machine (docs/notes/speed.md, speed3). */
#define MF_PAIRS_CHUNK 64
#define MF_STREAM_CHUNK 4096

/* A neighbour view: lists and the radius of one request. */
typedef struct mf_pairs {
    const double *pos;       /* 3 per particle */
    const uint32_t *start;   /* CSR over the particles: j's of i at j[start[i] .. start[i+1]) */
    const uint32_t *j;
    double radius, r2;       /* pairs with |r_ij|^2 < r2 = radius * radius */
    size_t ni;               /* i in [0, ni): the owned particles */
    size_t n;                /* particles the lists cover */
} mf_pairs;

/* A view of a list built by hand (tests, tools): pairs closer than radius
 * (at most the list's). */
static inline mf_pairs mf_pairs_of_list(const mf_particles *p, const mf_nlist *nl,
                                        double radius)
{
    mf_pairs v = {p->pos, nl->start, nl->j, radius, radius * radius, p->n_owned, nl->n};
    return v;
}

typedef struct mf_pair {
    size_t i, j;
    double r[3];  /* r_ij = r_j - r_i */
    double r2;    /* |r_ij|^2 = (x^2 + y^2) + z^2 */
    double len;   /* |r_ij| */
} mf_pair;

/* Entry k of the view as the pair (xi, yi, zi: i's position): false when
 * it is not closer than the view's radius. r_ij = r_j - r_i and |r_ij|^2 =
 * (x^2 + y^2) + z^2 exactly as the list build computes them (z = 0 in 2-D),
 * so that the view's pairs are the list build's at that radius. */
MF_ENGINE bool mf_pairs_entry_as(const mf_pairs *v, uint32_t k, double xi, double yi,
                                 double zi, mf_pair *pr, bool with_len)
{
    const size_t j = v->j[k];
    const double *xj = v->pos + 3 * j;
    const double dx = xj[0] - xi, dy = xj[1] - yi, dz = xj[2] - zi;
    const double r2 = dx * dx + dy * dy + dz * dz;
    if (!(r2 < v->r2))
        return false;
    pr->j = j;
    pr->r[0] = dx;
    pr->r[1] = dy;
    pr->r[2] = dz;
    pr->r2 = r2;
    pr->len = with_len ? sqrt(r2) : NAN;
    return true;
}

MF_ENGINE bool mf_pairs_entry(const mf_pairs *v, uint32_t k, double xi, double yi, double zi,
                              mf_pair *pr)
{
    return mf_pairs_entry_as(v, k, xi, yi, zi, pr, true);
}

/* Adds one pair to the accumulator acc; returns false to end the row. */
typedef bool (*mf_pair_kernel)(void *acc, const void *ctx, const mf_pair *pr);

/* The pairs of particle i (see the top); with_len a literal. */
MF_ENGINE void mf_pairs_row_as(const mf_pairs *v, size_t i, const uint8_t *jmask,
                               mf_pair_kernel kernel, const void *ctx, void *acc, bool with_len)
{
    /* A local copy: its fields stay in registers across the kernel's calls. */
    const mf_pairs w = *v;
    const double *pos = w.pos;
    const double xi = pos[3 * i], yi = pos[3 * i + 1], zi = pos[3 * i + 2];
    mf_pair pr;
    pr.i = i;
    for (uint32_t k = w.start[i], end = w.start[i + 1]; k < end; k++) {
        if (jmask && !jmask[w.j[k]])
            continue;
        if (mf_pairs_entry_as(&w, k, xi, yi, zi, &pr, with_len) && !kernel(acc, ctx, &pr))
            break;
    }
}

/* The pairs of particle i (see the top). */
MF_ENGINE void mf_pairs_row(const mf_pairs *v, size_t i, const uint8_t *jmask,
                            mf_pair_kernel kernel, const void *ctx, void *acc)
{
    mf_pairs_row_as(v, i, jmask, kernel, ctx, acc, true);
}

/* The same for a kernel that reads r_ij and |r_ij|^2 only (a minimum, a
 * count, a distance test): no square root (len is NaN). */
MF_ENGINE void mf_pairs_row_r2(const mf_pairs *v, size_t i, const uint8_t *jmask,
                               mf_pair_kernel kernel, const void *ctx, void *acc)
{
    mf_pairs_row_as(v, i, jmask, kernel, ctx, acc, false);
}

/* Computes and stores the result of particle i. */
typedef void (*mf_row_fn)(const void *ctx, size_t i);

/* row(ctx, i) for the owned particles i in imask (NULL: all), in parallel. */
MF_ENGINE void mf_pairs_each(const mf_pairs *v, const uint8_t *imask, mf_row_fn row,
                             const void *ctx)
{
    const long n = (long)v->ni;
#pragma omp parallel for schedule(dynamic, MF_PAIRS_CHUNK)
    for (long i = 0; i < n; i++)
        if (!imask || imask[i])
            row(ctx, (size_t)i);
}

/* ---- the assemble sink ------------------------------------------------- */

/* Rows of a sparse matrix (CSR, global columns) being assembled. */
typedef struct mf_rows {
    const long *col_of;  /* particle -> local column (>= 0), or -1: a known value */
    int64_t col_offset;  /* global column = col_offset + col_of[j] ... */
    size_t *rowptr;      /* rows + 1 */
    int32_t *col;        /* 32-bit global columns (mf_csr) */
    double *val;
    /* ... or, when not NULL, global_col[j]: the copies [n_owned, n) of other
     * ranks' particles hold their owners' global columns (col_of of a copy
     * only says whether it has one, >= 0). */
    const long *global_col;
} mf_rows;

/* Does the pair take part (NULL: every pair of the view does)? */
typedef bool (*mf_pair_test)(const void *ctx, const mf_pair *pr);
/* The pair's coefficient a_ij: the row gets -a_ij in j's column, a_ij on
 * the diagonal. */
typedef double (*mf_pair_coef)(const void *ctx, const mf_pair *pr);
/* A neighbour without a column: its known value times a_ij goes to the
 * right-hand side (acc). */
typedef void (*mf_pair_known)(void *acc, const void *ctx, const mf_pair *pr, double a);

/* Writes the row of particle i at rows->rowptr[row]: the diagonal's column
 * first (its value is the caller's: returned is the sum of a_ij over the
 * taking part pairs, known ones included), then -a_ij for each neighbour
 * with a column, in the view's order; known(acc, ...) for the others.
 * *entries: the row's entries, the diagonal included (at most 1 + the
 * particle's list length, which mf_pairs_assemble reserves). */
MF_ENGINE double mf_pairs_row_assemble(const mf_pairs *v, size_t i, const uint8_t *jmask,
                                       mf_pair_test test, mf_pair_coef coef,
                                       mf_pair_known known, const void *ctx, void *acc,
                                       const mf_rows *rows, size_t row, size_t *entries)
{
    const mf_pairs w = *v;
    const double *pos = w.pos;
    const long *col_of = rows->col_of;
    int32_t *col = rows->col;
    double *val = rows->val;
    const int64_t offset = rows->col_offset;
    const double xi = pos[3 * i], yi = pos[3 * i + 1], zi = pos[3 * i + 2];
    const long *global = rows->global_col;
    size_t at = rows->rowptr[row];
    col[at++] = (int32_t)(global ? global[i] : offset + col_of[i]);
    double sum = 0.0;
    mf_pair pr;
    pr.i = i;
    for (uint32_t k = w.start[i], end = w.start[i + 1]; k < end; k++) {
        const size_t j = w.j[k];
        if (jmask && !jmask[j])
            continue;
        if (!mf_pairs_entry(&w, k, xi, yi, zi, &pr) || (test && !test(ctx, &pr)))
            continue;
        const double a = coef(ctx, &pr);
        sum += a;
        const long c = col_of[j];
        if (c >= 0) {
            col[at] = (int32_t)(global ? global[j] : offset + c);
            val[at++] = -a;
        } else if (known) {
            known(acc, ctx, &pr, a);
        }
    }
    *entries = at - rows->rowptr[row];
    return sum;
}

/* The writing of row r of the particle i with col_of[i] == r
 * (mf_pairs_row_assemble, then the diagonal and the right-hand side):
 * returns the row's entries, or 0 to report the row as failed (its entries
 * are dropped; the assembly goes on, and the smallest failed particle is
 * reported). Called through the pointer once a row; the kernels inside it
 * are inlined. */
typedef size_t (*mf_assemble_row_fn)(const void *ctx, size_t i, size_t row);
/* Called before the rows are written with a bound on the entries: sizes
 * the column and value arrays (rows->col, rows->val); nonzero stops the
 * assembly. */
typedef int (*mf_assemble_sized_fn)(void *ctx, size_t nnz);

/* Chunks of particles the rows are written in (at most). */
#define MF_ASSEMBLE_CHUNKS 256

/* The matrix of the owned particles i with col_of[i] >= 0 (their rows in
 * particle order: rows->col_of[i] = 0, 1, ... over them) in one pass over
 * the pairs. A row has at most 1 + its particle's list length entries (the
 * bound). The particles are cut into chunks, dealt to the threads in order
 * (dynamically, for a thread held off its core by another process); a
 * chunk's rows are written packed from where the chunks dealt before it can
 * end at most: the end of the last one if it is done, else its start plus
 * its bound (a chunk done while it is the last dealt gives its unused
 * bound back). Then the chunks are moved down onto each other. With one
 * thread every chunk starts where the one before ended: nothing moves and
 * the memory written is the matrix's; with more, a chunk dealt while
 * another was being written leaves that chunk's unused bound as a gap.
 * Rows, entries and rowptr are those of a count pass, a prefix sum and a
 * writing pass, for any thread count. sized() gets the bound of all rows
 * and may move rows->rowptr, col and val. Returns in *failed the first
 * failed particle, or SIZE_MAX. */
MF_ENGINE int mf_pairs_assemble(const mf_pairs *v, mf_rows *rows, size_t nrows,
                                mf_assemble_sized_fn sized, mf_assemble_row_fn row, void *ctx,
                                size_t *failed)
{
    const size_t n = v->ni;
    const long *col_of = rows->col_of;
    const size_t per = n / MF_ASSEMBLE_CHUNKS + 1;
    const long nchunks = (long)((n + per - 1) / per);
    size_t bound[MF_ASSEMBLE_CHUNKS], base[MF_ASSEMBLE_CHUNKS], len[MF_ASSEMBLE_CHUNKS];
    size_t total = 0;
    for (long c = 0; c < nchunks; c++) {
        const size_t i1 = (size_t)(c + 1) * per < n ? (size_t)(c + 1) * per : n;
        bound[c] = 0;
        for (size_t i = (size_t)c * per; i < i1; i++)
            if (col_of[i] >= 0)
                bound[c] += 1 + (size_t)(v->start[i + 1] - v->start[i]);
        total += bound[c];
    }
    int rc = sized(ctx, total);
    if (rc != 0)
        return rc;
    size_t *rowptr = rows->rowptr;
    size_t first = SIZE_MAX, next_base = 0;
    long next_chunk = 0;
#pragma omp parallel
    {
        size_t my_first = SIZE_MAX;
        for (;;) {
            long c = -1;
#pragma omp critical(mf_pairs_assemble)
            if (next_chunk < nchunks) {
                c = next_chunk++;
                base[c] = next_base;
                next_base += bound[c];
            }
            if (c < 0)
                break;
            size_t at = base[c];
            const size_t i1 = (size_t)(c + 1) * per < n ? (size_t)(c + 1) * per : n;
            for (size_t i = (size_t)c * per; i < i1; i++) {
                const long r = col_of[i];
                if (r < 0)
                    continue;
                rowptr[r] = at;
                const size_t m = row(ctx, i, (size_t)r);
                if (m == 0 && i < my_first)
                    my_first = i;
                at += m;
            }
            len[c] = at - base[c];
#pragma omp critical(mf_pairs_assemble)
            if (c == next_chunk - 1) /* the last dealt: its unused bound back */
                next_base = at;
        }
#pragma omp critical(mf_pairs_assemble)
        if (my_first < first)
            first = my_first;
    }
    /* The chunks down onto each other, in order (each moves down or stays). */
    int32_t *col = rows->col;
    double *val = rows->val;
    size_t at = 0;
    for (long c = 0; c < nchunks; c++) {
        const size_t shift = base[c] - at;
        if (shift > 0) {
            if (len[c] > 0) {
                memmove(col + at, col + base[c], len[c] * sizeof *col);
                memmove(val + at, val + base[c], len[c] * sizeof *val);
            }
            const size_t i1 = (size_t)(c + 1) * per < n ? (size_t)(c + 1) * per : n;
            for (size_t i = (size_t)c * per; i < i1; i++)
                if (col_of[i] >= 0)
                    rowptr[col_of[i]] -= shift;
        }
        at += len[c];
    }
    rowptr[nrows] = at;
    *failed = first;
    return 0;
}

/* ---- point queries ------------------------------------------------------ */

/* Visits particle j (position xj in cell order, its squared distance d2
 * from the point: (x^2 + y^2) + z^2 of xj - x); returns false to stop. */
typedef bool (*mf_point_kernel)(void *acc, const void *ctx, size_t j, const double r[3],
                                double d2);

/* Every particle of the cells within one cell of x's (the 3^dim block
 * around it), cells in key order, particles in cell order: every particle
 * closer to x than the grid's cell size, and some farther ones (the kernel
 * tests the distance it needs). Nothing when x is more than a cell outside
 * the grid's box. r = x_j - x from the grid's copy of the positions. */
MF_ENGINE void mf_grid_near(const mf_grid *g, const double x[3], mf_point_kernel kernel,
                            const void *ctx, void *acc)
{
    if (g->ncells == 0)
        return;
    const double w = g->cell_size * (1.0 + MF_GRID_CELL_SLACK);
    long lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int a = 0; a < g->dim; a++) {
        double u = floor((x[a] - g->origin[a]) / w);
        if (!(u + 1 >= 0) || !(u - 1 < (double)g->nbox[a]))
            return; /* more than a cell outside the box, or NaN */
        long c = (long)u;
        lo[a] = c - 1 < 0 ? 0 : c - 1;
        hi[a] = c + 1 >= (long)g->nbox[a] ? (long)g->nbox[a] - 1 : c + 1;
    }
    const size_t np = g->np;
    const double *sx = g->spos, *sy = g->spos + np, *sz = g->spos + 2 * np;
    for (long iz = lo[2]; iz <= hi[2]; iz++)
        for (long iy = lo[1]; iy <= hi[1]; iy++)
            for (long ix = lo[0]; ix <= hi[0]; ix++) {
                long c = mf_grid_find_cell(g, mf_grid_key((uint64_t)ix, (uint64_t)iy,
                                                          (uint64_t)iz));
                if (c < 0)
                    continue;
                for (uint32_t m = g->cell_start[c]; m < g->cell_start[c + 1]; m++) {
                    const double r[3] = {sx[m] - x[0], sy[m] - x[1], sz[m] - x[2]};
                    const double d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
                    if (!kernel(acc, ctx, g->order[m], r, d2))
                        return;
                }
            }
}

#pragma GCC visibility pop
#endif
