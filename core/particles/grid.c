/* grid.c: the occupied-cell grid (mf_neighbours.h); the lists are in nlist.c.
 *
 * Grid build, O(N) time, memory in particles and occupied cells:
 *   1. bounding box -> origin and box size in cells;
 *   2. each particle gets a compact sort key (ix | iy << bx | iz << (bx+by),
 *      bx, by, bz the bits the box needs per axis): it orders cells like the
 *      public 21-bit key but needs fewer radix passes;
 *   3. stable LSD radix sort of (key, index) pairs;
 *   4. distinct keys are the occupied cells; a hash table maps the public key
 *      of a cell to its index;
 *   5. for each cell, the (2 reach + 1)^dim cells around it form
 *      (2 reach + 1)^(dim-1) rows along x; the occupied cells of a row are
 *      consecutive in key order, so a row is known by its first occupied cell
 *      within reach, stored per cell (nlist.c turns it into ranges of sorted
 *      particles);
 *   6. positions are copied in cell order (structure of arrays), so that the
 *      list build streams through contiguous memory.
 *
 * The neighbour lists built on this grid are in nlist.c.
 */
#include "neighbours_internal.h"
#include "mf_pairs.h" /* the threads policy: MF_STREAM_CHUNK */

/* ---- grid: memory ----------------------------------------------------- */

static void free_sort_buffers(mf_grid *g);

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
    mf_hashmap_free(&g->cells);
    free(g->spos);
    free_sort_buffers(g);
    mf_grid_init(g);
}

static void free_sort_buffers(mf_grid *g)
{
    free(g->sort_key);
    free(g->sort_idx);
    g->sort_key = NULL;
    g->sort_idx = NULL;
    g->alloc_sort = 0;
}

static void free_np_buffers(mf_grid *g)
{
    free(g->order);
    free(g->spos);
    g->order = NULL;
    g->spos = NULL;
    g->alloc_np = 0;
    free_sort_buffers(g);
}

/* order and spos, kept with the grid; the radix sort's double buffers,
 * which mf_grid_release_scratch may free between builds. */
static int ensure_np_buffers(mf_grid *g, size_t np)
{
    int rc = 0;
    if (!g->order || needs_realloc(g->alloc_np, np)) {
        size_t cap = with_headroom(np);
        free_np_buffers(g);
        if (cap > SIZE_MAX / 3 / sizeof(double))
            return MF_ERROR(MF_ERR_MEMORY, "neighbour grid for %zu particles is too large", np);
        if ((rc = replace_buffer((void **)&g->order, cap, sizeof(uint32_t), "particle order")) ||
            (rc = replace_buffer((void **)&g->spos, 3 * cap, sizeof(double), "sorted positions"))) {
            free_np_buffers(g);
            return mf_error_trace(rc, __FILE__, __LINE__, __func__);
        }
        g->alloc_np = cap;
    }
    if (!g->sort_key || g->alloc_sort < np || needs_realloc(g->alloc_sort, np)) {
        size_t cap = g->alloc_np;
        free_sort_buffers(g);
        if ((rc = replace_buffer((void **)&g->sort_key, 2 * cap, sizeof(uint64_t), "sort keys")) ||
            (rc = replace_buffer((void **)&g->sort_idx, 2 * cap, sizeof(uint32_t),
                                 "sort indices"))) {
            free_sort_buffers(g);
            return mf_error_trace(rc, __FILE__, __LINE__, __func__);
        }
        g->alloc_sort = cap;
    }
    return 0;
}

void mf_grid_release_scratch(mf_grid *g)
{
    if (g)
        free_sort_buffers(g);
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
    g->alloc_rows = 0;
}

/* Rows are sized for the reach and dimension asked (the buffers grow when a
 * later build asks for more rows). */
static int ensure_cell_buffers(mf_grid *g, size_t ncells, int rows)
{
    if (g->cell_start && !needs_realloc(g->alloc_cells, ncells) &&
        g->alloc_rows >= (size_t)rows)
        return 0;
    size_t cap = with_headroom(ncells);
    free_cell_buffers(g);
    if (cap > SIZE_MAX / (MAX_ROWS * sizeof(uint32_t)))
        return MF_ERROR(MF_ERR_MEMORY, "neighbour grid with %zu cells is too large", ncells);
    int rc = 0;
    if ((rc = replace_buffer((void **)&g->cell_key, cap, sizeof(uint64_t), "cell keys")) ||
        (rc = replace_buffer((void **)&g->cell_start, cap + 1, sizeof(uint32_t), "cell starts")) ||
        (rc = replace_buffer((void **)&g->cell_rows, (size_t)rows * cap, sizeof(uint32_t),
                             "cell rows"))) {
        free_cell_buffers(g);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    g->alloc_cells = cap;
    g->alloc_rows = (size_t)rows;
    return 0;
}


size_t mf_grid_memory(const mf_grid *g)
{
    if (!g)
        return 0;
    size_t bytes = g->alloc_np * (sizeof(uint32_t) + 3 * sizeof(double)) +
                   g->alloc_sort * 2 * (sizeof(uint64_t) + sizeof(uint32_t));
    size_t per_cell = sizeof(uint64_t) + sizeof(uint32_t) + g->alloc_rows * sizeof(uint32_t);
    if (g->cell_start)
        bytes += g->alloc_cells * per_cell + sizeof(uint32_t);
    bytes += mf_hashmap_memory(&g->cells);
    return bytes;
}

/* ---- grid: cells and hash table ------------------------------------------ */

long mf_grid_find_cell(const mf_grid *g, uint64_t key)
{
    if (!g || g->ncells == 0)
        return -1;
    uint32_t c = mf_hashmap_get(&g->cells, key);
    return c == MF_HASHMAP_EMPTY ? -1 : (long)c;
}

/* Integer cell coordinate of x on one axis; the same expression is used
 * everywhere so that a point always lands in the same cell. */
static inline uint64_t cell_coord(double x, double origin, double inv_width)
{
    /* x >= origin (the origin lies below every particle): truncation is the
     * floor, without the libm call floor() is at -O2 on x86-64. */
    return (uint64_t)((x - origin) * inv_width);
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

/* The first occupied cell, in key order, of the row (y, z) of cells with
 * x in [x0, x1] around cell c of coordinate ix, or EMPTY_SLOT. */
static uint32_t first_in_row(const mf_grid *g, size_t c, uint64_t ix, uint64_t y, uint64_t z,
                             uint64_t x0, uint64_t x1, bool own_row)
{
    long mid = own_row ? (long)c : mf_grid_find_cell(g, mf_grid_key(ix, y, z));
    if (mid >= 0) {
        /* Cells are sorted by key: the occupied cells of the row before the
         * middle one are just before it in the array. */
        const uint64_t lowest = mf_grid_key(x0, y, z);
        size_t q = (size_t)mid;
        while (q > 0 && g->cell_key[q - 1] >= lowest)
            q--;
        return (uint32_t)q;
    }
    for (uint64_t x = x0; x <= x1; x++) {
        long cell = x == ix ? -1 : mf_grid_find_cell(g, mf_grid_key(x, y, z));
        if (cell >= 0)
            return (uint32_t)cell;
    }
    return EMPTY_SLOT;
}

/* The rows of cells around cell c, (dz, dy) ascending: rows[r] is the first
 * occupied cell of row r within reach along x (EMPTY_SLOT if none). */
static void find_rows(const mf_grid *g, size_t c, int reach, uint32_t *rows)
{
    const uint64_t key = g->cell_key[c];
    const uint64_t ix = key & AXIS_MASK;
    const uint64_t iy = (key >> MF_GRID_AXIS_BITS) & AXIS_MASK;
    const uint64_t iz = key >> (2 * MF_GRID_AXIS_BITS);
    const uint64_t x0 = ix >= (uint64_t)reach ? ix - (uint64_t)reach : 0;
    const uint64_t x1 = ix + (uint64_t)reach < g->nbox[0] ? ix + (uint64_t)reach : g->nbox[0] - 1;
    const int zr = g->dim == 3 ? reach : 0;
    int r = 0;
    for (int dz = -zr; dz <= zr; dz++)
        for (int dy = -reach; dy <= reach; dy++, r++) {
            const int64_t y = (int64_t)iy + dy, z = (int64_t)iz + dz;
            rows[r] = EMPTY_SLOT;
            if (y < 0 || z < 0 || (uint64_t)y >= g->nbox[1] || (uint64_t)z >= g->nbox[2])
                continue;
            rows[r] = first_in_row(g, c, ix, (uint64_t)y, (uint64_t)z, x0, x1, dy == 0 && dz == 0);
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
    mf_hashmap_clear(&g->cells);
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
#pragma omp parallel for schedule(dynamic, MF_STREAM_CHUNK) \
    reduction(min : x0, y0, z0) reduction(max : x1, y1, z1) reduction(+ : bad)
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
                /* Named as the run's watch names it (mf_watch.h). */
                return MF_ERROR(MF_ERR_NUMERIC,
                                "unstable (nonFinite): %s particle id %lld has a non-finite "
                                "position (%g, %g, %g), %zu particles in all, found building the "
                                "neighbour grid",
                                mf_particle_kind_name(p->kind[i]), (long long)p->id[i], x[0],
                                x[1], x[2], bad);
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

/* Origin, box and key bits of a grid of this cell size over the first n
 * particles (the frame every key of that grid is computed in). */
typedef struct grid_frame {
    double origin[3], inv_width;
    size_t nbox[3];
    int axis_bits[3];
} grid_frame;

static int make_frame(const mf_particles *p, size_t np, double cell_size, grid_frame *f)
{
    const int dim = p->dim;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    if (np > 0)
        MF_CALL(bounding_box(p, np, lo, hi));
    /* The margin keeps the lowest particles off the origin face, so they do
     * not depend on how x - origin rounds. */
    f->inv_width = 1.0 / binning_width(cell_size);
    const double margin = 1e-3 * cell_size;
    for (int d = 0; d < 3; d++) {
        f->origin[d] = d < dim ? lo[d] - margin : 0.0;
        f->nbox[d] = 1;
        f->axis_bits[d] = 0;
        if (d >= dim || np == 0)
            continue;
        double span = (hi[d] - f->origin[d]) * f->inv_width;
        if (!(span < (double)(AXIS_LIMIT - 1)))
            return MF_ERROR(MF_ERR_INPUT,
                            "particles span %g on axis %c, more than 2^%d cells of size %g: "
                            "the spacing is too small for the domain extent (or a particle "
                            "has escaped)",
                            hi[d] - lo[d], "xyz"[d], MF_GRID_AXIS_BITS, cell_size);
        f->nbox[d] = cell_coord(hi[d], f->origin[d], f->inv_width) + 1;
        f->axis_bits[d] = bits_for(f->nbox[d]);
    }
    return 0;
}

static int check_input(const mf_grid *g, const mf_particles *p, double cell_size)
{
    if (!g || !p)
        return MF_ERROR(MF_ERR_INPUT, "mf_grid_build: NULL grid or particles");
    if (!(cell_size > 0.0) || !isfinite(cell_size))
        return MF_ERROR(MF_ERR_INPUT, "neighbour cell size must be positive and finite, got %g",
                        cell_size);
    if (p->dim != 2 && p->dim != 3)
        return MF_ERROR(MF_ERR_INPUT, "particle dimension must be 2 or 3, got %d", p->dim);
    if (p->n >= UINT32_MAX)
        return MF_ERROR(MF_ERR_INPUT,
                        "%zu particles on one rank: neighbour indices are 32-bit (limit %u)",
                        p->n, UINT32_MAX - 1);
    return 0;
}

int mf_grid_keys(const mf_particles *p, double cell_size, uint64_t *keys, bool *packed)
{
    mf_grid g = {0};
    MF_CALL(check_input(&g, p, cell_size));
    grid_frame f;
    MF_CALL(make_frame(p, p->n, cell_size, &f));
    const double *pos = p->pos;
    const int dim = p->dim;
    const long np = (long)p->n;
    const int sy = f.axis_bits[0], sz = f.axis_bits[0] + f.axis_bits[1];
    /* The compact key (the build's sort key) orders cells as the public key
     * does; with at most 32 bits it leaves room for the index. */
    const bool pack = f.axis_bits[0] + f.axis_bits[1] + f.axis_bits[2] <= 32;
    *packed = pack;
#pragma omp parallel for schedule(dynamic, MF_STREAM_CHUNK)
    for (long i = 0; i < np; i++) {
        const double *x = pos + 3 * i;
        uint64_t k = cell_coord(x[0], f.origin[0], f.inv_width) |
                     cell_coord(x[1], f.origin[1], f.inv_width) << sy;
        if (dim == 3)
            k |= cell_coord(x[2], f.origin[2], f.inv_width) << sz;
        keys[i] = pack ? k << 32 | (uint64_t)i : k;
    }
    return 0;
}

bool mf_grid_cells(const mf_grid *g, uint32_t *cell)
{
    /* make_frame's key bits of the build (nbox is the frame's) */
    int bits[3] = {0, 0, 0};
    for (int d = 0; d < g->dim && g->np > 0; d++)
        bits[d] = bits_for(g->nbox[d]);
    if (bits[0] + bits[1] + bits[2] > 32)
        return false;
    const int sy = bits[0], sz = bits[0] + bits[1];
    for (size_t c = 0; c < g->ncells; c++) {
        const uint64_t key = g->cell_key[c];
        const uint32_t compact = (uint32_t)((key & AXIS_MASK) |
                                            ((key >> MF_GRID_AXIS_BITS) & AXIS_MASK) << sy |
                                            (key >> (2 * MF_GRID_AXIS_BITS)) << sz);
        for (uint32_t k = g->cell_start[c]; k < g->cell_start[c + 1]; k++)
            cell[g->order[k]] = compact;
    }
    return true;
}

int mf_grid_build(mf_grid *g, const mf_particles *p, double cell_size)
{
    return mf_grid_build_reach(g, p, cell_size, 1);
}

int mf_grid_build_reach(mf_grid *g, const mf_particles *p, double cell_size, int reach)
{
    MF_CALL(check_input(g, p, cell_size));
    if (reach != 1 && reach != 2)
        return MF_ERROR(MF_ERR_INPUT, "neighbour grid reach must be 1 or 2, got %d", reach);
    const size_t np = p->n;
    const int dim = p->dim;
    g->dim = dim;
    g->reach = reach;
    g->cell_size = cell_size;
    make_empty(g);

    int rc = 0;
    grid_frame f;
    MF_CALL_GOTO(rc, make_frame(p, np, cell_size, &f), fail);
    const double inv_width = f.inv_width;
    const int *axis_bits = f.axis_bits;
    for (int d = 0; d < 3; d++) {
        g->origin[d] = f.origin[d];
        g->nbox[d] = f.nbox[d];
    }

    MF_CALL_GOTO(rc, ensure_np_buffers(g, np > 0 ? np : 1), fail);

    /* Compact sort keys: same order as the public key, fewer bits. */
    {
        const double *pos = p->pos;
        const double o0 = g->origin[0], o1 = g->origin[1], o2 = g->origin[2];
        const int sy = axis_bits[0], sz = axis_bits[0] + axis_bits[1];
        uint64_t *key = g->sort_key;
        uint32_t *idx = g->sort_idx;
#pragma omp parallel for schedule(dynamic, MF_STREAM_CHUNK)
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
    const int nrows = rows_per_cell(dim, reach);
    MF_CALL_GOTO(rc, ensure_cell_buffers(g, ncells, nrows), fail);
    /* at most half full: short probe sequences; reused unless more than 4
     * times too large */
    MF_CALL_GOTO(rc, mf_hashmap_reset(&g->cells, 2 * ncells, 4), fail);

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
                g->cell_start[c] = (uint32_t)k;
                c++;
            }
        }
        g->cell_start[ncells] = (uint32_t)np;
    }
    g->ncells = ncells;
    for (size_t c = 0; c < ncells; c++)
        mf_hashmap_put_new(&g->cells, g->cell_key[c], (uint32_t)c);

    /* Rows of neighbouring cells, once per cell for all later list builds. */
#pragma omp parallel for schedule(dynamic, MF_PAIRS_CHUNK)
    for (size_t c = 0; c < ncells; c++)
        find_rows(g, c, reach, g->cell_rows + c * (size_t)nrows);

    /* Order and positions in cell order. */
    {
        const double *pos = p->pos;
        uint32_t *order = g->order;
        double *sx = g->spos, *sy = g->spos + np, *sz = g->spos + 2 * np;
#pragma omp parallel for schedule(dynamic, MF_STREAM_CHUNK)
        for (size_t k = 0; k < np; k++) {
            size_t i = sidx[k];
            order[k] = (uint32_t)i;
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
    for (size_t k = 0; k < g->np; k++)
        perm[k] = g->order[k];
    return 0;
}

