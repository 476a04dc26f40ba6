/* test_scenes.c: the paper's two scenes (tutorials/corridorFlood and
 * tutorials/boxFilling) at their preview spacing, for a short time.
 *
 * corridorFlood, 1.5 s at l0 = 0.07 m: the fluid the nozzle has added is
 *   its rate times the time (whole layers, so within one layer); no fluid
 *   particle is more than l0/2 outside the closed corridor (winding number
 *   and distance to corridor.obj); the flood has run down the first arm
 *   (its front past x = 2 m).
 * boxFilling, 1 s at l0 = 0.04 m: every fluid particle is inside the open
 *   box (within l0/2); none of it more than l0 inside the plate's slab
 *   (its faces are lattice staircases: a particle may rest in a step); water
 *   has landed on the plate (particles just above it) and reached the
 *   floor; surface tension and drag are in the run.
 * Each runs single-threaded in under ~30 s.
 * argv: mpsflow, tutorials/corridorFlood, tutorials/boxFilling. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_util.h"
#include "mf_error.h"
#include "mf_mesh_import.h"
#include "mf_test.h"
#include "mf_trimesh.h"
#include "trimesh_internal.h"

/* Distance from x to the mesh (nearest triangle). */
static double mesh_distance(const mf_trimesh *m, const double x[3])
{
    double best = INFINITY;
    for (size_t t = 0; t < m->ntris; t++) {
        double q[3];
        mf_closest_on_triangle(x, &m->xyz[3 * m->tri[3 * t]], &m->xyz[3 * m->tri[3 * t + 1]],
                               &m->xyz[3 * m->tri[3 * t + 2]], q);
        double d2 = 0;
        for (int a = 0; a < 3; a++)
            d2 += (x[a] - q[a]) * (x[a] - q[a]);
        best = fmin(best, d2);
    }
    return sqrt(best);
}

static int load_last(tc_case *c, mf_sim *sim, mf_hdf5_header *h)
{
    tc_snapshots s;
    if (tc_snapshots_list(c->dir, &s) != 0 || s.n == 0)
        return -1;
    int rc = tc_snapshot_load(c->dir, s.index[s.n - 1], sim, h);
    tc_snapshots_free(&s);
    return rc;
}

static void test_corridor(const char *exe, const char *tutorial)
{
    tc_case c;
    if (tc_case_from_dir(&c, exe, "corridor", tutorial) != 0) {
        CHECK(0);
        return;
    }
    const double l0 = 0.07, end = 1.5;
    int status = tc_case_run(&c, NULL, (const char *[]){"-l0", "0.07", "-endTime", "1.5", NULL});
    CHECK_MSG(status == 0, "corridorFlood preview failed (%d)", status);
    if (status != 0)
        tc_case_log_tail(&c, 20);
    printf("corridorFlood to %g s at l0 = %g m: %.1f s\n", end, l0, c.last_wall);
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    mf_hdf5_header h;
    char obj[1200];
    snprintf(obj, sizeof obj, "%s/constant/triSurface/corridor.obj", c.dir);
    mf_trimesh m;
    mf_trimesh_init(&m);
    if (status == 0 && load_last(&c, &sim, &h) == 0 && mf_mesh_import(obj, &m) == 0) {
        CHECK_NEAR(h.time, end, 1e-9);
        size_t nfluid = tc_count_kind(sim.p, MF_FLUID), outside = 0;
        double worst = 0, front = 0;
        for (size_t i = 0; i < sim.p->n; i++) {
            if (sim.p->kind[i] != MF_FLUID)
                continue;
            const double *x = &sim.p->pos[3 * i];
            front = fmax(front, x[0]);
            if (mf_trimesh_winding(&m, x) < 0.5) {
                double d = mesh_distance(&m, x);
                worst = fmax(worst, d);
                outside += d > 0.5 * l0;
            }
        }
        /* The nozzle's rate (0.2 m^3/s) over 1.5 s, in particles of l0^3:
         * whole layers are added, each of about a hundredth of this. */
        double expected = 0.2 * end / (l0 * l0 * l0);
        printf("  %zu fluid particles (rate x time / l0^3 = %.0f); front at x = %.2f m; "
               "deepest outside the corridor %.3g m (%zu beyond l0/2)\n",
               nfluid, expected, front, worst, outside);
        CHECK(fabs(nfluid - expected) < 0.03 * expected);
        CHECK(outside == 0);
        CHECK(front > 2.0);
    } else {
        CHECK_MSG(0, "could not read the run's snapshot or corridor.obj");
        mf_error_print(stderr);
    }
    mf_trimesh_free(&m);
    tc_sim_free(&sim);
    tc_case_destroy(&c);
}

static void test_box(const char *exe, const char *tutorial)
{
    tc_case c;
    if (tc_case_from_dir(&c, exe, "box", tutorial) != 0) {
        CHECK(0);
        return;
    }
    const double l0 = 0.04, end = 1.0, L = 0.8;
    int status = tc_case_run(&c, NULL, (const char *[]){"-l0", "0.04", "-endTime", "1", NULL});
    CHECK_MSG(status == 0, "boxFilling preview failed (%d)", status);
    if (status != 0)
        tc_case_log_tail(&c, 20);
    printf("boxFilling to %g s at l0 = %g m: %.1f s\n", end, l0, c.last_wall);
    CHECK(tc_case_log_contains(&c, "surfaceTension"));
    CHECK(tc_case_log_contains(&c, "drag"));
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    mf_hdf5_header h;
    char obj[1200];
    snprintf(obj, sizeof obj, "%s/constant/triSurface/plate.obj", c.dir);
    mf_trimesh plate;
    mf_trimesh_init(&plate);
    if (status == 0 && load_last(&c, &sim, &h) == 0 && mf_mesh_import(obj, &plate) == 0) {
        CHECK_NEAR(h.time, end, 1e-9);
        size_t nfluid = 0, out_of_box = 0, in_plate = 0, on_plate = 0, on_floor = 0;
        const double half = 0.06; /* the plate's thickness / 2 (constant/geometry) */
        for (size_t i = 0; i < sim.p->n; i++) {
            if (sim.p->kind[i] != MF_FLUID)
                continue;
            nfluid++;
            const double *x = &sim.p->pos[3 * i];
            bool in = true;
            for (int a = 0; a < 3; a++)
                in = in && x[a] > -0.5 * l0 && (a == 1 || x[a] < L + 0.5 * l0);
            out_of_box += !in;
            double d = mesh_distance(&plate, x);
            /* The plate's faces are lattice staircases: the outermost wall
             * particle of a lattice line lies up to |n_y| l0 = 0.87 l0
             * under the nominal face, and a particle resting beside it sits
             * up to 0.65 l0 inside the face (measured). One more than l0
             * inside has passed the outer wall layer. */
            in_plate += d < half - l0;
            on_plate += d < half + 1.5 * l0 && x[1] > 0.45;
            on_floor += x[1] < 1.5 * l0;
        }
        printf("  %zu fluid particles: %zu on the plate, %zu on the floor; %zu out of the box, "
               "%zu inside the plate\n",
               nfluid, on_plate, on_floor, out_of_box, in_plate);
        CHECK(out_of_box == 0);
        CHECK(in_plate == 0);
        CHECK(on_plate > 20);
        CHECK(on_floor > 20);
    } else {
        CHECK_MSG(0, "could not read the run's snapshot or plate.obj");
        mf_error_print(stderr);
    }
    mf_trimesh_free(&plate);
    tc_sim_free(&sim);
    tc_case_destroy(&c);
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: %s mpsflow tutorials/corridorFlood tutorials/boxFilling\n",
                argv[0]);
        return 2;
    }
    test_corridor(argv[1], argv[2]);
    test_box(argv[1], argv[3]);
    return mf_test_summary("scenes");
}
