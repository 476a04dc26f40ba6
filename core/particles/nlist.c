/* nlist.c: CSR neighbour lists over the occupied-cell grid of grid.c
 * (mf_neighbours.h). How the grid is built is described in grid.c.
 *
 * Candidates of a particle: the cells that meet the box [x - R, x + R] of
 * its position (R the list radius), at most reach cells away from its own
 * cell on each axis. Along x those cells are consecutive in key order, so
 * each row (y, z) of them is one range of sorted particles; a cell turns the
 * first occupied cell of each of its rows (grid.c) into the boundaries of
 * every cell of the row once, and each of its particles picks its ranges.
 * With R up to the cell size that is the 3^dim cells around it; up to twice
 * the cell size (a list with a skin, mf_neighbours_pairs) the ring beyond
 * them only where the box reaches into it.
 *
 * List build, three parallel passes over cells:
 *   plan:  candidates per particle, hence the offsets of its candidate bits;
 *   count: test every candidate of every particle, store the outcome as one
 *          bit per candidate and the count per particle;
 *   fill:  after a prefix sum of the counts, turn the set bits into indices.
 * The distance test thus runs once per candidate, and both passes read the
 * same bits, so they cannot disagree. The j's of a particle come in row and
 * cell order, that is ascending (cell key, index), the same for any thread
 * count. When the bits would take too much memory (cells much larger than
 * the radius) the fill pass repeats the distance test instead.
 *
 * Only the owned particles [0, n_owned) get lists: the copies of other
 * ranks' particles and the periodic images [n_owned, n) are binned and
 * found as j's, but their rows are empty (the pair engine's i-loops cover
 * the owned particles only, mf_pairs.h), and they take no part in the
 * choice of a cell's candidate rows, which are the union over the cell's
 * owned particles (a candidate row more or less changes no list: the
 * distance test decides). Without copies (a serial run without periodic
 * images) n_owned = n: nothing changes.
 */
#include "neighbours_internal.h"
#include "mf_alloc.h"

/* Scratch bytes (ranges and candidate bits) per block of the fill pass,
 * given back after each block: about 5 blocks for the 3-D bench case's
 * 5 MB. At least MF_RELEASE_MIN_BYTES, else a block gives nothing back. */
#define FILL_BLOCK_BYTES ((size_t)1 << 20)

/* ---- neighbour lists: memory ---------------------------------------------- */

void mf_nlist_init(mf_nlist *nl)
{
    memset(nl, 0, sizeof *nl);
}

void mf_nlist_free(mf_nlist *nl)
{
    if (!nl)
        return;
    free(nl->start);
    free(nl->j);
    free(nl->work);
    mf_nlist_init(nl);
}

void mf_nlist_release_scratch(mf_nlist *nl)
{
    if (!nl)
        return;
    free(nl->work);
    nl->work = NULL;
    nl->work_bytes = 0;
}

size_t mf_nlist_memory(const mf_nlist *nl)
{
    if (!nl)
        return 0;
    return nl->cap_n * sizeof(uint32_t) + nl->cap_j * sizeof(uint32_t) + nl->work_bytes;
}

static int ensure_start(mf_nlist *nl, size_t n)
{
    if (nl->start && !needs_realloc(nl->cap_n, n + 1))
        return 0;
    nl->cap_n = 0;
    size_t cap = with_headroom(n + 1);
    MF_CALL(replace_buffer((void **)&nl->start, cap, sizeof(uint32_t), "list starts"));
    nl->cap_n = cap;
    return 0;
}

static int ensure_entries(mf_nlist *nl, size_t count)
{
    if (nl->j && !needs_realloc(nl->cap_j, count))
        return 0;
    nl->cap_j = 0;
    size_t cap = with_headroom(count);
    MF_CALL(replace_buffer((void **)&nl->j, cap, sizeof(uint32_t), "list entries"));
    nl->cap_j = cap;
    return 0;
}

/* Scratch of at least `bytes`, 8-byte aligned (malloc's alignment); its
 * contents do not survive a call that grows it. */
static int ensure_work(mf_nlist *nl, size_t bytes)
{
    if (nl->work && !needs_realloc(nl->work_bytes, bytes))
        return 0;
    nl->work_bytes = 0;
    size_t cap = with_headroom(bytes);
    MF_CALL(replace_buffer(&nl->work, cap, 1, "list scratch"));
    nl->work_bytes = cap;
    return 0;
}

/* start[i + 1] holds the count of i on entry; start becomes offsets. The
 * offsets are 32-bit: more than 2^32 - 1 entries on one rank is an error. */
static int counts_to_offsets(uint32_t *start, size_t n)
{
    uint64_t sum = 0;
    start[0] = 0;
    for (size_t i = 0; i < n; i++) {
        sum += start[i + 1];
        if (sum >= UINT32_MAX)
            return MF_ERROR(MF_ERR_MEMORY,
                            "neighbour list of %zu particles has more than 2^32 entries: run "
                            "on more ranks or with smaller radii",
                            n);
        start[i + 1] = (uint32_t)sum;
    }
    return 0;
}

/* ---- neighbour lists: the distance test ---------------------------------- */

/* Two candidates at a time. GCC/clang vector extensions give SIMD at -O2 (the
 * cheap cost model does not vectorize these short loops by itself); 16-byte
 * vectors are in the x86-64 and AArch64 baselines. Each lane computes
 * exactly the scalar expression (dx*dx + dy*dy) + dz*dz, so results equal a
 * scalar loop's (and a brute-force check's). */
typedef double vec2d __attribute__((vector_size(2 * sizeof(double))));
typedef int64_t vec2i __attribute__((vector_size(2 * sizeof(int64_t))));

typedef struct {
    const double *sx, *sy, *sz; /* positions in cell order */
    double r2;
    double r2s;                 /* the sub-list's (mf_nlist_build_pair) */
} pair_test;

static inline vec2d load2(const double *x)
{
    vec2d v;
    memcpy(&v, x, sizeof v);
    return v;
}

static inline vec2d splat2(double x)
{
    return (vec2d){x, x};
}

/* Squared distances of candidates m, m + 1. */
KERNEL vec2d distance2_2(const pair_test *t, size_t m, const double xi[3], int dim)
{
    vec2d dx = load2(t->sx + m) - splat2(xi[0]);
    vec2d dy = load2(t->sy + m) - splat2(xi[1]);
    vec2d d2 = dx * dx + dy * dy;
    if (dim == 3) {
        vec2d dz = load2(t->sz + m) - splat2(xi[2]);
        d2 += dz * dz;
    }
    return d2;
}

/* Candidates m, m + 1 closer than the radius: lanes -1 (in) or 0 (out). */
KERNEL vec2i within2(const pair_test *t, size_t m, const double xi[3], int dim, double r2)
{
    return distance2_2(t, m, xi, dim) < splat2(r2);
}

/* The two lanes of a test as bits 0 and 1. */
static inline unsigned lane_bits(vec2i h)
{
#if defined(__SSE2__)
    return (unsigned)_mm_movemask_pd((__m128d)h); /* one instruction */
#else
    return (unsigned)((h[0] & 1) | (h[1] & 2));
#endif
}

KERNEL double distance2_1(const pair_test *t, size_t m, const double xi[3], int dim)
{
    double dx = t->sx[m] - xi[0], dy = t->sy[m] - xi[1];
    double d2 = dx * dx + dy * dy;
    if (dim == 3) {
        double dz = t->sz[m] - xi[2];
        d2 += dz * dz;
    }
    return d2;
}

KERNEL bool within1(const pair_test *t, size_t m, const double xi[3], int dim, double r2)
{
    return distance2_1(t, m, xi, dim) < r2;
}

/* Candidate bits: a particle's bits start at a word, and each row at an even
 * bit (the tests come in pairs). row_bit[r] is the first bit of row r,
 * row_bit[nrows] the total. */
static void row_bit_offsets(const uint32_t *rows, int nrows, size_t row_bit[MAX_ROWS + 1])
{
    row_bit[0] = 0;
    for (int r = 0; r < nrows; r++)
        row_bit[r + 1] = row_bit[r] + (((size_t)(rows[2 * r + 1] - rows[2 * r]) + 1) & ~(size_t)1);
}

static size_t words_per_particle(const uint32_t *rows, int nrows)
{
    size_t row_bit[MAX_ROWS + 1];
    row_bit_offsets(rows, nrows, row_bit);
    return (row_bit[nrows] + 63) / 64;
}

/* Test every candidate of sorted particle k (position xi); with keep_bits,
 * store the outcomes as bits in words; with sub, count in *shits those
 * closer than the sub-list's radius too. Returns the count of hits, the
 * particle itself included (its distance 0 is < r2). dim, keep_bits and
 * sub are literals at the call sites, so each combination compiles to its
 * own loop. */
KERNEL size_t test_candidates(const pair_test *t, const uint32_t *rows, int nrows,
                              const double xi[3], int dim, bool keep_bits, uint64_t *words,
                              bool sub, size_t *shits)
{
    vec2i hits = {0, 0}, sh = {0, 0};
    uint64_t acc = 0;
    unsigned bit = 0;
    for (int r = 0; r < nrows; r++) {
        size_t m = rows[2 * r];
        const size_t b = rows[2 * r + 1];
        for (; m + 2 <= b; m += 2) {
            const vec2d d2 = distance2_2(t, m, xi, dim);
            const vec2i h = d2 < splat2(t->r2);
            hits -= h;
            if (sub)
                sh -= d2 < splat2(t->r2s);
            if (keep_bits) {
                acc |= (uint64_t)lane_bits(h) << bit;
                bit += 2;
                if (bit == 64) {
                    *words++ = acc;
                    acc = 0;
                    bit = 0;
                }
            }
        }
        if (m < b) {
            const double d2 = distance2_1(t, m, xi, dim);
            const uint64_t h = d2 < t->r2;
            hits[0] += (int64_t)h;
            if (sub)
                sh[0] += d2 < t->r2s;
            if (keep_bits) {
                acc |= h << bit;
                bit += 2;
                if (bit == 64) {
                    *words++ = acc;
                    acc = 0;
                    bit = 0;
                }
            }
        }
    }
    if (keep_bits && bit)
        *words = acc;
    if (sub)
        *shits = (size_t)(sh[0] + sh[1]);
    return (size_t)(hits[0] + hits[1]);
}

/* Append the particle indices of the set bits but self_bit (the particle
 * itself, cleared first: the bits are not read again); with sub (a
 * literal), those closer than the sub-list's radius to sout too. Bit b of
 * row r is candidate b + first[r] (first[r] = rows[2 r] - row_bit[r],
 * modulo 2^64). */
KERNEL size_t decode_bits(uint64_t *words, size_t nwords, const size_t row_bit[MAX_ROWS + 1],
                          const size_t first[MAX_ROWS], size_t self_bit, const uint32_t *order,
                          uint32_t *out, bool sub, const pair_test *t, const double xi[3],
                          int dim, uint32_t *sout)
{
    words[self_bit / 64] &= ~(UINT64_C(1) << (self_bit % 64));
    size_t w = 0, ws = 0;
    int r = 0;
    for (size_t wi = 0; wi < nwords; wi++) {
        uint64_t word = words[wi];
        while (word) {
            size_t bit = 64 * wi + (size_t)__builtin_ctzll(word);
            word &= word - 1;
            while (bit >= row_bit[r + 1])
                r++;
            const size_t m = bit + first[r];
            out[w++] = order[m];
            if (sub && distance2_1(t, m, xi, dim) < t->r2s)
                sout[ws++] = order[m];
        }
    }
    return w;
}

/* Fallback fill without bits: repeat the distance test (radius^2 r2). */
KERNEL size_t retest_candidates(const pair_test *t, const uint32_t *rows, int nrows,
                                const uint32_t *order, size_t k, const double xi[3], int dim,
                                double r2, uint32_t *out)
{
    size_t w = 0;
    for (int r = 0; r < nrows; r++) {
        size_t m = rows[2 * r];
        const size_t b = rows[2 * r + 1];
        for (; m + 2 <= b; m += 2) {
            vec2i h = within2(t, m, xi, dim, r2);
            if (h[0] && m != k)
                out[w++] = order[m];
            if (h[1] && m + 1 != k)
                out[w++] = order[m + 1];
        }
        if (m < b && within1(t, m, xi, dim, r2) && m != k)
            out[w++] = order[m];
    }
    return w;
}

/* ---- neighbour lists: candidate rows -------------------------------------- */

/* The cells around one cell: for each of its rows r, bound[r * stride + m]
 * is the first sorted particle of the cell at x = ix - reach + m (m = 0 ..
 * 2 reach), and bound[r * stride + 2 reach + 1] the end of the last one;
 * an unoccupied cell starts where the next occupied one does. */
typedef struct cell_bounds {
    uint32_t b[MAX_ROWS * 6];
    int stride;              /* 2 reach + 2 */
    int64_t ix, iy, iz;      /* the cell's coordinates */
} cell_bounds;

static inline void bounds_of_cell(const mf_grid *g, size_t c, int nrows, cell_bounds *cb)
{
    const uint64_t key = g->cell_key[c];
    const int reach = g->reach;
    cb->stride = 2 * reach + 2;
    cb->ix = (int64_t)(key & AXIS_MASK);
    cb->iy = (int64_t)((key >> MF_GRID_AXIS_BITS) & AXIS_MASK);
    cb->iz = (int64_t)(key >> (2 * MF_GRID_AXIS_BITS));
    const uint32_t *rows = g->cell_rows + c * (size_t)nrows;
    for (int r = 0; r < nrows; r++) {
        uint32_t *bd = cb->b + r * cb->stride;
        if (rows[r] == EMPTY_SLOT) {
            for (int m = 0; m < cb->stride; m++)
                bd[m] = 0;
            continue;
        }
        size_t q = rows[r];
        const uint64_t row_key = g->cell_key[q] >> MF_GRID_AXIS_BITS;
        for (int m = 0; m < cb->stride; m++) {
            const int64_t x = cb->ix - reach + m;
            while (q < g->ncells && g->cell_key[q] >> MF_GRID_AXIS_BITS == row_key &&
                   (int64_t)(g->cell_key[q] & AXIS_MASK) < x)
                q++;
            bd[m] = g->cell_start[q];
        }
    }
}

/* floor(t) of a finite t (no libm call). */
static inline int64_t floor_int(double t)
{
    int64_t a = (int64_t)t;
    return (double)a > t ? a - 1 : a;
}

/* Offsets (cells from the particle's own) of the first and last cell that
 * the interval [x - R, x + R] meets on one axis, within [-reach, reach]. The
 * radius is taken a hair larger so that rounding cannot drop a cell. */
static inline void axis_span(double x, double origin, double inv_width, double radius,
                             int64_t own, int reach, int *lo, int *hi)
{
    const double r = radius * (1.0 + 1e-12);
    int64_t a = floor_int((x - r - origin) * inv_width) - own;
    int64_t b = floor_int((x + r - origin) * inv_width) - own;
    *lo = a < -reach ? -reach : a > 0 ? 0 : (int)a;
    *hi = b > reach ? reach : b < 0 ? 0 : (int)b;
}

/* The candidate ranges of the particles of a cell: the cells that the boxes
 * [x - R, x + R] of its particles meet (the union over them: the particles
 * of a cell share one set of rows), (dz, dy) rows ascending, cells along x
 * ascending, so that hits come in key order. With R up to the cell size that
 * is the 3^dim block around it, as a single-reach grid always used. */
KERNEL int cell_rows(const mf_grid *g, const cell_bounds *cb, size_t c, const pair_test *t,
                     double radius, double inv_width, int dim, size_t ni, uint32_t *rows)
{
    const int reach = g->reach, w = 2 * reach + 1;
    int xl = 0, xh = 0, yl = 0, yh = 0, zl = 0, zh = 0;
    for (size_t k = g->cell_start[c]; k < g->cell_start[c + 1]; k++) {
        if (g->order[k] >= ni) /* a copy: no list of its own (see the top) */
            continue;
        int lo, hi;
        axis_span(t->sx[k], g->origin[0], inv_width, radius, cb->ix, reach, &lo, &hi);
        xl = lo < xl ? lo : xl;
        xh = hi > xh ? hi : xh;
        axis_span(t->sy[k], g->origin[1], inv_width, radius, cb->iy, reach, &lo, &hi);
        yl = lo < yl ? lo : yl;
        yh = hi > yh ? hi : yh;
        if (dim == 3) {
            axis_span(t->sz[k], g->origin[2], inv_width, radius, cb->iz, reach, &lo, &hi);
            zl = lo < zl ? lo : zl;
            zh = hi > zh ? hi : zh;
        }
    }
    int n = 0;
    for (int dz = zl; dz <= zh; dz++)
        for (int dy = yl; dy <= yh; dy++) {
            const int r = dim == 3 ? (dz + reach) * w + (dy + reach) : dy + reach;
            const uint32_t *bd = cb->b + r * cb->stride;
            const uint32_t a = bd[xl + reach], b = bd[xh + reach + 1];
            if (a < b) {
                rows[2 * n] = a;
                rows[2 * n + 1] = b;
                n++;
            }
        }
    return n;
}

/* ---- neighbour lists: the three passes ------------------------------------ */

typedef struct {
    const mf_grid *g;
    pair_test t;
    double radius, inv_width;
    size_t ni;               /* lists for particles [0, ni): the owned ones */
    int nrows;               /* rows stored per cell */
    size_t *cell_word;       /* ncells + 1 word offsets, or NULL: no bits */
    uint64_t *bits;
    /* The candidate ranges of each cell, found once by the plan pass for the
     * count and fill passes: at cell_ranges + c * range_slots, their number,
     * then (begin, end) of each. */
    uint32_t *cell_ranges;
    size_t range_slots;
} list_build;

static inline void load_position(const pair_test *t, size_t k, double xi[3])
{
    xi[0] = t->sx[k];
    xi[1] = t->sy[k];
    xi[2] = t->sz[k];
}

/* The rows of cell c (as the plan pass stored them), and the words of
 * candidate bits each of its particles takes. */
KERNEL int rows_of(const list_build *lb, size_t c, const uint32_t **rows, size_t *nwords)
{
    const uint32_t *r = lb->cell_ranges + c * lb->range_slots;
    const int n = (int)r[0];
    *rows = r + 1;
    *nwords = words_per_particle(r + 1, n);
    return n;
}

/* Pass 0: the ranges of cell c, and cell_word[c + 1] = words of the
 * particles of cell c. */
KERNEL void plan_cell(const list_build *lb, size_t c, int dim)
{
    cell_bounds cb;
    bounds_of_cell(lb->g, c, lb->nrows, &cb);
    uint32_t *r = lb->cell_ranges + c * lb->range_slots;
    const int n = cell_rows(lb->g, &cb, c, &lb->t, lb->radius, lb->inv_width, dim, lb->ni, r + 1);
    r[0] = (uint32_t)n;
    lb->cell_word[c + 1] =
        words_per_particle(r + 1, n) * (lb->g->cell_start[c + 1] - lb->g->cell_start[c]);
}

/* Pass 1: start[i + 1] = number of neighbours of i; bits if kept; with sub
 * the same for the sub-list into sstart. */
KERNEL void count_cell(const list_build *lb, size_t c, int dim, bool keep_bits, bool sub,
                       uint32_t *start, uint32_t *sstart)
{
    const mf_grid *g = lb->g;
    const uint32_t *rows = NULL;
    size_t nw = 0;
    const int n = rows_of(lb, c, &rows, &nw);
    const size_t k0 = g->cell_start[c];
    for (size_t k = k0; k < g->cell_start[c + 1]; k++) {
        if (g->order[k] >= lb->ni) { /* a copy: an empty row */
            start[g->order[k] + 1] = 0;
            if (sub)
                sstart[g->order[k] + 1] = 0;
            continue;
        }
        double xi[3];
        load_position(&lb->t, k, xi);
        size_t shits = 0;
        size_t hits = test_candidates(&lb->t, rows, n, xi, dim, keep_bits,
                                      keep_bits ? lb->bits + lb->cell_word[c] + (k - k0) * nw
                                                : NULL,
                                      sub, &shits);
        start[g->order[k] + 1] = (uint32_t)(hits - 1); /* minus the particle itself */
        if (sub)
            sstart[g->order[k] + 1] = (uint32_t)(shits - 1);
    }
}

/* Pass 2: j's at the offsets of pass 1, from the bits or by testing again
 * (and the sub-list's, when sstart is not NULL). */
KERNEL void fill_cell(const list_build *lb, size_t c, int dim, const uint32_t *start,
                      uint32_t *jlist, const uint32_t *sstart, uint32_t *sjlist)
{
    const mf_grid *g = lb->g;
    const uint32_t *rows = NULL;
    size_t nw = 0;
    const int n = rows_of(lb, c, &rows, &nw);
    size_t row_bit[MAX_ROWS + 1], first[MAX_ROWS];
    row_bit_offsets(rows, n, row_bit);
    const size_t k0 = g->cell_start[c];
    /* The cell's own row: its particles are candidates there, k at bit
     * own_bit + k. */
    size_t own_bit = 0;
    for (int r = 0; r < n; r++) {
        first[r] = (size_t)rows[2 * r] - row_bit[r];
        if (rows[2 * r] <= k0 && k0 < rows[2 * r + 1])
            own_bit = row_bit[r] - (size_t)rows[2 * r];
    }
    for (size_t k = k0; k < g->cell_start[c + 1]; k++) {
        const uint32_t i = g->order[k];
        if (i >= lb->ni) /* a copy: an empty row */
            continue;
        double xi[3];
        load_position(&lb->t, k, xi);
        uint32_t *out = jlist + start[i];
        if (lb->cell_word) {
            uint64_t *words = lb->bits + lb->cell_word[c] + (k - k0) * nw;
            if (sstart)
                decode_bits(words, nw, row_bit, first, own_bit + k, g->order, out, true, &lb->t,
                            xi, dim, sjlist + sstart[i]);
            else
                decode_bits(words, nw, row_bit, first, own_bit + k, g->order, out, false,
                            &lb->t, xi, dim, NULL);
        } else {
            retest_candidates(&lb->t, rows, n, g->order, k, xi, dim, lb->t.r2, out);
            if (sstart)
                retest_candidates(&lb->t, rows, n, g->order, k, xi, dim, lb->t.r2s,
                                  sjlist + sstart[i]);
        }
    }
}

static void plan_pass(const list_build *lb)
{
    const size_t ncells = lb->g->ncells;
    const int dim = lb->g->dim;
#pragma omp parallel for schedule(dynamic, 32)
    for (size_t c = 0; c < ncells; c++) {
        if (dim == 3)
            plan_cell(lb, c, 3);
        else
            plan_cell(lb, c, 2);
    }
}

/* One cell of pass 1 with literal arguments: the compiler specialises the
 * kernels for each combination. */
static inline void count_cell_as(const list_build *lb, size_t c, int dim, bool keep_bits,
                                 bool sub, uint32_t *start, uint32_t *sstart)
{
    if (dim == 3) {
        if (keep_bits && sub)
            count_cell(lb, c, 3, true, true, start, sstart);
        else if (keep_bits)
            count_cell(lb, c, 3, true, false, start, sstart);
        else if (sub)
            count_cell(lb, c, 3, false, true, start, sstart);
        else
            count_cell(lb, c, 3, false, false, start, sstart);
    } else {
        if (keep_bits && sub)
            count_cell(lb, c, 2, true, true, start, sstart);
        else if (keep_bits)
            count_cell(lb, c, 2, true, false, start, sstart);
        else if (sub)
            count_cell(lb, c, 2, false, true, start, sstart);
        else
            count_cell(lb, c, 2, false, false, start, sstart);
    }
}

static void count_pass(const list_build *lb, uint32_t *start, uint32_t *sstart)
{
    const size_t ncells = lb->g->ncells;
    const int dim = lb->g->dim;
    const bool keep_bits = lb->cell_word != NULL, sub = sstart != NULL;
#pragma omp parallel for schedule(dynamic, 32)
    for (size_t c = 0; c < ncells; c++)
        count_cell_as(lb, c, dim, keep_bits, sub, start, sstart);
}

/* Give back the whole pages of scratch in [*from, to), read for the last
 * time (mf_release_pages; the partial page at `to` is kept), and move *from
 * to the first page kept. Nothing happens below MF_RELEASE_MIN_BYTES: the
 * range then grows with the next block. */
static void release_read(char **from, char *to, uintptr_t page)
{
    if (to > *from && mf_release_pages(*from, (size_t)(to - *from)) > 0)
        *from = (char *)((uintptr_t)to / page * page);
}

/* Pass 2 in blocks of consecutive cells, each block's scratch (its ranges
 * and candidate bits, which no other cell reads) given back once its j's
 * are written: the entries then grow into the pages the bits leave, and
 * the list and its full scratch are never resident at once (issue 12).
 * The cells and what each writes are those of one loop over all cells:
 * the same list. */
static void fill_pass(const list_build *lb, const uint32_t *start, uint32_t *jlist,
                      const uint32_t *sstart, uint32_t *sjlist)
{
    const size_t ncells = lb->g->ncells;
    const int dim = lb->g->dim;
    const uintptr_t page = (uintptr_t)mf_page_size(); /* 0: nothing is released */
    char *ranges_from = (char *)lb->cell_ranges, *bits_from = (char *)lb->bits;
    for (size_t c0 = 0; c0 < ncells;) {
        size_t c1 = c0, bytes = 0;
        while (c1 < ncells && bytes < FILL_BLOCK_BYTES) {
            bytes += lb->range_slots * sizeof(uint32_t);
            if (lb->cell_word)
                bytes += (lb->cell_word[c1 + 1] - lb->cell_word[c1]) * sizeof(uint64_t);
            c1++;
        }
#pragma omp parallel for schedule(dynamic, 32)
        for (size_t c = c0; c < c1; c++) {
            if (dim == 3)
                fill_cell(lb, c, 3, start, jlist, sstart, sjlist);
            else
                fill_cell(lb, c, 2, start, jlist, sstart, sjlist);
        }
        release_read(&ranges_from, (char *)(lb->cell_ranges + c1 * lb->range_slots), page);
        if (lb->cell_word)
            release_read(&bits_from, (char *)(lb->bits + lb->cell_word[c1]), page);
        c0 = c1;
    }
}

/* Lay out the scratch: word offsets per cell at its start, the cells'
 * ranges after them, then the candidate bits. Leaves lb->cell_word NULL (no
 * bits) when they would exceed MAX_BIT_WORDS_PER_PARTICLE on average. */
static int plan_bits(mf_nlist *nl, list_build *lb)
{
    const size_t np = lb->g->np, ncells = lb->g->ncells;
    lb->cell_word = NULL;
    lb->bits = NULL;
    lb->range_slots = 1 + 2 * (size_t)lb->nrows;
    const size_t words_bytes = (ncells + 1) * sizeof(size_t);
    const size_t ranges_bytes =
        (ncells * lb->range_slots * sizeof(uint32_t) + sizeof(uint64_t) - 1) /
        sizeof(uint64_t) * sizeof(uint64_t);
    const size_t head = words_bytes + ranges_bytes;
    /* Grow only: the bits that follow the offsets need the space again. */
    if (!nl->work || nl->work_bytes < head)
        MF_CALL(ensure_work(nl, head));
    size_t *cell_word = nl->work;
    lb->cell_word = cell_word;
    lb->cell_ranges = (uint32_t *)((char *)nl->work + words_bytes);
    plan_pass(lb);
    cell_word[0] = 0;
    for (size_t c = 0; c < ncells; c++)
        cell_word[c + 1] += cell_word[c];
    const size_t total = cell_word[ncells];
    if (total > MAX_BIT_WORDS_PER_PARTICLE * np) {
        lb->cell_word = NULL;
        return 0;
    }
    const size_t need = head + total * sizeof(uint64_t);
    if (nl->work_bytes < need) { /* grow, keeping the offsets and ranges just planned */
        size_t cap = with_headroom(need);
        if (mf_resize(&nl->work, cap, 1))
            return MF_ERROR(MF_ERR_MEMORY, "cannot allocate neighbour list scratch (%zu bytes)",
                            cap);
        nl->work_bytes = cap;
        cell_word = nl->work;
        lb->cell_word = cell_word;
        lb->cell_ranges = (uint32_t *)((char *)nl->work + words_bytes);
    }
    lb->bits = (uint64_t *)((char *)nl->work + head);
    return 0;
}

int mf_nlist_build(mf_nlist *nl, const mf_grid *g, const mf_particles *p, double radius)
{
    return mf_nlist_build_pair(nl, NULL, g, p, radius, 0.0);
}

int mf_nlist_build_pair(mf_nlist *nl, mf_nlist *sub, const mf_grid *g, const mf_particles *p,
                        double radius, double sub_radius)
{
    if (!nl || !g || !p || nl == sub)
        return MF_ERROR(MF_ERR_INPUT, "mf_nlist_build: NULL list, grid or particles");
    if (!(radius * radius > 0.0) || radius > g->reach * g->cell_size)
        return MF_ERROR(MF_ERR_INPUT,
                        "neighbour radius %g must be positive and at most %d times the cell "
                        "size %g",
                        radius, g->reach, g->cell_size);
    if (sub && (!(sub_radius * sub_radius > 0.0) || sub_radius > radius))
        return MF_ERROR(MF_ERR_INPUT,
                        "sub-list radius %g must be positive and at most the list radius %g",
                        sub_radius, radius);
    if (g->np != p->n || g->dim != p->dim)
        return MF_ERROR(MF_ERR_INPUT,
                        "grid is stale: built for %zu particles in %d-D, now %zu in %d-D "
                        "(call mf_grid_build first)",
                        g->np, g->dim, p->n, p->dim);
    const size_t n = g->np;
    MF_CALL(ensure_start(nl, n));
    nl->n = 0;
    nl->radius = radius;
    if (sub) {
        MF_CALL(ensure_start(sub, n));
        sub->n = 0;
        sub->radius = sub_radius;
    }
    /* The old entries are dead from here; their pages, given back now, are
     * not resident beside the scratch of the plan and count passes (the
     * fill pass writes every entry again before anything reads one). */
    if (nl->j)
        (void)mf_release_pages(nl->j, nl->cap_j * sizeof *nl->j);
    if (sub && sub->j)
        (void)mf_release_pages(sub->j, sub->cap_j * sizeof *sub->j);

    list_build lb = {
        .g = g,
        .t = {g->spos, g->spos + n, g->spos + 2 * n, radius * radius,
              sub ? sub_radius * sub_radius : 0.0},
        .radius = radius,
        .ni = p->n_owned < n ? p->n_owned : n,
        .inv_width = 1.0 / binning_width(g->cell_size),
        .nrows = rows_per_cell(g->dim, g->reach),
    };
    MF_CALL(plan_bits(nl, &lb));
    count_pass(&lb, nl->start, sub ? sub->start : NULL);
    MF_CALL(counts_to_offsets(nl->start, n));
    MF_CALL(ensure_entries(nl, nl->start[n] > 0 ? nl->start[n] : 1));
    if (sub) {
        MF_CALL(counts_to_offsets(sub->start, n));
        MF_CALL(ensure_entries(sub, sub->start[n] > 0 ? sub->start[n] : 1));
    }
    fill_pass(&lb, nl->start, nl->j, sub ? sub->start : NULL, sub ? sub->j : NULL);
    nl->n = n;
    if (sub)
        sub->n = n;
    return 0;
}

/* ---- order ----------------------------------------------------------------- */

/* Does (ka, a) come before (kb, b)? By the keys alone when they hold the
 * index (packed, a literal at the call sites). */
KERNEL bool before(uint64_t ka, uint32_t a, uint64_t kb, uint32_t b, bool packed)
{
    return packed ? ka < kb : ka < kb || (ka == kb && a < b);
}

/* Insertion sort of one list; in order, it costs a load and a compare an
 * entry. */
KERNEL void sort_one(uint32_t *e, uint32_t m, const uint64_t *keys, bool packed)
{
    if (m < 2)
        return;
    uint64_t kprev = keys[e[0]];
    for (uint32_t a = 1; a < m; a++) {
        const uint32_t v = e[a];
        const uint64_t kv = keys[v];
        if (!before(kv, v, kprev, e[a - 1], packed)) {
            kprev = kv;
            continue;
        }
        uint32_t b = a;
        do {
            e[b] = e[b - 1];
            b--;
        } while (b > 0 && before(kv, v, keys[e[b - 1]], e[b - 1], packed));
        e[b] = v;
        kprev = keys[e[a]];
    }
}

void mf_nlist_sort(mf_nlist *nl, const uint64_t *keys, bool packed)
{
    const long n = (long)nl->n;
    const uint32_t *start = nl->start;
    uint32_t *jl = nl->j;
#pragma omp parallel for schedule(dynamic, 256)
    for (long i = 0; i < n; i++) {
        if (packed)
            sort_one(jl + start[i], start[i + 1] - start[i], keys, true);
        else
            sort_one(jl + start[i], start[i + 1] - start[i], keys, false);
    }
}

/* The lists that hold a particle whose cell changed: by symmetry, those of
 * the moved particles' own neighbours. */
static inline bool changed_cell(const uint64_t *keys, const uint32_t *cell_before, size_t j)
{
    return (uint32_t)(keys[j] >> 32) != cell_before[j];
}

void mf_nlist_mark_moved(const mf_nlist *nl, const uint64_t *keys, const uint32_t *cell_before,
                         size_t n_rows, uint8_t *dirty)
{
    const size_t n = nl->n;
    const uint32_t *start = nl->start, *jl = nl->j;
    if (n_rows > n)
        n_rows = n;
    memset(dirty, 0, n);
    for (size_t j = 0; j < n_rows; j++) /* serial: a few particles change cell a step */
        if (changed_cell(keys, cell_before, j))
            for (uint32_t e = start[j]; e < start[j + 1]; e++)
                dirty[jl[e]] = 1;
    bool copy_moved = false; /* a copy's row is empty: who holds it is not known */
    for (size_t j = n_rows; j < n && !copy_moved; j++)
        copy_moved = changed_cell(keys, cell_before, j);
    if (!copy_moved)
        return;
    for (size_t i = 0; i < n_rows; i++)
        for (uint32_t e = start[i]; !dirty[i] && e < start[i + 1]; e++)
            dirty[i] = jl[e] >= n_rows && changed_cell(keys, cell_before, jl[e]);
}

/* Only a marked list can be out of order: the others hold only particles
 * whose key is the one they were sorted by. */
void mf_nlist_sort_marked(mf_nlist *nl, const uint64_t *keys, bool packed, const uint8_t *dirty)
{
    const long n = (long)nl->n;
    const uint32_t *start = nl->start;
    uint32_t *jl = nl->j;
#pragma omp parallel for schedule(dynamic, 256)
    for (long i = 0; i < n; i++) {
        if (!dirty[i])
            continue;
        if (packed)
            sort_one(jl + start[i], start[i + 1] - start[i], keys, true);
        else
            sort_one(jl + start[i], start[i + 1] - start[i], keys, false);
    }
}

/* ---- filtering ------------------------------------------------------------ */

/* Squared distance of particles i and j, computed as in the list build. */
static inline double distance2(const double *pos, int dim, size_t i, size_t j)
{
    const double *a = pos + 3 * i, *b = pos + 3 * j;
    double dx = b[0] - a[0], dy = b[1] - a[1];
    double d2 = dx * dx + dy * dy;
    if (dim == 3) {
        double dz = b[2] - a[2];
        d2 += dz * dz;
    }
    return d2;
}

int mf_nlist_filter(mf_nlist *nl, const mf_nlist *from, const mf_particles *p, double radius)
{
    if (!nl || !from || !p)
        return MF_ERROR(MF_ERR_INPUT, "mf_nlist_filter: NULL list or particles");
    if (nl == from)
        return MF_ERROR(MF_ERR_INPUT, "mf_nlist_filter: output and input lists must differ");
    if (!(radius * radius > 0.0) || radius > from->radius)
        return MF_ERROR(MF_ERR_INPUT,
                        "filter radius %g must be positive and at most the list radius %g",
                        radius, from->radius);
    if (from->n != p->n)
        return MF_ERROR(MF_ERR_INPUT, "neighbour list covers %zu particles, the store holds %zu",
                        from->n, p->n);
    const size_t n = from->n;
    MF_CALL(ensure_start(nl, n));
    nl->n = 0;
    nl->radius = radius;
    const double r2 = radius * radius;
    const double *pos = p->pos;
    const int dim = p->dim;
    uint32_t *start = nl->start;

#pragma omp parallel for schedule(dynamic, 256)
    for (size_t i = 0; i < n; i++) {
        size_t count = 0;
        for (size_t e = from->start[i]; e < from->start[i + 1]; e++)
            count += distance2(pos, dim, i, from->j[e]) < r2;
        start[i + 1] = (uint32_t)count;
    }
    MF_CALL(counts_to_offsets(start, n));
    MF_CALL(ensure_entries(nl, start[n] > 0 ? start[n] : 1));
    uint32_t *jlist = nl->j;
#pragma omp parallel for schedule(dynamic, 256)
    for (size_t i = 0; i < n; i++) {
        uint32_t *out = jlist + start[i];
        for (size_t e = from->start[i]; e < from->start[i + 1]; e++)
            /* Testing again is as fast as keeping a byte per entry of `from`,
             * and needs no memory. */
            if (distance2(pos, dim, i, from->j[e]) < r2)
                *out++ = from->j[e];
    }
    nl->n = n;
    return 0;
}
