/* mf_neighbours.h: cell lists over occupied cells only, neighbour lists, and
 * the neighbour service that every module reads (DESIGN.md section 8).
 *
 * The grid stores only cells that hold particles: particles are sorted by a
 * 64-bit cell key (radix sort, O(N)), the occupied cells are the distinct
 * keys, and an open-addressing hash table maps a key to its cell. Memory
 * follows the particles, not the bounding box (an L-shaped corridor does not
 * pay for the empty corner).
 *
 * A neighbour list holds, for each owned particle i in [0, n_owned), the
 * indices j != i in [0, n) with |r_j - r_i| < radius, in CSR form, radius
 * up to grid.reach cell sizes; the rows of the copies [n_owned, n) (other
 * ranks' particles, periodic images) are empty, as no loop visits them.
 * The j's of each i come in the grid's order: ascending (cell key of j,
 * j), the key of a cell of side cell_size with the origin at the lower
 * corner of the particles' bounding box. Every sum over a list therefore runs
 * in an order fixed by the positions and the cell size alone, whichever way
 * the list was made (built, or kept and re-sorted: mf_nlist_sort).
 *
 * The service (mf_neighbours) owns the grids and lists of a run. A module
 * asks once for a radius (mf_neighbours_request) and then, each time it
 * loops, for the pairs of that radius at the current positions
 * (mf_neighbours_pairs, a view for the engine of mf_pairs.h). Lists are kept
 * across position changes with a skin (a Verlet list: built at radius + skin,
 * reused while no particle has moved by more than half the skin) and brought
 * back into the order of the current positions at each order point
 * (mf_neighbours_moved), so that a kept list gives the same sums, bit for
 * bit, as one built afresh.
 */
#ifndef MF_NEIGHBOURS_H
#define MF_NEIGHBOURS_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mf_hashmap.h"
#include "mf_particles.h"

typedef struct mf_grid {
    int dim;
    int reach;             /* list radii up to reach * cell_size (1 or 2) */
    double cell_size;
    double origin[3];      /* lower corner of the particles' bounding box */
    size_t np;             /* particles binned */
    size_t ncells;         /* occupied cells */
    uint64_t *cell_key;    /* ncells, ascending */
    uint32_t *cell_start;  /* ncells + 1: particles of cell c are order[cell_start[c] .. cell_start[c+1]) */
    uint32_t *order;       /* np: particle indices sorted by cell */
    mf_hashmap cells;      /* key -> cell index; >= 2 * ncells slots (the layout of
                              the hash_cap, hash_key, hash_cell it replaced) */
    size_t alloc_np, alloc_cells, alloc_rows, alloc_sort; /* capacities, reused between builds */
    size_t nbox[3];        /* bounding box size in cells per axis (nbox[2] = 1 in 2-D) */
    double *spos;          /* 3 * alloc_np: positions in cell order (order[k]'s at k),
                              x block, then y, then z; copied by mf_grid_build */
    uint64_t *sort_key;    /* 2 * alloc_sort: radix sort keys (double buffer); scratch */
    uint32_t *sort_idx;    /* 2 * alloc_sort: radix sort payload (double buffer) */
    uint32_t *cell_rows;   /* per cell, (2 reach + 1)^(dim-1) rows along x of the cells
                              around it, (dz, dy) ascending: the first occupied cell of
                              the row within reach along x, or UINT32_MAX */
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
    uint32_t *start;       /* n + 1 */
    uint32_t *j;           /* start[n] entries */
    size_t cap_n, cap_j;
    void *work;            /* scratch of mf_nlist_build (candidate bits), reused */
    size_t work_bytes;
} mf_nlist;

void mf_grid_init(mf_grid *g);
void mf_grid_free(mf_grid *g);
/* Bin the first p->n particles into cells of side cell_size (>= the largest
 * radius later asked of mf_nlist_build). O(N) time and memory. */
int mf_grid_build(mf_grid *g, const mf_particles *p, double cell_size);
/* The same for lists of radius up to reach * cell_size (reach 1 or 2): a
 * list keeps the order of cell_size's cells whatever its radius. */
int mf_grid_build_reach(mf_grid *g, const mf_particles *p, double cell_size, int reach);
/* Cell index of a key, or -1 if the cell is empty. */
long mf_grid_find_cell(const mf_grid *g, uint64_t key);
/* The permutation that sorts particles by cell (for mf_particles_permute):
 * perm[k] = old index of the particle now at k. Copies g->order. */
int mf_grid_locality_order(const mf_grid *g, size_t *perm);
size_t mf_grid_memory(const mf_grid *g);
/* Free the build's scratch (the radix sort's buffers, 24 bytes a particle);
 * the next build allocates it again. The grid stays usable. */
void mf_grid_release_scratch(mf_grid *g);
/* Occupied cell containing point x, or -1 (empty cell or outside the box). */
long mf_grid_point_cell(const mf_grid *g, const double x[3]);
/* keys[i] for i in [0, p->n): the cells of the grid mf_grid_build(p,
 * cell_size) would make (same origin, same rounding) in key order, and with
 * *packed the index too (keys[i] < keys[j] exactly when (cell, i) comes
 * before (cell, j)). Fails as mf_grid_build does on a non-finite position. */
int mf_grid_keys(const mf_particles *p, double cell_size, uint64_t *keys, bool *packed);
/* cell[i] for i in [0, g->np): the cell of particle i in the grid, as the
 * high 32 bits of the packed keys mf_grid_keys gave at the build's
 * positions. Returns false (cell untouched) when those keys are not packed. */
bool mf_grid_cells(const mf_grid *g, uint32_t *cell);

void mf_nlist_init(mf_nlist *nl);
void mf_nlist_free(mf_nlist *nl);
/* All pairs closer than radius (radius <= g->reach * g->cell_size).
 * Parallel (OpenMP). Distances use the positions as they were at
 * mf_grid_build (the grid keeps a copy in cell order); p must be the store
 * the grid was built from. The j's of each i are in the grid's order (see
 * the top of this file), the same for any thread count. */
int mf_nlist_build(mf_nlist *nl, const mf_grid *g, const mf_particles *p, double radius);
/* The same list and, in one pass, its sub-list of the pairs closer than
 * sub_radius (<= radius) in sub. */
int mf_nlist_build_pair(mf_nlist *nl, mf_nlist *sub, const mf_grid *g, const mf_particles *p,
                        double radius, double sub_radius);
/* The sub-list of `from` closer than radius (radius <= from->radius). */
int mf_nlist_filter(mf_nlist *nl, const mf_nlist *from, const mf_particles *p, double radius);
/* Put the j's of every i in ascending (keys[j], j) (keys and packed from
 * mf_grid_keys): the order a fresh build at the positions of the keys
 * gives. Cheap when the list is nearly in order already (insertion sort). */
void mf_nlist_sort(mf_nlist *nl, const uint64_t *keys, bool packed);
/* mf_nlist_sort in two steps for packed keys (mf_grid_keys: the cell in
 * the high 32 bits, the index in the low) and a list in the order of the
 * cells cell_before (built or sorted at them: mf_grid_cells) that is
 * symmetric (j in i's list exactly when i is in j's: every list
 * mf_nlist_build makes). mark sets dirty[i] (nl->n bytes) for each list
 * that holds a particle whose cell changed, the lists of its neighbours;
 * sort_marked sorts the marked lists only, which gives mf_nlist_sort's
 * result (the unmarked ones are in order already). A sub-list made in the
 * same build (mf_nlist_build_pair) holds a subset of each list: the
 * list's marks serve it. Particles [n_rows, nl->n) (the copies of other
 * ranks' particles and the periodic images) have empty rows, so their own
 * lists cannot say who holds them: for a copy that changed cell, the lists
 * of [0, n_rows) are searched for it instead. */
void mf_nlist_mark_moved(const mf_nlist *nl, const uint64_t *keys, const uint32_t *cell_before,
                         size_t n_rows, uint8_t *dirty);
void mf_nlist_sort_marked(mf_nlist *nl, const uint64_t *keys, bool packed,
                          const uint8_t *dirty);
size_t mf_nlist_memory(const mf_nlist *nl);
/* Free the build's scratch (the candidate bits); the list stays usable. */
void mf_nlist_release_scratch(mf_nlist *nl);

/* ---- the neighbour service --------------------------------------------- */

typedef struct mf_neighbours mf_neighbours;
struct mf_pairs; /* mf_pairs.h */

int mf_neighbours_create(mf_neighbours **out);
void mf_neighbours_destroy(mf_neighbours *nb);
/* Ask for the pairs closer than radius. cell fixes the order of the sums
 * over them: that of a grid of that cell size (radius <= cell); 0: the
 * order of the smallest cell already asked for that is >= radius, else
 * radius itself (a force or function object that shares the solver's
 * lists where they reach). Returns a handle for mf_neighbours_pairs. */
int mf_neighbours_request(mf_neighbours *nb, double radius, double cell, int *handle);
/* An order point: positions have changed and the next loops run in the
 * order of the positions they find (the solver calls it at r^n and at r*).
 * Between order points a list keeps its order while it still holds every
 * pair the loop needs. */
void mf_neighbours_moved(mf_neighbours *nb);
/* The pairs of a handle at the current positions of p (the view holds
 * every pair closer than the handle's radius, and the engine drops the
 * others). Rebuilds or re-sorts as needed; the view stays valid until the
 * next call for the same cell. */
int mf_neighbours_pairs(mf_neighbours *nb, const mf_particles *p, int handle,
                        struct mf_pairs *out);
/* The largest radius any request asked for (0: none): how far a rank's
 * copies of other ranks' particles must reach for every module's loops. */
double mf_neighbours_max_radius(const mf_neighbours *nb);
/* mf_neighbours_moved, then the handle's lists at once (the solver's
 * neighbour phase: the time goes there and not into the first loop). */
int mf_neighbours_update(mf_neighbours *nb, const mf_particles *p, int handle);
/* A grid of this cell size at the current positions, built now, for point
 * queries (mf_pairs.h, mf_grid_near); valid until the next call. */
int mf_neighbours_grid(mf_neighbours *nb, const mf_particles *p, double cell,
                       const mf_grid **out);
/* The permutation that sorts particles along the cells of the handle's
 * cell size at the current positions (for mf_particles_permute). */
int mf_neighbours_locality_order(mf_neighbours *nb, const mf_particles *p, int handle,
                                 size_t *perm);
/* Skin of later builds as fractions of the cell: min, max and start
 * (defaults 0.01, 0.25, 0.05). The skin adapts between min and max to the
 * displacement a list has to survive. */
int mf_neighbours_set_skin(mf_neighbours *nb, double min, double max, double start);
size_t mf_neighbours_memory(const mf_neighbours *nb);
typedef struct mf_neighbours_stats {
    long builds, sorts, checks;
    double seconds;        /* in builds, sorts and checks */
    double entries;        /* list entries per owned particle of the last build (largest cell) */
} mf_neighbours_stats;
void mf_neighbours_get_stats(const mf_neighbours *nb, mf_neighbours_stats *out);

#pragma GCC visibility pop
#endif
