/* bench_neighbours: timings and memory of the grid and neighbour lists.
 *
 *   bench_neighbours            100,000 and 1,000,000 particles
 *   bench_neighbours N ...      other sizes
 *
 * Cubic lattice blocks (spacing l0, radius 2.1 l0 as in MPS), in random
 * order and in cell order, then an L-shaped corridor to compare the grid's
 * memory with a dense bounding-box grid. OMP_NUM_THREADS sets the threads.
 */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "mf_error.h"
#include "mf_neighbours.h"
#include "mf_particles.h"

#define REPEATS 5

static void die(const char *what)
{
    fprintf(stderr, "bench_neighbours: %s failed\n", what);
    mf_error_print(stderr);
    exit(EXIT_FAILURE);
}

/* An nx * ny * nz lattice block of spacing l0. */
static mf_particles *block(int nx, int ny, int nz, double l0)
{
    mf_particles *p = NULL;
    if (mf_particles_create(3, (size_t)nx * ny * nz, &p))
        die("mf_particles_create");
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                double x[3] = {i * l0, j * l0, k * l0};
                if (mf_particles_add(p, MF_FLUID, x, NULL, NULL))
                    die("mf_particles_add");
            }
    return p;
}

static void shuffle(mf_particles *p)
{
    size_t n = p->n;
    size_t *perm = malloc(n * sizeof *perm);
    if (!perm)
        die("malloc");
    for (size_t k = 0; k < n; k++)
        perm[k] = k;
    uint64_t s = 88172645463325252ULL;
    for (size_t k = n - 1; k > 0; k--) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        size_t r = (size_t)(s % (k + 1));
        size_t t = perm[k];
        perm[k] = perm[r];
        perm[r] = t;
    }
    if (mf_particles_permute(p, perm))
        die("mf_particles_permute");
    free(perm);
}

static void sort_by_cell(mf_particles *p, mf_grid *g)
{
    size_t *perm = malloc(p->n * sizeof *perm);
    if (!perm)
        die("malloc");
    if (mf_grid_locality_order(g, perm) || mf_particles_permute(p, perm))
        die("locality sort");
    free(perm);
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Times (best of REPEATS, ms: the machine may be shared) of grid build,
 * list build and filter. */
static void time_builds(mf_particles *p, mf_grid *g, mf_nlist *nl, mf_nlist *small, double l0,
                        const char *label)
{
    const double radius = 2.1 * l0;
    double tg[REPEATS], tl[REPEATS], tf[REPEATS], tt[REPEATS];
    for (int r = 0; r < REPEATS; r++) {
        double t0 = omp_get_wtime();
        if (mf_grid_build(g, p, radius))
            die("mf_grid_build");
        double t1 = omp_get_wtime();
        if (mf_nlist_build(nl, g, p, radius))
            die("mf_nlist_build");
        double t2 = omp_get_wtime();
        if (mf_nlist_filter(small, nl, p, 1.5 * l0))
            die("mf_nlist_filter");
        double t3 = omp_get_wtime();
        tg[r] = 1e3 * (t1 - t0);
        tl[r] = 1e3 * (t2 - t1);
        tf[r] = 1e3 * (t3 - t2);
        tt[r] = tg[r] + tl[r];
    }
    qsort(tg, REPEATS, sizeof *tg, compare_double);
    qsort(tl, REPEATS, sizeof *tl, compare_double);
    qsort(tf, REPEATS, sizeof *tf, compare_double);
    qsort(tt, REPEATS, sizeof *tt, compare_double);
    int m = 0;
    printf("  %-14s grid %8.2f ms  list %8.2f ms  grid+list %8.2f ms  filter(1.5 l0) %7.2f ms\n",
           label, tg[m], tl[m], tt[m], tf[m]);
}

static void bench_block(size_t target)
{
    /* A cube with about `target` particles. */
    int side = (int)floor(cbrt((double)target) + 0.5);
    int nz = (int)((target + (size_t)side * side - 1) / ((size_t)side * side));
    const double l0 = 0.01;
    mf_particles *p = block(side, side, nz, l0);
    mf_grid g;
    mf_nlist nl, small;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    mf_nlist_init(&small);

    printf("cubic block %d x %d x %d = %zu particles, radius 2.1 l0, %d threads\n", side, side,
           nz, p->n, omp_get_max_threads());
    shuffle(p);
    time_builds(p, &g, &nl, &small, l0, "random order");
    sort_by_cell(p, &g);
    time_builds(p, &g, &nl, &small, l0, "cell order");

    size_t pairs = nl.start[p->n];
    printf("  %zu cells, %.2f neighbours per particle (interior: 32)\n", g.ncells,
           (double)pairs / (double)p->n);
    printf("  memory: particles %.1f MB, grid %.1f MB (%.0f B/particle), list %.1f MB, "
           "filtered list %.1f MB\n",
           mf_particles_memory(p) / 1e6, mf_grid_memory(&g) / 1e6,
           (double)mf_grid_memory(&g) / (double)p->n, mf_nlist_memory(&nl) / 1e6,
           mf_nlist_memory(&small) / 1e6);
    mf_nlist_free(&nl);
    mf_nlist_free(&small);
    mf_grid_free(&g);
    mf_particles_destroy(p);
}

/* Two corridor arms (x and y), `arm` particles long, 4 x 4 in section. */
static void bench_corridor(int arm)
{
    const double l0 = 0.01, radius = 2.1 * l0;
    const int width = 4;
    mf_particles *p = NULL;
    if (mf_particles_create(3, 0, &p))
        die("mf_particles_create");
    for (int k = 0; k < width; k++)
        for (int j = 0; j < arm; j++)
            for (int i = 0; i < arm; i++)
                if (i < width || j < width) {
                    double x[3] = {i * l0, j * l0, k * l0};
                    if (mf_particles_add(p, MF_FLUID, x, NULL, NULL))
                        die("mf_particles_add");
                }
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    double t0 = omp_get_wtime();
    if (mf_grid_build(&g, p, radius))
        die("mf_grid_build");
    double t1 = omp_get_wtime();
    if (mf_nlist_build(&nl, &g, p, radius))
        die("mf_nlist_build");
    double t2 = omp_get_wtime();
    size_t box = g.nbox[0] * g.nbox[1] * g.nbox[2];
    /* A dense grid holds at least one offset per box cell. */
    double dense = (double)box * sizeof(size_t);
    printf("L corridor, arms %d x %d x %d: %zu particles\n", arm, width, width, p->n);
    printf("  occupied cells %zu of %zu in the bounding box (%.3f%%)\n", g.ncells, box,
           100.0 * (double)g.ncells / (double)box);
    printf("  grid memory %.2f MB; a dense box grid needs >= %.2f MB for its cell offsets alone\n",
           mf_grid_memory(&g) / 1e6, dense / 1e6);
    printf("  grid %.2f ms, list %.2f ms\n", 1e3 * (t1 - t0), 1e3 * (t2 - t1));
    mf_nlist_free(&nl);
    mf_grid_free(&g);
    mf_particles_destroy(p);
}

int main(int argc, char **argv)
{
    if (argc > 1) {
        for (int a = 1; a < argc; a++)
            bench_block((size_t)strtoull(argv[a], NULL, 10));
    } else {
        bench_block(100000);
        bench_block(1000000);
    }
    bench_corridor(2000);
    bench_corridor(20000);
    return 0;
}
