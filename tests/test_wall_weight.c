/* test_wall_weight.c: the wall weight tables (mf_wall_weight.h) against
 * what they stand for.
 *
 * - A particle of a lattice block whose wall is a face (k + 1/2) l0 below
 *   it: the fluid lattice above the face plus the table's wall sum is the
 *   whole lattice, so n_fluid + zn = n0 (Harada et al. 2008's Z(d) is
 *   exactly the missing part) and the gradient of a constant vanishes
 *   (sum over the fluid + g = 0), in 2-D and 3-D.
 * - An edge (2-D corner) and a 3-D corner the same way, the wall's sums
 *   the faces' less the edges' plus the corner's (the terms of one, two
 *   and three constrained axes, as walls_sums.c expands a box).
 * - The same through a solid's expansion (walls_sums.c): a particle in the
 *   corner of a closed 2-D tank and one beside a box obstacle in 3-D.
 * - Between the nodes the interpolated tables against brute force over the
 *   virtual lattice (mf_wall_term_direct), at random offsets. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_kernel.h"
#include "mf_test.h"
#include "mf_wall_weight.h"
#include "mf_walls.h"

static const double RE_ND = 3.1, RE_GRAD = 2.1, RE_LAP = 3.1;

/* Sums over the lattice points j (offset v = j l0 from the particle) that
 * are on the fluid side of every constrained plane: v_k > -delta_k along
 * the wall normals -e_k (the wall is toward e_k), and of the whole lattice. */
static void lattice_sums(int dim, int c, const double *delta, double l0, double *n_fluid,
                         double g_fluid[3], double *n_all)
{
    *n_fluid = *n_all = 0;
    for (int a = 0; a < 3; a++)
        g_fluid[a] = 0;
    const long J = (long)ceil(RE_ND / 1.0) + 1;
    for (long k = dim == 3 ? -J : 0; k <= (dim == 3 ? J : 0); k++)
        for (long j = -J; j <= J; j++)
            for (long i = -J; i <= J; i++) {
                if (!i && !j && !k)
                    continue;
                /* e_k = -axis k: the wall lies below on each constrained axis. */
                const double v[3] = {i * l0, j * l0, k * l0};
                const double r = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
                const double wn = mf_weight(r, RE_ND * l0), wg = mf_weight(r, RE_GRAD * l0);
                *n_all += wn;
                bool fluid = true;
                for (int a = 0; a < c; a++)
                    fluid = fluid && v[a] > -delta[a];
                if (!fluid)
                    continue;
                *n_fluid += wn;
                for (int a = 0; a < 3; a++)
                    g_fluid[a] += v[a] / (r * r) * wg;
            }
}

static void test_identity(int dim, int c)
{
    const double l0 = 0.01;
    mf_wall_tables *t = NULL;
    CHECK(mf_wall_tables_create(dim, l0, RE_ND * l0, RE_GRAD * l0, RE_LAP * l0, &t) == 0);
    if (!t)
        return;
    double worst_n = 0, worst_g = 0;
    for (int k = 0; k < 4; k++) {
        double delta[3];
        for (int a = 0; a < c; a++)
            delta[a] = (k + a % 2 + 0.5) * l0; /* corners at unequal depths */
        /* The wall behind c planes is the union of their half-spaces: by
         * inclusion and exclusion, each subset of the planes with sign
         * (-1)^(|S| + 1) (two faces less their quadrant; three faces, less
         * three edges, plus the octant). */
        mf_wall_sums s;
        memset(&s, 0, sizeof s);
        for (int set = 1; set < (1 << c); set++) {
            mf_wall_term term;
            memset(&term, 0, sizeof term);
            for (int a = 0; a < c; a++)
                if (set & (1 << a)) {
                    term.delta[term.c] = delta[a];
                    term.e[term.c][a] = -1;
                    term.c++;
                }
            term.sign = term.c % 2 ? 1 : -1;
            mf_wall_term_add(t, &term, &s);
        }
        double nf, gf[3], n0;
        lattice_sums(dim, c, delta, l0, &nf, gf, &n0);
        worst_n = fmax(worst_n, fabs(nf + s.zn - n0) / n0);
        for (int a = 0; a < dim; a++)
            worst_g = fmax(worst_g, fabs(gf[a] + s.g[a]) * l0 / n0);
    }
    printf("%d-D, %d constrained axes: |n_fluid + zn - n0| / n0 <= %.2e, |g_fluid + g| l0 / n0 "
           "<= %.2e\n", dim, c, worst_n, worst_g);
    CHECK_MSG(worst_n < 1e-12 && worst_g < 1e-12, "%d-D c = %d: n %g, g %g", dim, c, worst_n,
              worst_g);
    mf_wall_tables_destroy(t);
}

static void test_interpolation(int dim)
{
    const double l0 = 1;
    mf_wall_tables *t = NULL;
    CHECK(mf_wall_tables_create(dim, l0, RE_ND, RE_GRAD, RE_LAP, &t) == 0);
    if (!t)
        return;
    srand(7);
    double worst = 0, n0 = 0;
    {
        double nf, gf[3], delta[1] = {100};
        lattice_sums(dim, 0, delta, l0, &nf, gf, &n0);
    }
    for (int trial = 0; trial < 300; trial++) {
        mf_wall_term term;
        memset(&term, 0, sizeof term);
        term.c = 1 + trial % (dim == 3 ? 3 : 2);
        term.sign = 1;
        for (int a = 0; a < term.c; a++) {
            term.delta[a] = 0.3 + 3.0 * rand() / (double)RAND_MAX;
            term.e[a][a] = -1;
        }
        mf_wall_sums a, b;
        memset(&a, 0, sizeof a);
        memset(&b, 0, sizeof b);
        mf_wall_term_add(t, &term, &a);
        mf_wall_term_direct(t, &term, &b);
        worst = fmax(worst, fabs(a.zn - b.zn) / n0);
    }
    printf("%d-D interpolated against direct, 300 random offsets: |zn - zn_direct| / n0 <= %.3e\n",
           dim, worst);
    CHECK_MSG(worst < 1e-3, "%d-D: %g", dim, worst);
    mf_wall_tables_destroy(t);
}

/* Lattice points (i + 1/2) l0 of a region: the fluid of a block filling
 * it, as the scene places it. n of the particle at x from them. */
static double block_density(int dim, const double *mn, const double *mx, const double *x,
                            double l0, const double *hole_mn, const double *hole_mx)
{
    double n = 0;
    long N[3] = {1, 1, 1};
    for (int a = 0; a < dim; a++)
        N[a] = lround((mx[a] - mn[a]) / l0);
    for (long k = 0; k < N[2]; k++)
        for (long j = 0; j < N[1]; j++)
            for (long i = 0; i < N[0]; i++) {
                const double y[3] = {mn[0] + (i + 0.5) * l0, mn[1] + (j + 0.5) * l0,
                                     dim == 3 ? mn[2] + (k + 0.5) * l0 : 0};
                bool in_hole = hole_mn != NULL;
                for (int a = 0; in_hole && a < dim; a++)
                    in_hole = y[a] > hole_mn[a] && y[a] < hole_mx[a];
                if (in_hole)
                    continue;
                const double r = sqrt((y[0] - x[0]) * (y[0] - x[0]) + (y[1] - x[1]) * (y[1] - x[1]) +
                                      (y[2] - x[2]) * (y[2] - x[2]));
                if (r > 0)
                    n += mf_weight(r, RE_ND * l0);
            }
    return n;
}

static void test_solids(void)
{
    const double l0 = 0.01;
    double n0, nf, gf[3], far[1] = {100};
    /* 2-D: a closed tank [0, 0.2]^2; particles at its corner and beside a wall. */
    mf_wall_tables *t2 = NULL, *t3 = NULL;
    CHECK(mf_wall_tables_create(2, l0, RE_ND * l0, RE_GRAD * l0, RE_LAP * l0, &t2) == 0);
    CHECK(mf_wall_tables_create(3, l0, RE_ND * l0, RE_GRAD * l0, RE_LAP * l0, &t3) == 0);
    if (!t2 || !t3)
        return;
    lattice_sums(2, 0, far, l0, &nf, gf, &n0);
    mf_wall tank;
    memset(&tank, 0, sizeof tank);
    tank.shape = MF_SOLID_TANK;
    tank.dim = 2;
    tank.max[0] = tank.max[1] = 0.2;
    tank.open[2][0] = tank.open[2][1] = true;
    mf_motion_state(&tank.motion, 0, &tank.state);
    const double mn[3] = {0, 0, 0}, mx[3] = {0.2, 0.2, 0};
    const double xs[3][3] = {{0.005, 0.005, 0}, {0.015, 0.025, 0}, {0.105, 0.005, 0}};
    double worst = 0;
    for (int k = 0; k < 3; k++) {
        mf_wall_sums s;
        CHECK(mf_wall_sums_of(&tank, t2, 2, l0, xs[k], &s));
        const double n = block_density(2, mn, mx, xs[k], l0, NULL, NULL);
        worst = fmax(worst, fabs(n + s.zn - n0) / n0);
    }
    printf("2-D tank, corner and face: |n_fluid + zn - n0| / n0 <= %.2e\n", worst);
    CHECK_MSG(worst < 1e-12, "2-D tank: %g", worst);
    /* 3-D: a box obstacle [0.1, 0.14]^3 in a block; particles beside a
     * face, along an edge, at a corner (outside the box). */
    lattice_sums(3, 0, far, l0, &nf, gf, &n0);
    mf_wall box;
    memset(&box, 0, sizeof box);
    box.shape = MF_SOLID_BOX;
    box.dim = 3;
    box.obstacle = true;
    for (int a = 0; a < 3; a++) {
        box.min[a] = 0.1;
        box.max[a] = 0.14;
    }
    mf_motion_state(&box.motion, 0, &box.state);
    const double bmn[3] = {0.05, 0.05, 0.05}, bmx[3] = {0.19, 0.19, 0.19};
    const double ys[3][3] = {{0.095, 0.125, 0.115}, {0.095, 0.095, 0.125}, {0.095, 0.095, 0.095}};
    worst = 0;
    for (int k = 0; k < 3; k++) {
        mf_wall_sums s;
        CHECK(mf_wall_sums_of(&box, t3, 3, l0, ys[k], &s));
        const double n = block_density(3, bmn, bmx, ys[k], l0, box.min, box.max);
        worst = fmax(worst, fabs(n + s.zn - n0) / n0);
    }
    printf("3-D box obstacle, face, edge and corner: |n_fluid + zn - n0| / n0 <= %.2e\n", worst);
    CHECK_MSG(worst < 1e-12, "3-D box: %g", worst);
    mf_wall_tables_destroy(t2);
    mf_wall_tables_destroy(t3);
}

int main(void)
{
    test_identity(2, 1);
    test_identity(2, 2);
    test_identity(3, 1);
    test_identity(3, 2);
    test_identity(3, 3);
    test_solids();
    test_interpolation(2);
    test_interpolation(3);
    return mf_test_summary("wall_weight");
}
