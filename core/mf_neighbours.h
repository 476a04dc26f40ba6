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
} mf_grid;

typedef struct mf_nlist {
    double radius;
    size_t n;              /* particles covered */
    size_t *start;         /* n + 1 */
    uint32_t *j;           /* start[n] entries */
    size_t cap_n, cap_j;
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

void mf_nlist_init(mf_nlist *nl);
void mf_nlist_free(mf_nlist *nl);
/* All pairs closer than radius (radius <= g->cell_size). Parallel (OpenMP). */
int mf_nlist_build(mf_nlist *nl, const mf_grid *g, const mf_particles *p, double radius);
/* The sub-list of `from` closer than radius (radius <= from->radius). */
int mf_nlist_filter(mf_nlist *nl, const mf_nlist *from, const mf_particles *p, double radius);
size_t mf_nlist_memory(const mf_nlist *nl);

#endif
