/* bench_scene_grid.c: memory of the neighbour structure of a scene's
 * snapshot against a dense grid of its bounding box (the paper, section 5:
 * "because the corridor is L-shaped ... in grid-based approaches about 70
 * percent of the space would be wasted").
 *
 *   bench_scene_grid SNAPSHOT.h5 [RADIUS_IN_L0]      (default 2.1)
 *
 * Builds the cell grid (cells of the radius, occupied cells only) and the
 * neighbour list of every particle, fluid and fixed, as the MPS solver
 * does, and prints their memory next to what a dense grid of the bounding
 * box needs for its cell offsets alone (one size_t per cell; a real dense
 * cell list needs that plus the particles). Not a test: it prints. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_neighbours.h"

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s SNAPSHOT.h5 [RADIUS_IN_L0]\n", argv[0]);
        return 2;
    }
    const double radius_l0 = argc > 2 ? atof(argv[2]) : 2.1;
    mf_hdf5_header h;
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    if (mf_hdf5_read_header(argv[1], &h) != 0 || mf_hdf5_read_snapshot(argv[1], &sim) != 0) {
        mf_error_print(stderr);
        return 1;
    }
    const mf_particles *p = sim.p;
    const double cell = radius_l0 * h.l0;
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    if (mf_grid_build(&g, p, cell) != 0 || mf_nlist_build(&nl, &g, p, cell) != 0) {
        mf_error_print(stderr);
        return 1;
    }
    size_t counts[MF_NKINDS];
    mf_particles_count_kinds(p, counts);
    const double box = (double)g.nbox[0] * (double)g.nbox[1] * (double)g.nbox[2];
    const double total = (double)mf_grid_memory(&g);
    /* The part of our grid that is per occupied cell: key, start, rows, and
     * the hash table's slots; the rest (order, positions, sort buffers) is
     * per particle, and a dense grid of the box needs it too. */
    const int rows = p->dim == 3 ? 9 : 3;
    const double per_cell = (double)g.ncells * (sizeof(uint64_t) + sizeof(size_t) +
                                                rows * 2 * sizeof(uint32_t)) +
                            (double)mf_hashmap_memory(&g.cells);
    const double per_particle = total - per_cell;
    /* A dense grid of the bounding box: one offset per box cell at least. */
    const double dense = box * sizeof(size_t) + per_particle;
    printf("snapshot %s: t = %g s, l0 = %g m, %zu particles (%zu fluid, %zu wall, %zu dummy)\n",
           argv[1], h.time, h.l0, p->n, counts[MF_FLUID], counts[MF_WALL], counts[MF_DUMMY]);
    printf("cells of %.3g m (%.2g l0): bounding box %zu x %zu x %zu = %.0f cells, %zu occupied "
           "(%.1f%%: %.1f%% of the box is empty)\n",
           cell, radius_l0, g.nbox[0], g.nbox[1], g.nbox[2], box, g.ncells,
           100.0 * g.ncells / box, 100.0 * (1 - g.ncells / box));
    printf("grid %.2f MB (%.1f B a particle): %.2f MB of per-particle arrays, %.2f MB of tables "
           "over the occupied cells; a dense grid of the box >= %.2f MB (the same per-particle "
           "arrays and %.2f MB of cell offsets)\n",
           total / 1e6, total / (double)p->n, per_particle / 1e6, per_cell / 1e6, dense / 1e6,
           box * sizeof(size_t) / 1e6);
    printf("neighbour list %.2f MB (%.1f neighbours a particle): it follows the particles\n",
           mf_nlist_memory(&nl) / 1e6, (double)nl.start[p->n] / (double)p->n);
    printf("csv,%g,%zu,%zu,%.0f,%zu,%.0f,%.0f,%.0f,%.0f\n", h.l0, p->n, counts[MF_FLUID], box,
           g.ncells, total, per_cell, dense, (double)mf_nlist_memory(&nl));
    mf_grid_free(&g);
    mf_nlist_free(&nl);
    mf_particles_destroy(sim.p);
    return 0;
}
