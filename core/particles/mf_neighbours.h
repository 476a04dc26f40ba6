/* mf_neighbours.h: cell lists over occupied cells only, and neighbour lists.
 *
 * The grid stores only cells that hold particles: particles are sorted by a
 * 64-bit cell key (radix sort, O(N)), the occupied cells are the distinct
 * keys, and an open-addressing hash table maps a key to its cell. Memory
 * follows the particles, not the bounding box (an L-shaped corridor does not
 * pay for the empty corner).
 *
 * A neighbour list holds, for each particle i in [0, n), the indices j != i
 * with |r_j - r_i| < radius, in CSR form. Build it once per radius the
 * operators need; lists for smaller radii can be filtered from a larger one.
 */
#ifndef MF_NEIGHBOURS_H
#define MF_NEIGHBOURS_H

#include <stddef.h>
#include <stdint.h>

#include "mf_particles.h"

typedef struct mf_grid {
    int dim;
    double cell_size;
    double origin[3];      /* lower corner of the particles' bounding box */
    size_t np;             /* particles binned */
    size_t ncells;         /* occupied cells */
    uint64_t *cell_key;    /* ncells, ascending */
    size_t *cell_start;    /* ncells + 1: particles of cell c are order[cell_start[c] .. cell_start[c+1]) */
    size_t *order;         /* np: particle indices sorted by cell */
    /* key -> cell index, open addressing with linear probing */
    size_t hash_cap;       /* power of two, >= 2 * ncells */
    uint64_t *hash_key;
    uint32_t *hash_cell;   /* UINT32_MAX marks an empty slot */
    size_t alloc_np, alloc_cells; /* capacities, to reuse memory between builds */
    /* Added with the implementation: */
    size_t nbox[3];        /* bounding box size in cells per axis (nbox[2] = 1 in 2-D) */
    double *spos;          /* 3 * alloc_np: positions in cell order (order[k]'s at k),
                              x block, then y, then z; copied by mf_grid_build */
    uint64_t *sort_key;    /* 2 * alloc_np: radix sort keys (double buffer) */
    uint32_t *sort_idx;    /* 2 * alloc_np: radix sort payload (double buffer) */
    uint32_t *cell_rows;   /* per cell, 3^(dim-1) ranges [a, b) of sorted particles: the
                              rows along x of its neighbouring cells (a == b if empty) */
} mf_grid;

/* Cell keys: integer cell coordinates (ix, iy, iz) >= 0 relative to origin,
 * 21 bits each. A cell spans [origin + ix * w, origin + (ix + 1) * w) with w
 * = cell_size * (1 + MF_GRID_CELL_SLACK): the slack keeps pairs closer than
 * cell_size in adjacent cells despite rounding. */
#define MF_GRID_AXIS_BITS 21
#define MF_GRID_CELL_SLACK 1e-7
static inline uint64_t mf_grid_key(uint64_t ix, uint64_t iy, uint64_t iz)
{
    return ix | iy << MF_GRID_AXIS_BITS | iz << (2 * MF_GRID_AXIS_BITS);
}

typedef struct mf_nlist {
    double radius;
    size_t n;              /* particles covered */
    size_t *start;         /* n + 1 */
    uint32_t *j;           /* start[n] entries */
    size_t cap_n, cap_j;
    void *work;            /* scratch of mf_nlist_build (candidate bits), reused (added) */
    size_t work_bytes;
} mf_nlist;

void mf_grid_init(mf_grid *g);
void mf_grid_free(mf_grid *g);
/* Bin the first p->n particles into cells of side cell_size (>= the largest
 * radius later asked of mf_nlist_build). O(N) time and memory. */
int mf_grid_build(mf_grid *g, const mf_particles *p, double cell_size);
/* Cell index of a key, or -1 if the cell is empty. */
long mf_grid_find_cell(const mf_grid *g, uint64_t key);
/* The permutation that sorts particles by cell (for mf_particles_permute):
 * perm[k] = old index of the particle now at k. Copies g->order. */
int mf_grid_locality_order(const mf_grid *g, size_t *perm);
size_t mf_grid_memory(const mf_grid *g);
/* Occupied cell containing point x, or -1 (empty cell or outside the box). */
long mf_grid_point_cell(const mf_grid *g, const double x[3]);

void mf_nlist_init(mf_nlist *nl);
void mf_nlist_free(mf_nlist *nl);
/* All pairs closer than radius (radius <= g->cell_size). Parallel (OpenMP).
 * Distances use the positions as they were at mf_grid_build (the grid keeps
 * a copy in cell order); p must be the store the grid was built from. The
 * j's of each i are in cell order, the same for any thread count. */
int mf_nlist_build(mf_nlist *nl, const mf_grid *g, const mf_particles *p, double radius);
/* The sub-list of `from` closer than radius (radius <= from->radius). */
int mf_nlist_filter(mf_nlist *nl, const mf_nlist *from, const mf_particles *p, double radius);
size_t mf_nlist_memory(const mf_nlist *nl);

#endif
