/* ls_bricks.c: the sparse grid of the level set, a hash of 8^3-point bricks
 * (OpenVDB's leaf nodes, without the tree above them). Only bricks that
 * hold band points exist, so memory follows the surface, not the box.
 *
 * The bricks' index is mf_hashmap.h's map from the packed brick coordinates,
 * at most half full. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mf_alloc.h"
#include "levelset.h"

size_t ls_memory_limit(double max_memory_mb)
{
    if (max_memory_mb > 0)
        return (size_t)(max_memory_mb * 1048576.0);
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0)
        return (size_t)8 << 30;
    return (size_t)((double)pages * (double)page * 0.75);
}

static inline uint64_t pack(int32_t bx, int32_t by, int32_t bz)
{
    const uint64_t bias = LS_BRICK_LIMIT;
    return ((uint64_t)(bx + (int64_t)bias) | (uint64_t)(by + (int64_t)bias) << 21 |
            (uint64_t)(bz + (int64_t)bias) << 42) + 1;
}

void ls_bricks_init(ls_bricks *b)
{
    memset(b, 0, sizeof *b);
}

void ls_bricks_free(ls_bricks *b)
{
    free(b->coord);
    mf_hashmap_free(&b->map);
    ls_bricks_init(b);
}

void ls_bricks_clear(ls_bricks *b)
{
    b->n = 0;
    mf_hashmap_clear(&b->map);
}

int32_t ls_bricks_find(const ls_bricks *b, int32_t bx, int32_t by, int32_t bz)
{
    uint32_t k = mf_hashmap_get(&b->map, pack(bx, by, bz));
    return k == MF_HASHMAP_EMPTY ? LS_NONE : (int32_t)k;
}

/* A table of hcap slots holding every brick; the old one stays on failure. */
static int rehash(ls_bricks *b, size_t hcap)
{
    mf_hashmap t = {0, NULL, NULL};
    MF_CALL(mf_hashmap_reset(&t, hcap, 0));
    for (size_t k = 0; k < b->n; k++) {
        const int32_t *c = &b->coord[3 * k];
        mf_hashmap_put_new(&t, pack(c[0], c[1], c[2]), (uint32_t)k);
    }
    mf_hashmap_free(&b->map);
    b->map = t;
    return 0;
}

int ls_bricks_insert(ls_bricks *b, int32_t bx, int32_t by, int32_t bz, int32_t *index,
                     bool *added)
{
    if (bx <= -LS_BRICK_LIMIT || bx >= LS_BRICK_LIMIT || by <= -LS_BRICK_LIMIT ||
        by >= LS_BRICK_LIMIT || bz <= -LS_BRICK_LIMIT || bz >= LS_BRICK_LIMIT)
        return MF_ERROR(MF_ERR_INPUT,
                        "a surface grid brick (%d, %d, %d) is outside the grid's range "
                        "(+-%d bricks of 8 cells): the grid spacing is too small for the "
                        "extent of the particles",
                        bx, by, bz, LS_BRICK_LIMIT);
    int32_t found = ls_bricks_find(b, bx, by, bz);
    if (found != LS_NONE) {
        *index = found;
        if (added)
            *added = false;
        return 0;
    }
    if (b->n >= (size_t)INT32_MAX - 1)
        return MF_ERROR(MF_ERR_MEMORY, "more than %d bricks in the surface grid", INT32_MAX);
    if (2 * (b->n + 1) > b->map.cap)
        MF_CALL(rehash(b, b->map.cap ? 2 * b->map.cap : 1024));
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 256;
        if (mf_resize(&b->coord, 3 * cap, sizeof *b->coord))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu bricks", cap);
        b->cap = cap;
    }
    int32_t k = (int32_t)b->n++;
    b->coord[3 * k] = bx;
    b->coord[3 * k + 1] = by;
    b->coord[3 * k + 2] = bz;
    mf_hashmap_put_new(&b->map, pack(bx, by, bz), (uint32_t)k);
    *index = k;
    if (added)
        *added = true;
    return 0;
}

size_t ls_bricks_memory(const ls_bricks *b)
{
    return b->cap * 3 * sizeof(int32_t) + mf_hashmap_memory(&b->map);
}

int ls_bricks_neighbours(const ls_bricks *b, int32_t **nb)
{
    int32_t *t = malloc((b->n ? b->n : 1) * 27 * sizeof *t);
    if (!t)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the neighbours of %zu bricks", b->n);
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < b->n; k++) {
        const int32_t *c = &b->coord[3 * k];
        for (int dz = -1; dz <= 1; dz++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                    t[27 * k + (dx + 1) + 3 * (dy + 1) + 9 * (dz + 1)] =
                        ls_bricks_find(b, c[0] + dx, c[1] + dy, c[2] + dz);
    }
    *nb = t;
    return 0;
}
