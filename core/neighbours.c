/* neighbours.c: occupied-cell grid and CSR neighbour lists (mf_neighbours.h).
 *
 * Grid build, O(N) time, memory in particles and occupied cells:
 *   1. bounding box -> origin and box size in cells;
 *   2. each particle gets a compact sort key (ix | iy << bx | iz << (bx+by),
 *      bx, by, bz the bits the box needs per axis): it orders cells like the
 *      public 21-bit key but needs fewer radix passes;
 *   3. stable LSD radix sort of (key, index) pairs;
 *   4. distinct keys are the occupied cells; a hash table maps the public key
 *      of a cell to its index;
 *   5. for each cell, the 3^dim neighbouring cells form 3^(dim-1) rows along
 *      x; the occupied cells of a row are consecutive in key order, so a row
 *      is one range of sorted particles, stored per cell;
 *   6. positions are copied in cell order (structure of arrays), so that the
 *      list build streams through contiguous memory.
 *
 * List build, two parallel passes over cells:
 *   count: test every candidate of every particle, store the outcome as one
 *          bit per candidate and the count per particle;
 *   fill:  after a prefix sum of the counts, turn the set bits into indices.
 * The distance test thus runs once per candidate, and both passes read the
 * same bits, so they cannot disagree. The j's of a particle come in row and
 * cell order, the same for any thread count. When the bits would take too
 * much memory (cells much larger than the radius) the fill pass repeats the
 * distance test instead.
 */
#include "mf_neighbours.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* The kernels take dim and keep_bits as arguments but are called with
 * literals; forced inlining makes each combination its own branch-free loop. */
#define KERNEL static inline __attribute__((always_inline))

#define EMPTY_SLOT UINT32_MAX
#define AXIS_LIMIT ((uint64_t)1 << MF_GRID_AXIS_BITS)
#define AXIS_MASK (AXIS_LIMIT - 1)
#define RADIX_BITS 11
#define RADIX_SIZE (1u << RADIX_BITS)
#define MAX_ROWS 9
/* Candidate bits allowed per particle, on average, before the fill pass
 * falls back to repeating the distance test (bounds the scratch memory). */
#define MAX_BIT_WORDS_PER_PARTICLE 16

/* ---- small helpers ------------------------------------------------------ */

/* splitmix64 finalizer: consecutive keys (neighbouring cells) land far apart
 * in the table. */
static inline uint64_t mix64(uint64_t x)
{
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ULL;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebULL;
    x ^= x >> 31;
    return x;
}

/* Bits needed to store values 0 .. n-1. */
static int bits_for(uint64_t n)
{
    int b = 0;
    while (b < 64 && (n - 1) >> b)
        b++;
    return b;
}

static double binning_width(double cell_size)
{
    return cell_size * (1.0 + MF_GRID_CELL_SLACK);
}

static int rows_per_cell(int dim)
{
    return dim == 3 ? 9 : 3;
}

/* Free-and-allocate: contents never need to survive a rebuild, so avoid the
 * copy realloc would make. */
static int replace_buffer(void **buf, size_t count, size_t elem_size, const char *what)
{
    free(*buf);
    *buf = NULL;
    if (count > SIZE_MAX / elem_size)
        return MF_ERROR(MF_ERR_MEMORY, "neighbour %s: %zu elements is too many", what, count);
    *buf = malloc(count * elem_size);
    if (!*buf)
        return MF_ERROR(MF_ERR_MEMORY, "cannot allocate neighbour %s (%zu bytes)", what,
                        count * elem_size);
    return 0;
}

/* Capacity policy for reused buffers: grow with 1/8 headroom (particle
 * counts drift between steps), shrink when four times too large. */
static bool needs_realloc(size_t have, size_t need)
{
    return need > have || (have > 1024 && need < have / 4);
}

static size_t with_headroom(size_t need)
{
    size_t extra = need / 8;
    return need > SIZE_MAX - extra - 1 ? need : need + extra + 1;
}

/* ---- grid: memory ----------------------------------------------------- */

void mf_grid_init(mf_grid *g)
{
    memset(g, 0, sizeof *g);
}

void mf_grid_free(mf_grid *g)
{
    if (!g)
        return;
    free(g->cell_key);
    free(g->cell_start);
    free(g->cell_rows);
    free(g->order);
    free(g->hash_key);
    free(g->hash_cell);
    free(g->spos);
    free(g->sort_key);
    free(g->sort_idx);
    mf_grid_init(g);
}

static void free_np_buffers(mf_grid *g)
{
    free(g->order);
    free(g->spos);
    free(g->sort_key);
    free(g->sort_idx);
    g->order = NULL;
    g->spos = NULL;
    g->sort_key = NULL;
    g->sort_idx = NULL;
    g->alloc_np = 0;
}

static int ensure_np_buffers(mf_grid *g, size_t np)
{
    if (g->order && !needs_realloc(g->alloc_np, np))
        return 0;
    size_t cap = with_headroom(np);
    free_np_buffers(g);
    if (cap > SIZE_MAX / 3 / sizeof(double))
        return MF_ERROR(MF_ERR_MEMORY, "neighbour grid for %zu particles is too large", np);
    int rc = 0;
    if ((rc = replace_buffer((void **)&g->order, cap, sizeof(size_t), "particle order")) ||
        (rc = replace_buffer((void **)&g->spos, 3 * cap, sizeof(double), "sorted positions")) ||
        (rc = replace_buffer((void **)&g->sort_key, 2 * cap, sizeof(uint64_t), "sort keys")) ||
        (rc = replace_buffer((void **)&g->sort_idx, 2 * cap, sizeof(uint32_t), "sort indices"))) {
        free_np_buffers(g);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    g->alloc_np = cap;
    return 0;
}

static void free_cell_buffers(mf_grid *g)
{
    free(g->cell_key);
    free(g->cell_start);
    free(g->cell_rows);
    g->cell_key = NULL;
    g->cell_start = NULL;
    g->cell_rows = NULL;
    g->alloc_cells = 0;
}

/* Rows are sized for 3-D so that a grid can switch dimension. */
static int ensure_cell_buffers(mf_grid *g, size_t ncells)
{
    if (g->cell_start && !needs_realloc(g->alloc_cells, ncells))
        return 0;
    size_t cap = with_headroom(ncells);
    free_cell_buffers(g);
    if (cap > SIZE_MAX / (2 * MAX_ROWS * sizeof(uint32_t)))
        return MF_ERROR(MF_ERR_MEMORY, "neighbour grid with %zu cells is too large", ncells);
    int rc = 0;
    if ((rc = replace_buffer((void **)&g->cell_key, cap, sizeof(uint64_t), "cell keys")) ||
        (rc = replace_buffer((void **)&g->cell_start, cap + 1, sizeof(size_t), "cell starts")) ||
        (rc = replace_buffer((void **)&g->cell_rows, 2 * MAX_ROWS * cap, sizeof(uint32_t),
                             "cell rows"))) {
        free_cell_buffers(g);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    g->alloc_cells = cap;
    return 0;
}

/* Table of capacity a power of two >= 2 * ncells (load <= 1/2 keeps probe
 * sequences short); reused unless more than 4 times too large. */
static int ensure_hash(mf_grid *g, size_t ncells)
{
    size_t need = 16;
    while (need < 2 * ncells) {
        if (need > SIZE_MAX / 2)
            return MF_ERROR(MF_ERR_MEMORY, "hash table for %zu cells is too large", ncells);
        need *= 2;
    }
    if (!g->hash_key || g->hash_cap < need || g->hash_cap > 4 * need) {
        int rc = 0;
        g->hash_cap = 0;
        if ((rc = replace_buffer((void **)&g->hash_key, need, sizeof(uint64_t), "hash keys")) ||
            (rc = replace_buffer((void **)&g->hash_cell, need, sizeof(uint32_t), "hash cells"))) {
            free(g->hash_key);
            free(g->hash_cell);
            g->hash_key = NULL;
            g->hash_cell = NULL;
            return mf_error_trace(rc, __FILE__, __LINE__, __func__);
        }
        g->hash_cap = need;
    }
    /* All bytes 0xFF gives UINT32_MAX, the empty mark. */
    memset(g->hash_cell, 0xFF, g->hash_cap * sizeof(uint32_t));
    return 0;
}

size_t mf_grid_memory(const mf_grid *g)
{
    if (!g)
        return 0;
    size_t per_particle = sizeof(size_t) + 3 * sizeof(double) + 2 * sizeof(uint64_t) +
                          2 * sizeof(uint32_t);
    size_t per_cell = sizeof(uint64_t) + sizeof(size_t) + 2 * MAX_ROWS * sizeof(uint32_t);
    size_t bytes = g->alloc_np * per_particle;
    if (g->cell_start)
        bytes += g->alloc_cells * per_cell + sizeof(size_t);
    bytes += g->hash_cap * (sizeof(uint64_t) + sizeof(uint32_t));
    return bytes;
}

/* ---- grid: cells and hash table ------------------------------------------ */

static void hash_insert(mf_grid *g, uint64_t key, uint32_t cell)
{
    size_t mask = g->hash_cap - 1;
    size_t h = (size_t)mix64(key) & mask;
    while (g->hash_cell[h] != EMPTY_SLOT)
        h = (h + 1) & mask;
    g->hash_key[h] = key;
    g->hash_cell[h] = cell;
}

long mf_grid_find_cell(const mf_grid *g, uint64_t key)
{
    if (!g || g->ncells == 0)
        return -1;
    size_t mask = g->hash_cap - 1;
    size_t h = (size_t)mix64(key) & mask;
    while (g->hash_cell[h] != EMPTY_SLOT) {
        if (g->hash_key[h] == key)
            return (long)g->hash_cell[h];
        h = (h + 1) & mask;
    }
    return -1;
}

/* Integer cell coordinate of x on one axis; the same expression is used
 * everywhere so that a point always lands in the same cell. */
static inline uint64_t cell_coord(double x, double origin, double inv_width)
{
    return (uint64_t)floor((x - origin) * inv_width);
}

long mf_grid_point_cell(const mf_grid *g, const double x[3])
{
    if (!g || g->ncells == 0 || !x)
        return -1;
    double inv_width = 1.0 / binning_width(g->cell_size);
    uint64_t c[3] = {0, 0, 0};
    for (int d = 0; d < g->dim; d++) {
        double u = (x[d] - g->origin[d]) * inv_width;
        if (!(u >= 0.0) || u >= (double)g->nbox[d])
            return -1;
        c[d] = cell_coord(x[d], g->origin[d], inv_width);
        if (c[d] >= g->nbox[d])
            return -1;
    }
    return mf_grid_find_cell(g, mf_grid_key(c[0], c[1], c[2]));
}

/* The rows of cells around cell c as ranges [a, b) of sorted particles,
 * into rows[2 * r], rows[2 * r + 1] (a == b for an empty row). */
static void find_rows(const mf_grid *g, size_t c, uint32_t *rows)
{
    const uint64_t key = g->cell_key[c];
    const uint64_t ix = key & AXIS_MASK;
    const uint64_t iy = (key >> MF_GRID_AXIS_BITS) & AXIS_MASK;
    const uint64_t iz = key >> (2 * MF_GRID_AXIS_BITS);
    const uint64_t x0 = ix > 0 ? ix - 1 : 0;
    const uint64_t x1 = ix + 1 < g->nbox[0] ? ix + 1 : ix;
    int r = 0;
    for (int dz = -1; dz <= 1; dz++) {
        if (g->dim == 2 && dz != 0)
            continue;
        for (int dy = -1; dy <= 1; dy++, r++) {
            rows[2 * r] = rows[2 * r + 1] = 0;
            if ((dz < 0 && iz == 0) || (dz > 0 && iz + 1 >= g->nbox[2]) || (dy < 0 && iy == 0) ||
                (dy > 0 && iy + 1 >= g->nbox[1]))
                continue;
            const uint64_t y = iy + (uint64_t)(int64_t)dy, z = iz + (uint64_t)(int64_t)dz;
            long first = -1, last = -1;
            const uint64_t mid_key = mf_grid_key(ix, y, z);
            long mid = dy == 0 && dz == 0 ? (long)c : mf_grid_find_cell(g, mid_key);
            if (mid >= 0) {
                /* Cells are sorted by key: the x-neighbours of an occupied
                 * cell, if occupied, are the cells next to it. */
                first = last = mid;
                if (x0 < ix && mid > 0 && g->cell_key[mid - 1] == mid_key - 1)
                    first = mid - 1;
                if (x1 > ix && (size_t)mid + 1 < g->ncells && g->cell_key[mid + 1] == mid_key + 1)
                    last = mid + 1;
            } else {
                for (uint64_t x = x0; x <= x1; x++) {
                    long cell = x == ix ? -1 : mf_grid_find_cell(g, mf_grid_key(x, y, z));
                    if (cell >= 0) {
                        if (first < 0)
                            first = cell;
                        last = cell;
                    }
                }
            }
            if (first >= 0) {
                rows[2 * r] = (uint32_t)g->cell_start[first];
                rows[2 * r + 1] = (uint32_t)g->cell_start[last + 1];
            }
        }
    }
}

/* ---- grid: build -------------------------------------------------------- */

/* Leave a failed build as a valid empty grid. */
static void make_empty(mf_grid *g)
{
    g->np = 0;
    g->ncells = 0;
    if (g->cell_start)
        g->cell_start[0] = 0;
    if (g->hash_cell)
        memset(g->hash_cell, 0xFF, g->hash_cap * sizeof(uint32_t));
}

/* Bounding box of the first n particles; fails on a non-finite coordinate
 * (it would poison the cell coordinates). */
static int bounding_box(const mf_particles *p, size_t n, double lo[3], double hi[3])
{
    const double *pos = p->pos;
    const int dim = p->dim;
    double x0 = INFINITY, y0 = INFINITY, z0 = INFINITY;
    double x1 = -INFINITY, y1 = -INFINITY, z1 = -INFINITY;
    size_t bad = 0;
#pragma omp parallel for schedule(static) reduction(min : x0, y0, z0) \
    reduction(max : x1, y1, z1) reduction(+ : bad)
    for (size_t i = 0; i < n; i++) {
        const double *x = pos + 3 * i;
        double z = dim == 3 ? x[2] : 0.0;
        if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(z))
            bad++;
        /* Not fmin/fmax: those are library calls at -O2. */
        x0 = x[0] < x0 ? x[0] : x0;
        x1 = x[0] > x1 ? x[0] : x1;
        y0 = x[1] < y0 ? x[1] : y0;
        y1 = x[1] > y1 ? x[1] : y1;
        z0 = z < z0 ? z : z0;
        z1 = z > z1 ? z : z1;
    }
    if (bad) {
        for (size_t i = 0; i < n; i++) {
            const double *x = pos + 3 * i;
            if (!isfinite(x[0]) || !isfinite(x[1]) || (dim == 3 && !isfinite(x[2])))
                return MF_ERROR(MF_ERR_NUMERIC,
                                "particle %zu has a non-finite position (%g, %g, %g); %zu such",
                                i, x[0], x[1], x[2], bad);
        }
    }
    lo[0] = x0, lo[1] = y0, lo[2] = z0;
    hi[0] = x1, hi[1] = y1, hi[2] = z1;
    return 0;
}

/* Stable LSD radix sort of (key, idx) on the low `bits` bits of key.
 * key/idx hold 2 * n entries: the input in the first half; returns the half
 * (0 or 1) holding the sorted output. Passes are balanced so that a 14-bit
 * key takes two 7-bit passes and not an 11-bit and a 3-bit one. */
static int radix_sort(uint64_t *key, uint32_t *idx, size_t n, int bits)
{
    if (bits == 0 || n < 2)
        return 0;
    int passes = (bits + RADIX_BITS - 1) / RADIX_BITS;
    int digit_bits = (bits + passes - 1) / passes;
    uint64_t digit_mask = ((uint64_t)1 << digit_bits) - 1;
    size_t count[RADIX_SIZE];
    int src = 0;
    for (int pass = 0; pass < passes; pass++) {
        int shift = pass * digit_bits;
        const uint64_t *ks = key + src * n;
        const uint32_t *is = idx + src * n;
        uint64_t *kd = key + (1 - src) * n;
        uint32_t *id = idx + (1 - src) * n;
        memset(count, 0, sizeof count);
        for (size_t i = 0; i < n; i++)
            count[(ks[i] >> shift) & digit_mask]++;
        size_t sum = 0;
        for (size_t d = 0; d <= digit_mask; d++) {
            size_t c = count[d];
            count[d] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++) {
            size_t dst = count[(ks[i] >> shift) & digit_mask]++;
            kd[dst] = ks[i];
            id[dst] = is[i];
        }
        src = 1 - src;
    }
    return src;
}

int mf_grid_build(mf_grid *g, const mf_particles *p, double cell_size)
{
    if (!g || !p)
        return MF_ERROR(MF_ERR_INPUT, "mf_grid_build: NULL grid or particles");
    if (!(cell_size > 0.0) || !isfinite(cell_size))
        return MF_ERROR(MF_ERR_INPUT, "neighbour cell size must be positive and finite, got %g",
                        cell_size);
    if (p->dim != 2 && p->dim != 3)
        return MF_ERROR(MF_ERR_INPUT, "particle dimension must be 2 or 3, got %d", p->dim);
    const size_t np = p->n;
    if (np >= UINT32_MAX)
        return MF_ERROR(MF_ERR_INPUT,
                        "%zu particles on one rank: neighbour indices are 32-bit (limit %u)", np,
                        UINT32_MAX - 1);
    const int dim = p->dim;
    g->dim = dim;
    g->cell_size = cell_size;
    make_empty(g);

    int rc = 0;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    if (np > 0)
        MF_CALL_GOTO(rc, bounding_box(p, np, lo, hi), fail);

    /* The margin keeps the lowest particles off the origin face, so they do
     * not depend on how x - origin rounds. */
    const double inv_width = 1.0 / binning_width(cell_size);
    const double margin = 1e-3 * cell_size;
    int axis_bits[3] = {0, 0, 0};
    for (int d = 0; d < 3; d++) {
        g->origin[d] = d < dim ? lo[d] - margin : 0.0;
        g->nbox[d] = 1;
        if (d >= dim || np == 0)
            continue;
        double span = (hi[d] - g->origin[d]) * inv_width;
        if (!(span < (double)(AXIS_LIMIT - 1)))
            MF_CALL_GOTO(rc,
                         MF_ERROR(MF_ERR_INPUT,
                                  "particles span %g on axis %c, more than 2^%d cells of size %g: "
                                  "the spacing is too small for the domain extent (or a particle "
                                  "has escaped)",
                                  hi[d] - lo[d], "xyz"[d], MF_GRID_AXIS_BITS, cell_size),
                         fail);
        g->nbox[d] = cell_coord(hi[d], g->origin[d], inv_width) + 1;
        axis_bits[d] = bits_for(g->nbox[d]);
    }

    MF_CALL_GOTO(rc, ensure_np_buffers(g, np > 0 ? np : 1), fail);

    /* Compact sort keys: same order as the public key, fewer bits. */
    {
        const double *pos = p->pos;
        const double o0 = g->origin[0], o1 = g->origin[1], o2 = g->origin[2];
        const int sy = axis_bits[0], sz = axis_bits[0] + axis_bits[1];
        uint64_t *key = g->sort_key;
        uint32_t *idx = g->sort_idx;
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < np; i++) {
            const double *x = pos + 3 * i;
            uint64_t k = cell_coord(x[0], o0, inv_width) | cell_coord(x[1], o1, inv_width) << sy;
            if (dim == 3)
                k |= cell_coord(x[2], o2, inv_width) << sz;
            key[i] = k;
            idx[i] = (uint32_t)i;
        }
    }
    const int total_bits = axis_bits[0] + axis_bits[1] + axis_bits[2];
    const int half = radix_sort(g->sort_key, g->sort_idx, np, total_bits);
    const uint64_t *skey = g->sort_key + half * np;
    const uint32_t *sidx = g->sort_idx + half * np;

    size_t ncells = np > 0 ? 1 : 0;
    for (size_t k = 1; k < np; k++)
        ncells += skey[k] != skey[k - 1];
    MF_CALL_GOTO(rc, ensure_cell_buffers(g, ncells), fail);
    MF_CALL_GOTO(rc, ensure_hash(g, ncells), fail);

    /* Cells: starts and public keys. */
    {
        const uint64_t mx = ((uint64_t)1 << axis_bits[0]) - 1;
        const uint64_t my = ((uint64_t)1 << axis_bits[1]) - 1;
        const int sy = axis_bits[0], sz = axis_bits[0] + axis_bits[1];
        size_t c = 0;
        for (size_t k = 0; k < np; k++) {
            if (k == 0 || skey[k] != skey[k - 1]) {
                uint64_t s = skey[k];
                g->cell_key[c] = mf_grid_key(s & mx, (s >> sy) & my, s >> sz);
                g->cell_start[c] = k;
                c++;
            }
        }
        g->cell_start[ncells] = np;
    }
    g->ncells = ncells;
    for (size_t c = 0; c < ncells; c++)
        hash_insert(g, g->cell_key[c], (uint32_t)c);

    /* Rows of neighbouring cells, once per cell for all later list builds. */
    {
        const int stride = 2 * rows_per_cell(dim);
#pragma omp parallel for schedule(static)
        for (size_t c = 0; c < ncells; c++)
            find_rows(g, c, g->cell_rows + c * stride);
    }

    /* Order and positions in cell order. */
    {
        const double *pos = p->pos;
        size_t *order = g->order;
        double *sx = g->spos, *sy = g->spos + np, *sz = g->spos + 2 * np;
#pragma omp parallel for schedule(static)
        for (size_t k = 0; k < np; k++) {
            size_t i = sidx[k];
            order[k] = i;
            sx[k] = pos[3 * i];
            sy[k] = pos[3 * i + 1];
            sz[k] = dim == 3 ? pos[3 * i + 2] : 0.0;
        }
    }
    g->np = np;
    return 0;

fail:
    make_empty(g);
    return rc;
}

int mf_grid_locality_order(const mf_grid *g, size_t *perm)
{
    if (!g || (!perm && g->np > 0))
        return MF_ERROR(MF_ERR_INPUT, "mf_grid_locality_order: NULL grid or output");
    if (g->np > 0)
        memcpy(perm, g->order, g->np * sizeof *perm);
    return 0;
}

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

size_t mf_nlist_memory(const mf_nlist *nl)
{
    if (!nl)
        return 0;
    return nl->cap_n * sizeof(size_t) + nl->cap_j * sizeof(uint32_t) + nl->work_bytes;
}

static int ensure_start(mf_nlist *nl, size_t n)
{
    if (nl->start && !needs_realloc(nl->cap_n, n + 1))
        return 0;
    nl->cap_n = 0;
    size_t cap = with_headroom(n + 1);
    MF_CALL(replace_buffer((void **)&nl->start, cap, sizeof(size_t), "list starts"));
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

/* Scratch of at least `bytes`, 8-byte aligned (malloc's alignment). */
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

/* start[i + 1] holds the count of i on entry; start becomes offsets. */
static void counts_to_offsets(size_t *start, size_t n)
{
    start[0] = 0;
    for (size_t i = 0; i < n; i++)
        start[i + 1] += start[i];
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

/* Candidates m, m + 1 closer than the radius: lanes -1 (in) or 0 (out). */
KERNEL vec2i within2(const pair_test *t, size_t m, const double xi[3], int dim)
{
    vec2d dx = load2(t->sx + m) - splat2(xi[0]);
    vec2d dy = load2(t->sy + m) - splat2(xi[1]);
    vec2d d2 = dx * dx + dy * dy;
    if (dim == 3) {
        vec2d dz = load2(t->sz + m) - splat2(xi[2]);
        d2 += dz * dz;
    }
    return d2 < splat2(t->r2);
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

KERNEL bool within1(const pair_test *t, size_t m, const double xi[3], int dim)
{
    double dx = t->sx[m] - xi[0], dy = t->sy[m] - xi[1];
    double d2 = dx * dx + dy * dy;
    if (dim == 3) {
        double dz = t->sz[m] - xi[2];
        d2 += dz * dz;
    }
    return d2 < t->r2;
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
 * store the outcomes as bits in words. Returns the count of hits, the
 * particle itself included (its distance 0 is < r2). dim and keep_bits are
 * literals at the call sites, so each combination compiles to its own loop. */
KERNEL size_t test_candidates(const pair_test *t, const uint32_t *rows, int nrows,
                              const double xi[3], int dim, bool keep_bits, uint64_t *words)
{
    vec2i hits = {0, 0};
    uint64_t acc = 0;
    unsigned bit = 0;
    for (int r = 0; r < nrows; r++) {
        size_t m = rows[2 * r];
        const size_t b = rows[2 * r + 1];
        for (; m + 2 <= b; m += 2) {
            vec2i h = within2(t, m, xi, dim);
            hits -= h;
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
            uint64_t h = within1(t, m, xi, dim);
            hits[0] += (int64_t)h;
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
    return (size_t)(hits[0] + hits[1]);
}

/* Append the particle indices of the set bits (other than k itself). */
KERNEL size_t decode_bits(const uint64_t *words, size_t nwords, const uint32_t *rows,
                          const size_t row_bit[MAX_ROWS + 1], const size_t *order, size_t k,
                          uint32_t *out)
{
    size_t w = 0;
    int r = 0;
    for (size_t wi = 0; wi < nwords; wi++) {
        uint64_t word = words[wi];
        while (word) {
            size_t bit = 64 * wi + (size_t)__builtin_ctzll(word);
            word &= word - 1;
            while (bit >= row_bit[r + 1])
                r++;
            size_t m = rows[2 * r] + (bit - row_bit[r]);
            if (m != k)
                out[w++] = (uint32_t)order[m];
        }
    }
    return w;
}

/* Fallback fill without bits: repeat the distance test. */
KERNEL size_t retest_candidates(const pair_test *t, const uint32_t *rows, int nrows,
                                const size_t *order, size_t k, const double xi[3], int dim,
                                uint32_t *out)
{
    size_t w = 0;
    for (int r = 0; r < nrows; r++) {
        size_t m = rows[2 * r];
        const size_t b = rows[2 * r + 1];
        for (; m + 2 <= b; m += 2) {
            vec2i h = within2(t, m, xi, dim);
            if (h[0] && m != k)
                out[w++] = (uint32_t)order[m];
            if (h[1] && m + 1 != k)
                out[w++] = (uint32_t)order[m + 1];
        }
        if (m < b && within1(t, m, xi, dim) && m != k)
            out[w++] = (uint32_t)order[m];
    }
    return w;
}

/* ---- neighbour lists: the two passes -------------------------------------- */

typedef struct {
    const mf_grid *g;
    pair_test t;
    int nrows;
    const size_t *cell_word; /* ncells + 1 word offsets, or NULL: no bits */
    uint64_t *bits;
} list_build;

/* Pass 1: start[i + 1] = number of neighbours of i; bits if kept. */
KERNEL void count_cell(const list_build *lb, size_t c, int dim, bool keep_bits, size_t *start)
{
    const mf_grid *g = lb->g;
    const uint32_t *rows = g->cell_rows + (size_t)c * 2 * lb->nrows;
    const size_t k0 = g->cell_start[c], k1 = g->cell_start[c + 1];
    uint64_t *words = NULL;
    size_t nwords = 0;
    if (keep_bits) {
        words = lb->bits + lb->cell_word[c];
        nwords = (lb->cell_word[c + 1] - lb->cell_word[c]) / (k1 - k0);
    }
    for (size_t k = k0; k < k1; k++) {
        const double xi[3] = {lb->t.sx[k], lb->t.sy[k], lb->t.sz[k]};
        size_t hits = test_candidates(&lb->t, rows, lb->nrows, xi, dim, keep_bits,
                                      keep_bits ? words + (k - k0) * nwords : NULL);
        start[g->order[k] + 1] = hits - 1; /* minus the particle itself */
    }
}

static void count_pass(const list_build *lb, size_t *start)
{
    const size_t ncells = lb->g->ncells;
    const int dim = lb->g->dim;
    const bool keep_bits = lb->cell_word != NULL;
#pragma omp parallel for schedule(dynamic, 32)
    for (size_t c = 0; c < ncells; c++) {
        /* Literals let the compiler specialise the kernels. */
        if (dim == 3 && keep_bits)
            count_cell(lb, c, 3, true, start);
        else if (dim == 3)
            count_cell(lb, c, 3, false, start);
        else if (keep_bits)
            count_cell(lb, c, 2, true, start);
        else
            count_cell(lb, c, 2, false, start);
    }
}

/* Pass 2: j's at the offsets of pass 1, from the bits or by testing again. */
KERNEL void fill_cell(const list_build *lb, size_t c, int dim, const size_t *start,
                      uint32_t *jlist)
{
    const mf_grid *g = lb->g;
    const uint32_t *rows = g->cell_rows + (size_t)c * 2 * lb->nrows;
    const size_t k0 = g->cell_start[c], k1 = g->cell_start[c + 1];
    size_t row_bit[MAX_ROWS + 1], nwords = 0;
    if (lb->cell_word) {
        row_bit_offsets(rows, lb->nrows, row_bit);
        nwords = (lb->cell_word[c + 1] - lb->cell_word[c]) / (k1 - k0);
    }
    for (size_t k = k0; k < k1; k++) {
        uint32_t *out = jlist + start[g->order[k]];
        if (lb->cell_word) {
            const uint64_t *words = lb->bits + lb->cell_word[c] + (k - k0) * nwords;
            decode_bits(words, nwords, rows, row_bit, g->order, k, out);
        } else {
            const double xi[3] = {lb->t.sx[k], lb->t.sy[k], lb->t.sz[k]};
            retest_candidates(&lb->t, rows, lb->nrows, g->order, k, xi, dim, out);
        }
    }
}

static void fill_pass(const list_build *lb, const size_t *start, uint32_t *jlist)
{
    const size_t ncells = lb->g->ncells;
    const int dim = lb->g->dim;
#pragma omp parallel for schedule(dynamic, 32)
    for (size_t c = 0; c < ncells; c++) {
        if (dim == 3)
            fill_cell(lb, c, 3, start, jlist);
        else
            fill_cell(lb, c, 2, start, jlist);
    }
}

/* Lay out the candidate bits: word offsets per cell at the start of the
 * scratch, the bits after them. Leaves lb->cell_word NULL (no bits) when
 * they would exceed MAX_BIT_WORDS_PER_PARTICLE on average. */
static int plan_bits(mf_nlist *nl, list_build *lb)
{
    const mf_grid *g = lb->g;
    const size_t ncells = g->ncells;
    size_t total = 0;
    for (size_t c = 0; c < ncells; c++) {
        const uint32_t *rows = g->cell_rows + c * 2 * lb->nrows;
        total += words_per_particle(rows, lb->nrows) * (g->cell_start[c + 1] - g->cell_start[c]);
    }
    lb->cell_word = NULL;
    lb->bits = NULL;
    if (total > MAX_BIT_WORDS_PER_PARTICLE * g->np)
        return 0;
    MF_CALL(ensure_work(nl, (ncells + 1 + total) * sizeof(uint64_t)));
    size_t *cell_word = nl->work;
    size_t offset = 0;
    for (size_t c = 0; c < ncells; c++) {
        const uint32_t *rows = g->cell_rows + c * 2 * lb->nrows;
        cell_word[c] = offset;
        offset += words_per_particle(rows, lb->nrows) * (g->cell_start[c + 1] - g->cell_start[c]);
    }
    cell_word[ncells] = offset;
    lb->cell_word = cell_word;
    lb->bits = (uint64_t *)nl->work + (ncells + 1);
    return 0;
}

int mf_nlist_build(mf_nlist *nl, const mf_grid *g, const mf_particles *p, double radius)
{
    if (!nl || !g || !p)
        return MF_ERROR(MF_ERR_INPUT, "mf_nlist_build: NULL list, grid or particles");
    if (!(radius * radius > 0.0) || radius > g->cell_size)
        return MF_ERROR(MF_ERR_INPUT,
                        "neighbour radius %g must be positive and at most the cell size %g",
                        radius, g->cell_size);
    if (g->np != p->n || g->dim != p->dim)
        return MF_ERROR(MF_ERR_INPUT,
                        "grid is stale: built for %zu particles in %d-D, now %zu in %d-D "
                        "(call mf_grid_build first)",
                        g->np, g->dim, p->n, p->dim);
    const size_t n = g->np;
    MF_CALL(ensure_start(nl, n));
    nl->n = 0;
    nl->radius = radius;

    list_build lb = {
        .g = g,
        .t = {g->spos, g->spos + n, g->spos + 2 * n, radius * radius},
        .nrows = rows_per_cell(g->dim),
    };
    MF_CALL(plan_bits(nl, &lb));
    count_pass(&lb, nl->start);
    counts_to_offsets(nl->start, n);
    MF_CALL(ensure_entries(nl, nl->start[n] > 0 ? nl->start[n] : 1));
    fill_pass(&lb, nl->start, nl->j);
    nl->n = n;
    return 0;
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
    size_t *start = nl->start;

#pragma omp parallel for schedule(dynamic, 256)
    for (size_t i = 0; i < n; i++) {
        size_t count = 0;
        for (size_t e = from->start[i]; e < from->start[i + 1]; e++)
            count += distance2(pos, dim, i, from->j[e]) < r2;
        start[i + 1] = count;
    }
    counts_to_offsets(start, n);
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
