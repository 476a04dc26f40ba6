/* neighbours_internal.h: what grid.c and nlist.c share (buffer policy,
 * key helpers, limits). Private to core/. */
#ifndef MF_NEIGHBOURS_INTERNAL_H
#define MF_NEIGHBOURS_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

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
/* Rows of cells a particle may need: up to 2 reach + 1 = 5 per axis. */
#define MAX_ROWS 25
/* Candidate bits allowed per particle, on average, before the fill pass
 * falls back to repeating the distance test (bounds the scratch memory). */
#define MAX_BIT_WORDS_PER_PARTICLE 16

/* ---- small helpers ------------------------------------------------------ */

/* Bits needed to store values 0 .. n-1. */
static inline int bits_for(uint64_t n)
{
    int b = 0;
    while (b < 64 && (n - 1) >> b)
        b++;
    return b;
}

static inline double binning_width(double cell_size)
{
    return cell_size * (1.0 + MF_GRID_CELL_SLACK);
}

/* Rows stored per cell: (2 reach + 1)^(dim-1). */
static inline int rows_per_cell(int dim, int reach)
{
    const int w = 2 * reach + 1;
    return dim == 3 ? w * w : w;
}

/* Free-and-allocate: contents never need to survive a rebuild, so avoid the
 * copy realloc would make. */
static inline int replace_buffer(void **buf, size_t count, size_t elem_size, const char *what)
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
static inline bool needs_realloc(size_t have, size_t need)
{
    return need > have || (have > 1024 && need < have / 4);
}

static inline size_t with_headroom(size_t need)
{
    size_t extra = need / 8;
    return need > SIZE_MAX - extra - 1 ? need : need + extra + 1;
}


#endif
