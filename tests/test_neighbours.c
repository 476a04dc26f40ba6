/* test_neighbours: the cell grid and neighbour lists against brute force.
 *
 * Every list is compared, particle by particle and as a set, with the O(N^2)
 * loop over all pairs using the same distance formula. The point sets aim at
 * the places a cell list goes wrong: lattice points on cell faces, pairs at
 * exactly the radius, empty and tiny sets, coincident points, sparse shapes
 * (the L-shaped corridor) and rebuilds that reuse buffers.
 */
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mf_neighbours.h"
#include "mf_particles.h"
#include "mf_test.h"

/* ---- helpers ------------------------------------------------------------- */

static uint64_t rng_state = 0x2545F4914F6CDD1DULL;

static double uniform(void) /* xorshift64*, in [0, 1) */
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ULL) >> 11) * 0x1.0p-53;
}

static mf_particles *new_store(int dim)
{
    mf_particles *p = NULL;
    CHECK_OK(mf_particles_create(dim, 0, &p));
    if (!p) {
        fprintf(stderr, "cannot create a particle store\n");
        exit(EXIT_FAILURE);
    }
    return p;
}

static void add_point(mf_particles *p, double x, double y, double z)
{
    double pos[3] = {x, y, z};
    CHECK_OK(mf_particles_add(p, MF_FLUID, pos, NULL, NULL));
}

static mf_particles *random_points(int dim, size_t n, double box)
{
    mf_particles *p = new_store(dim);
    for (size_t i = 0; i < n; i++)
        add_point(p, box * uniform(), box * uniform(), dim == 3 ? box * uniform() : 0.0);
    return p;
}

/* Lattice with spacing l0 and m points per side, starting at corner. */
static mf_particles *lattice(int dim, int m, double l0, double corner)
{
    mf_particles *p = new_store(dim);
    int mz = dim == 3 ? m : 1;
    for (int k = 0; k < mz; k++)
        for (int j = 0; j < m; j++)
            for (int i = 0; i < m; i++)
                add_point(p, corner + i * l0, corner + j * l0, dim == 3 ? corner + k * l0 : 0.0);
    return p;
}

/* The distance formula of the library, written out again. */
static double dist2(const mf_particles *p, size_t i, size_t j)
{
    const double *a = p->pos + 3 * i, *b = p->pos + 3 * j;
    double dx = b[0] - a[0], dy = b[1] - a[1];
    double d2 = dx * dx + dy * dy;
    if (p->dim == 3) {
        double dz = b[2] - a[2];
        d2 += dz * dz;
    }
    return d2;
}

static int compare_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* The list equals brute force as a set per particle. Returns the number of
 * particles whose list differs (and reports the first few). */
static size_t compare_with_brute_force(const mf_nlist *nl, const mf_particles *p, double radius,
                                       const char *what)
{
    const size_t n = p->n;
    const double r2 = radius * radius;
    size_t bad = 0;
    CHECK_MSG(nl->n == n, "%s: list covers %zu particles, store has %zu", what, nl->n, n);
    if (nl->n != n)
        return n;
    uint32_t *got = malloc((n + 1) * sizeof *got);
    uint32_t *want = malloc((n + 1) * sizeof *want);
    if (!got || !want) {
        fprintf(stderr, "out of memory in test\n");
        exit(EXIT_FAILURE);
    }
    for (size_t i = 0; i < n; i++) {
        size_t ng = nl->start[i + 1] - nl->start[i];
        if (ng > n) {
            bad++;
            continue;
        }
        memcpy(got, nl->j + nl->start[i], ng * sizeof *got);
        qsort(got, ng, sizeof *got, compare_u32);
        size_t nw = 0;
        for (size_t j = 0; j < n; j++)
            if (j != i && dist2(p, i, j) < r2)
                want[nw++] = (uint32_t)j;
        bool same = ng == nw && memcmp(got, want, nw * sizeof *got) == 0;
        if (!same) {
            if (bad < 5)
                fprintf(stderr,
                        "%s: particle %zu at (%g, %g, %g): %zu neighbours, brute force %zu\n",
                        what, i, p->pos[3 * i], p->pos[3 * i + 1], p->pos[3 * i + 2], ng, nw);
            bad++;
        }
    }
    free(got);
    free(want);
    CHECK_MSG(bad == 0, "%s: %zu particles with a wrong list", what, bad);
    return bad;
}

/* Grid of cell_size + list of radius, checked against brute force. */
static void check_build(const mf_particles *p, double cell_size, double radius, const char *what)
{
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    CHECK_OK(mf_grid_build(&g, p, cell_size));
    CHECK_OK(mf_nlist_build(&nl, &g, p, radius));
    compare_with_brute_force(&nl, p, radius, what);
    CHECK(nl.radius == radius);
    mf_nlist_free(&nl);
    mf_grid_free(&g);
}

static size_t interior_count(const mf_nlist *nl, size_t i)
{
    return nl->start[i + 1] - nl->start[i];
}

/* ---- scenarios ------------------------------------------------------------ */

static void test_random(void)
{
    mf_particles *p2 = random_points(2, 3000, 10.0);
    check_build(p2, 0.5, 0.5, "random 2-D, cell = radius");
    check_build(p2, 0.8, 0.5, "random 2-D, cell > radius");
    mf_particles_destroy(p2);

    mf_particles *p3 = random_points(3, 4000, 5.0);
    check_build(p3, 0.6, 0.6, "random 3-D, cell = radius");
    check_build(p3, 1.0, 0.45, "random 3-D, cell > radius");
    /* Cells far larger than the radius: many candidates per particle, the
     * list build repeats the distance test instead of keeping bits. */
    check_build(p3, 2.5, 0.45, "random 3-D, cell >> radius");
    mf_particles_destroy(p3);

    /* A large offset: positions far from 0 relative to the spacing. */
    mf_particles *p4 = new_store(3);
    for (int i = 0; i < 2000; i++)
        add_point(p4, 1e4 + uniform(), -3e4 + uniform(), 7e3 + uniform());
    check_build(p4, 0.15, 0.15, "random 3-D far from the origin");
    mf_particles_destroy(p4);
}

/* Lattice spacing l0 with the cell size equal to the radius: with l0 = 0.1
 * (not a binary fraction) distances between lattice points round either way
 * around the radius, and many points sit on cell faces. */
static void test_lattice(void)
{
    const double l0 = 0.1;
    const double radii[] = {2.1 * l0, 3.1 * l0, 2.0 * l0, 3.0 * l0};
    for (int r = 0; r < 4; r++) {
        char what[96];
        mf_particles *p2 = lattice(2, 40, l0, -1.3);
        snprintf(what, sizeof what, "square lattice, radius %.1f l0", radii[r] / l0);
        check_build(p2, radii[r], radii[r], what);
        mf_particles_destroy(p2);
        mf_particles *p3 = lattice(3, 15, l0, 0.0);
        snprintf(what, sizeof what, "cubic lattice, radius %.1f l0", radii[r] / l0);
        check_build(p3, radii[r], radii[r], what);
        mf_particles_destroy(p3);
    }
}

/* Integer coordinates: distances are exact, so pairs at exactly the radius
 * must be left out and the interior counts are known. */
static void test_exact_radius(void)
{
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);

    mf_particles *p2 = lattice(2, 9, 1.0, 0.0);
    CHECK_OK(mf_grid_build(&g, p2, 2.0));
    CHECK_OK(mf_nlist_build(&nl, &g, p2, 2.0));
    compare_with_brute_force(&nl, p2, 2.0, "integer square lattice, radius 2");
    /* Centre point (4, 4) = index 4 * 9 + 4: d^2 in {1, 2} -> 8 neighbours, d = 2 excluded. */
    CHECK(interior_count(&nl, 40) == 8);
    CHECK_OK(mf_nlist_build(&nl, &g, p2, 1.5));
    CHECK(interior_count(&nl, 40) == 8);
    CHECK_OK(mf_nlist_build(&nl, &g, p2, 1.0));
    CHECK(interior_count(&nl, 40) == 0);
    mf_particles_destroy(p2);

    mf_particles *p3 = lattice(3, 7, 1.0, 0.0);
    CHECK_OK(mf_grid_build(&g, p3, 2.0));
    CHECK_OK(mf_nlist_build(&nl, &g, p3, 2.0));
    compare_with_brute_force(&nl, p3, 2.0, "integer cubic lattice, radius 2");
    /* Centre (3, 3, 3): d^2 in {1, 2, 3} -> 6 + 12 + 8 = 26. */
    CHECK(interior_count(&nl, 3 * 49 + 3 * 7 + 3) == 26);
    mf_particles_destroy(p3);

    /* A 3-4-5 triangle: at radius 5 the pair at distance 5 is out. */
    mf_particles *p = new_store(2);
    add_point(p, 0.0, 0.0, 0.0);
    add_point(p, 3.0, 4.0, 0.0);
    add_point(p, 3.0, 3.96875, 0.0); /* just inside, exactly representable */
    CHECK_OK(mf_grid_build(&g, p, 5.0));
    CHECK_OK(mf_nlist_build(&nl, &g, p, 5.0));
    compare_with_brute_force(&nl, p, 5.0, "3-4-5 pair");
    CHECK(interior_count(&nl, 0) == 1);
    CHECK(nl.j[nl.start[0]] == 2);
    mf_particles_destroy(p);

    mf_nlist_free(&nl);
    mf_grid_free(&g);
}

/* Pairs a hair closer than the cell size whose naive cell coordinates
 * floor((x - origin) / h) differ by 2 after rounding (found by search, with
 * a particle at 0 fixing the origin): the grid must still pair them. */
static void test_rounding_at_cell_size(void)
{
    const struct { double h, a, b; } cases[] = {
        {0.021, 0x1.580fb224aada4p+1, 0x1.5abfd2e946802p+1},
        {0.21, 0x1.ff8f251c193b3p+6, 0x1.003317acc4ef8p+7},
    };
    for (int c = 0; c < 2; c++) {
        mf_particles *p = new_store(2);
        add_point(p, 0.0, 0.0, 0.0);
        add_point(p, cases[c].a, 0.0, 0.0);
        add_point(p, cases[c].b, 0.0, 0.0);
        CHECK(dist2(p, 1, 2) < cases[c].h * cases[c].h);
        check_build(p, cases[c].h, cases[c].h, "pair just inside the cell size");
        mf_particles_destroy(p);
    }
}

static void test_tiny_sets(void)
{
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);

    /* No particles at all. */
    mf_particles *p0 = new_store(3);
    CHECK_OK(mf_grid_build(&g, p0, 1.0));
    CHECK(g.ncells == 0 && g.np == 0);
    CHECK_OK(mf_nlist_build(&nl, &g, p0, 1.0));
    CHECK(nl.n == 0 && nl.start[0] == 0);
    mf_particles_destroy(p0);

    /* One particle: one cell, no neighbours. */
    mf_particles *p1 = new_store(3);
    add_point(p1, 0.5, -2.0, 3.0);
    CHECK_OK(mf_grid_build(&g, p1, 1.0));
    CHECK(g.ncells == 1 && g.np == 1);
    CHECK_OK(mf_nlist_build(&nl, &g, p1, 1.0));
    CHECK(nl.n == 1 && nl.start[1] == 0);
    CHECK(mf_grid_point_cell(&g, p1->pos) == 0);
    const double far[3] = {10.0, -2.0, 3.0}, below[3] = {-10.0, -2.0, 3.0};
    CHECK(mf_grid_point_cell(&g, far) == -1);
    CHECK(mf_grid_point_cell(&g, below) == -1);
    CHECK(mf_nlist_memory(&nl) >= 2 * sizeof(uint32_t));
    CHECK(mf_grid_memory(&g) > 0);
    mf_particles_destroy(p1);

    /* Two coincident particles (r = 0 < radius) are neighbours of each other;
     * a third far away is nobody's. */
    mf_particles *pc = new_store(2);
    add_point(pc, 1.0, 1.0, 0.0);
    add_point(pc, 1.0, 1.0, 0.0);
    add_point(pc, 9.0, 1.0, 0.0);
    CHECK_OK(mf_grid_build(&g, pc, 0.5));
    CHECK(g.ncells == 2);
    CHECK_OK(mf_nlist_build(&nl, &g, pc, 0.5));
    compare_with_brute_force(&nl, pc, 0.5, "coincident pair");
    CHECK(interior_count(&nl, 0) == 1 && nl.j[nl.start[0]] == 1);
    CHECK(interior_count(&nl, 1) == 1 && nl.j[nl.start[1]] == 0);
    CHECK(interior_count(&nl, 2) == 0);
    mf_particles_destroy(pc);

    mf_nlist_free(&nl);
    mf_grid_free(&g);
}

/* Occupied cells by brute force: distinct cell coordinates, with the cell
 * width documented in mf_neighbours.h. */
static size_t distinct_cells(const mf_grid *g, const mf_particles *p)
{
    const double w = g->cell_size * (1.0 + MF_GRID_CELL_SLACK);
    uint64_t *keys = malloc((p->n + 1) * sizeof *keys);
    if (!keys)
        exit(EXIT_FAILURE);
    for (size_t i = 0; i < p->n; i++) {
        uint64_t c[3] = {0, 0, 0};
        for (int d = 0; d < p->dim; d++)
            c[d] = (uint64_t)floor((p->pos[3 * i + d] - g->origin[d]) / w);
        keys[i] = mf_grid_key(c[0], c[1], c[2]);
    }
    qsort(keys, p->n, sizeof *keys, compare_u64);
    size_t distinct = 0;
    for (size_t i = 0; i < p->n; i++)
        distinct += i == 0 || keys[i] != keys[i - 1];
    free(keys);
    return distinct;
}

/* Every particle is listed in the cell its position falls in. */
static void check_cells_hold_particles(const mf_grid *g, const mf_particles *p, const char *what)
{
    size_t bad = 0;
    for (size_t k = 0; k < g->np; k++) {
        size_t i = g->order[k];
        long c = mf_grid_point_cell(g, p->pos + 3 * i);
        if (c < 0 || k < g->cell_start[c] || k >= g->cell_start[c + 1])
            bad++;
    }
    CHECK_MSG(bad == 0, "%s: %zu particles outside their cell's range", what, bad);
    for (size_t c = 0; c + 1 < g->ncells; c++)
        CHECK(g->cell_key[c] < g->cell_key[c + 1] && g->cell_start[c] < g->cell_start[c + 1]);
}

/* An L-shaped corridor of two thin arms: the occupied cells are a sliver of
 * the bounding box, and the grid must pay only for them. */
static mf_particles *l_shape(int dim, int arm, int width, double l0)
{
    mf_particles *p = new_store(dim);
    int depth = dim == 3 ? width : 1;
    for (int k = 0; k < depth; k++)
        for (int j = 0; j < arm; j++)
            for (int i = 0; i < arm; i++)
                if (i < width || j < width) /* two arms along x and y */
                    add_point(p, i * l0, j * l0, dim == 3 ? k * l0 : 0.0);
    return p;
}

static void check_l_shape(int dim, int arm, int width, bool small)
{
    const double l0 = 0.01, radius = 2.1 * l0;
    char what[64];
    snprintf(what, sizeof what, "%d-D L shape, arm %d", dim, arm);
    mf_particles *p = l_shape(dim, arm, width, l0);
    mf_grid g;
    mf_grid_init(&g);
    CHECK_OK(mf_grid_build(&g, p, radius));
    size_t box_cells = g.nbox[0] * g.nbox[1] * g.nbox[2];
    size_t occupied = distinct_cells(&g, p);
    CHECK_MSG(g.ncells == occupied, "%s: %zu cells, brute force %zu", what, g.ncells, occupied);
    CHECK_MSG(g.ncells < 0.2 * box_cells, "%s: %zu occupied cells of %zu in the box", what,
              g.ncells, box_cells);
    check_cells_hold_particles(&g, p, what);
    /* A dense grid needs at least a start offset per box cell on top of the
     * per-particle arrays both kinds of grid have. */
    size_t per_particle = sizeof(size_t) + 3 * sizeof(double) + 2 * sizeof(uint64_t) +
                          2 * sizeof(uint32_t);
    size_t dense = box_cells * sizeof(size_t) + p->n * per_particle;
    size_t mem = mf_grid_memory(&g);
    /* Memory follows particles and occupied cells (with the buffers'
     * headroom and a hash table of at most 8 slots per cell)... */
    size_t per_cell = 2 * sizeof(size_t) + 2 * 9 * sizeof(uint32_t); /* key, start, rows */
    size_t bound = 2 * p->n * per_particle + 2 * g.ncells * per_cell + 8 * g.ncells * 12 + 4096;
    CHECK_MSG(mem <= bound, "%s: grid memory %zu bytes > %zu", what, mem, bound);
    /* ...and for a large thin L is a fraction of a dense grid's. */
    if (!small)
        CHECK_MSG(mem < 0.2 * dense, "%s: grid memory %zu bytes, a dense grid %zu", what, mem,
                  dense);
    printf("%s: %zu particles, %zu occupied cells of %zu, grid %zu bytes (dense >= %zu)\n", what,
           p->n, g.ncells, box_cells, mem, dense);
    if (small) { /* brute force is O(N^2) */
        mf_nlist nl;
        mf_nlist_init(&nl);
        CHECK_OK(mf_nlist_build(&nl, &g, p, radius));
        compare_with_brute_force(&nl, p, radius, what);
        mf_nlist_free(&nl);
    }
    mf_grid_free(&g);
    mf_particles_destroy(p);
}

static void test_l_shape(void)
{
    check_l_shape(2, 3000, 3, false);
    check_l_shape(3, 4000, 2, false);
    check_l_shape(2, 400, 3, true);
    check_l_shape(3, 150, 3, true);
}

/* A filtered list equals a list built directly at the smaller radius. */
static void test_filter(void)
{
    mf_particles *p = random_points(3, 3000, 4.0);
    mf_grid g;
    mf_nlist big, small, direct;
    mf_grid_init(&g);
    mf_nlist_init(&big);
    mf_nlist_init(&small);
    mf_nlist_init(&direct);
    CHECK_OK(mf_grid_build(&g, p, 0.6));
    CHECK_OK(mf_nlist_build(&big, &g, p, 0.6));
    CHECK_OK(mf_nlist_filter(&small, &big, p, 0.35));
    CHECK_OK(mf_nlist_build(&direct, &g, p, 0.35));
    compare_with_brute_force(&small, p, 0.35, "filtered list");
    /* Same grid: the filtered list keeps the build's order exactly. */
    CHECK(small.start[p->n] == direct.start[p->n]);
    CHECK(memcmp(small.start, direct.start, (p->n + 1) * sizeof(uint32_t)) == 0);
    CHECK(memcmp(small.j, direct.j, direct.start[p->n] * sizeof(uint32_t)) == 0);
    /* Filtering at the same radius is the identity. */
    CHECK_OK(mf_nlist_filter(&small, &big, p, 0.6));
    CHECK(memcmp(small.j, big.j, big.start[p->n] * sizeof(uint32_t)) == 0);
    /* A larger radius than the source list is an error. */
    CHECK(mf_nlist_filter(&small, &big, p, 0.7) == MF_ERR_INPUT);
    mf_error_clear();
    mf_nlist_free(&big);
    mf_nlist_free(&small);
    mf_nlist_free(&direct);
    mf_grid_free(&g);
    mf_particles_destroy(p);
}

/* Rebuilding the same grid and list after particles move, appear and vanish
 * (buffers are reused, grown and shrunk) gives correct lists. */
static void test_rebuild(void)
{
    mf_particles *p = random_points(3, 2000, 3.0);
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    const double radius = 0.4;
    for (int step = 0; step < 6; step++) {
        CHECK_OK(mf_grid_build(&g, p, radius));
        CHECK_OK(mf_nlist_build(&nl, &g, p, radius));
        char what[64];
        snprintf(what, sizeof what, "rebuild step %d (%zu particles)", step, p->n);
        compare_with_brute_force(&nl, p, radius, what);
        /* Move everything, sometimes spreading the set out. */
        double stretch = step % 2 ? 1.0 : 1.7;
        for (size_t i = 0; i < p->n; i++)
            for (int d = 0; d < 3; d++)
                p->pos[3 * i + d] = stretch * p->pos[3 * i + d] + 0.2 * (uniform() - 0.5);
        if (step == 1) { /* grow well past the buffers' headroom */
            for (int i = 0; i < 3000; i++)
                add_point(p, 5.0 * uniform(), 5.0 * uniform(), 5.0 * uniform());
        }
        if (step == 3) { /* shrink: remove 90% */
            uint8_t *flag = calloc(p->n, 1);
            for (size_t i = 0; i < p->n; i++)
                flag[i] = i % 10 != 0;
            size_t removed = 0;
            CHECK_OK(mf_particles_remove(p, flag, &removed));
            free(flag);
        }
    }
    mf_nlist_free(&nl);
    mf_grid_free(&g);
    mf_particles_destroy(p);
}

/* The same input gives the same list, element by element, for any thread
 * count. */
static void test_determinism(void)
{
    mf_particles *p = random_points(3, 20000, 6.0);
    mf_grid g;
    mf_nlist a, b;
    mf_grid_init(&g);
    mf_nlist_init(&a);
    mf_nlist_init(&b);
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    CHECK_OK(mf_grid_build(&g, p, 0.35));
    CHECK_OK(mf_nlist_build(&a, &g, p, 0.35));
    omp_set_num_threads(threads > 4 ? threads : 4);
    CHECK_OK(mf_grid_build(&g, p, 0.35));
    CHECK_OK(mf_nlist_build(&b, &g, p, 0.35));
    omp_set_num_threads(threads);
    CHECK(a.start[p->n] == b.start[p->n]);
    CHECK(a.start[p->n] > 0);
    CHECK(memcmp(a.start, b.start, (p->n + 1) * sizeof(uint32_t)) == 0);
    CHECK(memcmp(a.j, b.j, a.start[p->n] * sizeof(uint32_t)) == 0);
    mf_nlist_free(&a);
    mf_nlist_free(&b);
    mf_grid_free(&g);
    mf_particles_destroy(p);
}

/* A copy of a list (start and entries). */
static void copy_list(mf_nlist *to, const mf_nlist *from)
{
    mf_nlist_init(to);
    to->n = from->n;
    to->radius = from->radius;
    to->start = malloc((from->n + 1) * sizeof(uint32_t));
    to->j = malloc((from->start[from->n] + 1) * sizeof(uint32_t));
    memcpy(to->start, from->start, (from->n + 1) * sizeof(uint32_t));
    memcpy(to->j, from->j, from->start[from->n] * sizeof(uint32_t));
    to->cap_n = from->n + 1;
    to->cap_j = from->start[from->n] + 1;
}

static bool same_lists(const mf_nlist *a, const mf_nlist *b)
{
    return a->n == b->n && memcmp(a->start, b->start, (a->n + 1) * sizeof(uint32_t)) == 0 &&
           memcmp(a->j, b->j, a->start[a->n] * sizeof(uint32_t)) == 0;
}

/* A kept list re-sorted only where a particle changed cell (the service's
 * way: mf_grid_cells at the build, mf_nlist_mark_moved, mf_nlist_sort_marked)
 * is the list sorted in full, after random moves that take some particles
 * into other cells, over three rounds (the cells of a round from its keys),
 * for the list and the sub-list of the same build, in 2-D and 3-D; and with
 * the last quarter of the particles copies (a halo: empty rows of their
 * own, found only as j's). */
static void test_sort_moved(void)
{
    for (int run = 0; run < 4; run++) {
        const int dim = 2 + run % 2;
        const bool copies = run >= 2;
        mf_particles *p = random_points(dim, dim == 2 ? 3000 : 4000, 2.0);
        if (copies)
            p->n_owned = p->n - p->n / 4;
        const double cell = dim == 2 ? 0.1 : 0.25;
        mf_grid g;
        mf_nlist nl, sub;
        mf_grid_init(&g);
        mf_nlist_init(&nl);
        mf_nlist_init(&sub);
        CHECK_OK(mf_grid_build(&g, p, cell));
        CHECK_OK(mf_nlist_build_pair(&nl, &sub, &g, p, cell, 0.6 * cell));
        uint32_t *cell0 = malloc(p->n * sizeof *cell0);
        uint64_t *keys = malloc(p->n * sizeof *keys);
        uint8_t *dirty = malloc(p->n);
        CHECK(mf_grid_cells(&g, cell0));
        int reordered = 0;
        for (int round = 0; round < 3; round++) {
            for (size_t i = 0; i < p->n; i++)
                for (int d = 0; d < dim; d++)
                    p->pos[3 * i + d] += 0.1 * cell * (uniform() - 0.5);
            bool packed = false;
            CHECK_OK(mf_grid_keys(p, cell, keys, &packed));
            CHECK(packed);
            size_t moved = 0, marked = 0;
            for (size_t i = 0; i < p->n; i++)
                moved += (uint32_t)(keys[i] >> 32) != cell0[i];
            mf_nlist full, fsub, orig;
            copy_list(&orig, &nl);
            copy_list(&full, &nl);
            copy_list(&fsub, &sub);
            mf_nlist_sort(&full, keys, packed);
            mf_nlist_sort(&fsub, keys, packed);
            mf_nlist_mark_moved(&nl, keys, cell0, p->n_owned, dirty);
            for (size_t i = 0; i < p->n; i++)
                marked += dirty[i];
            mf_nlist_sort_marked(&nl, keys, packed, dirty);
            mf_nlist_sort_marked(&sub, keys, packed, dirty);
            /* some particles crossed, and not every list was marked */
            CHECK_MSG(moved > 0 && marked < p->n, "%d-D round %d: %zu moved, %zu of %zu marked",
                      dim, round, moved, marked, p->n);
            CHECK_MSG(same_lists(&nl, &full) && same_lists(&sub, &fsub),
                      "%d-D round %d%s: the marked sort differs from the full sort", dim, round,
                      copies ? " (with copies)" : "");
            reordered += !same_lists(&orig, &full); /* the sorts had work to do */
            mf_nlist_free(&orig);
            for (size_t i = 0; i < p->n; i++)
                cell0[i] = (uint32_t)(keys[i] >> 32);
            mf_nlist_free(&full);
            mf_nlist_free(&fsub);
        }
        CHECK_MSG(reordered == 3, "%d-D%s: the moves reordered the lists in %d of 3 rounds", dim,
                  copies ? " (with copies)" : "", reordered);
        free(cell0);
        free(keys);
        free(dirty);
        mf_nlist_free(&nl);
        mf_nlist_free(&sub);
        mf_grid_free(&g);
        mf_particles_destroy(p);
    }
}

/* Sorting particles by cell (locality order) keeps every particle and its
 * fields; the lists of the sorted store are still right. */
static void test_locality_order(void)
{
    mf_particles *p = random_points(2, 3000, 8.0);
    int f = -1;
    CHECK_OK(mf_particles_request_field(p, "tag", 1, MF_FIELD_DOUBLE, false, &f));
    for (size_t i = 0; i < p->n; i++)
        mf_particles_fd(p, f)[i] = (double)p->id[i];
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    CHECK_OK(mf_grid_build(&g, p, 0.5));
    size_t *perm = malloc(p->n * sizeof *perm);
    CHECK_OK(mf_grid_locality_order(&g, perm));
    CHECK_OK(mf_particles_permute(p, perm));
    free(perm);
    size_t bad = 0;
    for (size_t i = 0; i < p->n; i++)
        bad += mf_particles_fd(p, f)[i] != (double)p->id[i];
    CHECK(bad == 0);
    CHECK_OK(mf_grid_build(&g, p, 0.5));
    /* Already sorted: the order is now the identity. */
    bad = 0;
    for (size_t k = 0; k < g.np; k++)
        bad += g.order[k] != k;
    CHECK(bad == 0);
    CHECK_OK(mf_nlist_build(&nl, &g, p, 0.5));
    compare_with_brute_force(&nl, p, 0.5, "after locality sort");
    mf_nlist_free(&nl);
    mf_grid_free(&g);
    mf_particles_destroy(p);
}

/* ---- a large list, rebuilt in place -------------------------------------- */

static const double *sort_pos; /* qsort has no context argument */
static int compare_x(const void *a, const void *b)
{
    const double xa = sort_pos[3 * *(const uint32_t *)a], xb = sort_pos[3 * *(const uint32_t *)b];
    return (xa > xb) - (xa < xb);
}

/* The list equals brute force as a set per particle, for sets too large
 * for compare_with_brute_force: the pairs closer than radius found by a
 * sweep along x (particles sorted by x, each paired with those less than
 * radius ahead), every entry checked for distance and duplicates. */
static size_t compare_with_sweep(const mf_nlist *nl, const mf_particles *p, double radius,
                                 const char *what)
{
    const size_t n = p->n;
    const double r2 = radius * radius;
    CHECK_MSG(nl->n == n, "%s: list covers %zu particles, store has %zu", what, nl->n, n);
    if (nl->n != n)
        return n;
    uint32_t *s = malloc((n ? n : 1) * sizeof *s);
    size_t *count = calloc(n ? n : 1, sizeof *count);
    uint32_t *got = malloc((n ? n : 1) * sizeof *got);
    if (!s || !count || !got) {
        fprintf(stderr, "out of memory in test\n");
        exit(EXIT_FAILURE);
    }
    for (size_t i = 0; i < n; i++)
        s[i] = (uint32_t)i;
    sort_pos = p->pos;
    qsort(s, n, sizeof *s, compare_x);
    for (size_t a = 0; a < n; a++)
        for (size_t b = a + 1; b < n && p->pos[3 * s[b]] - p->pos[3 * s[a]] < radius; b++)
            if (dist2(p, s[a], s[b]) < r2) {
                count[s[a]]++;
                count[s[b]]++;
            }
    size_t bad = 0;
    for (size_t i = 0; i < n; i++) {
        const size_t ng = nl->start[i + 1] - nl->start[i];
        bool ok = ng == count[i];
        if (ok) {
            memcpy(got, nl->j + nl->start[i], ng * sizeof *got);
            qsort(got, ng, sizeof *got, compare_u32);
            for (size_t e = 0; ok && e < ng; e++)
                ok = got[e] != i && got[e] < n && dist2(p, i, got[e]) < r2 &&
                     (e == 0 || got[e] > got[e - 1]);
        }
        if (!ok && bad++ < 5)
            fprintf(stderr, "%s: particle %zu: %zu neighbours, brute force %zu\n", what, i, ng,
                    count[i]);
    }
    free(s);
    free(count);
    free(got);
    CHECK_MSG(bad == 0, "%s: %zu particles with a wrong list", what, bad);
    return bad;
}

/* A list and sub-list rebuilt in place (the same arrays: the build gives
 * the old entries' pages back first) after the particles moved, with a
 * fill pass in several blocks (each block's scratch given back as it goes):
 * the lists equal brute force and, entry for entry, the lists built into
 * fresh arrays; a third build at the same positions, over scratch whose
 * pages were given back, equals the second. */
static void test_rebuild_in_place(void)
{
    mf_particles *p = random_points(3, 60000, 5.5);
    const double radius = 0.3, sub_radius = 0.2;
    mf_grid g;
    mf_nlist nl, sub, fresh, fresh_sub;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    mf_nlist_init(&sub);
    mf_nlist_init(&fresh);
    mf_nlist_init(&fresh_sub);
    CHECK_OK(mf_grid_build(&g, p, radius));
    CHECK_OK(mf_nlist_build_pair(&nl, &sub, &g, p, radius, sub_radius));
    /* At least three blocks of nlist.c's FILL_BLOCK_BYTES (1 MiB) of scratch. */
    CHECK_MSG(nl.work_bytes > ((size_t)2 << 20), "list scratch %zu bytes: too few blocks",
              nl.work_bytes);
    const uint32_t *j_before = nl.j, *sub_before = sub.j;
    for (size_t i = 0; i < p->n; i++)
        for (int d = 0; d < 3; d++)
            p->pos[3 * i + d] += 0.01 * (uniform() - 0.5);
    CHECK_OK(mf_grid_build(&g, p, radius));
    CHECK_OK(mf_nlist_build_pair(&nl, &sub, &g, p, radius, sub_radius));
    CHECK_MSG(nl.j == j_before && sub.j == sub_before,
              "the rebuild did not reuse the arrays (the case this test is for)");
    compare_with_sweep(&nl, p, radius, "list rebuilt in place");
    compare_with_sweep(&sub, p, sub_radius, "sub-list rebuilt in place");
    CHECK_OK(mf_nlist_build_pair(&fresh, &fresh_sub, &g, p, radius, sub_radius));
    CHECK(fresh.start[p->n] == nl.start[p->n] && fresh_sub.start[p->n] == sub.start[p->n]);
    CHECK(memcmp(fresh.start, nl.start, (p->n + 1) * sizeof(uint32_t)) == 0);
    CHECK(memcmp(fresh.j, nl.j, nl.start[p->n] * sizeof(uint32_t)) == 0);
    CHECK(memcmp(fresh_sub.j, sub.j, sub.start[p->n] * sizeof(uint32_t)) == 0);
    CHECK_OK(mf_nlist_build_pair(&fresh, &fresh_sub, &g, p, radius, sub_radius));
    CHECK(memcmp(fresh.j, nl.j, nl.start[p->n] * sizeof(uint32_t)) == 0);
    CHECK(memcmp(fresh_sub.j, sub.j, sub.start[p->n] * sizeof(uint32_t)) == 0);
    mf_nlist_free(&nl);
    mf_nlist_free(&sub);
    mf_nlist_free(&fresh);
    mf_nlist_free(&fresh_sub);
    mf_grid_free(&g);
    mf_particles_destroy(p);
}

static void test_errors(void)
{
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    mf_particles *p = new_store(3);
    add_point(p, 0.0, 0.0, 0.0);
    add_point(p, 1e9, 0.0, 0.0);
    /* 1e9 / 1e-3 cells on x is far beyond 2^21. */
    CHECK(mf_grid_build(&g, p, 1e-3) == MF_ERR_INPUT);
    CHECK(strstr(mf_error_message(), "spacing") != NULL);
    mf_error_clear();
    CHECK(g.ncells == 0 && g.np == 0);
    CHECK(mf_grid_build(&g, p, 0.0) == MF_ERR_INPUT);
    mf_error_clear();
    p->pos[3] = NAN;
    CHECK(mf_grid_build(&g, p, 1.0) == MF_ERR_NUMERIC);
    mf_error_clear();
    p->pos[3] = 0.5;
    CHECK_OK(mf_grid_build(&g, p, 1.0));
    CHECK(mf_nlist_build(&nl, &g, p, 1.5) == MF_ERR_INPUT); /* radius > cell */
    mf_error_clear();
    add_point(p, 0.2, 0.2, 0.2);
    CHECK(mf_nlist_build(&nl, &g, p, 1.0) == MF_ERR_INPUT); /* stale grid */
    mf_error_clear();
    mf_nlist_free(&nl);
    mf_grid_free(&g);
    mf_particles_destroy(p);
}

int main(void)
{
    test_random();
    test_lattice();
    test_exact_radius();
    test_rounding_at_cell_size();
    test_tiny_sets();
    test_l_shape();
    test_filter();
    test_rebuild();
    test_determinism();
    test_locality_order();
    test_sort_moved();
    test_rebuild_in_place(); /* last: its draws would change the points above */
    test_errors();
    return mf_test_summary("neighbours");
}
