/* test_control.c: the control forces of issue 18 (solvers/force/control/)
 * act where they say and nowhere else.
 *
 *   attraction      the directedSplash tutorial (at l0 = 0.02 m): the
 *                   fraction of the fluid inside the target box at the end
 *                   is large where the same case without the force leaves
 *                   almost none there;
 *   velocityRegion  a box region in the middle of a still pool prescribes
 *                   (0.2 0 0) m/s: its fluid's mean velocity is within 10% of
 *                   it, where the pool without the force stays at rest. The
 *                   rest of the pool, held back by the walls, pushes back on
 *                   the region through the pressure: the steady deficit is
 *                   that push over the rate (at rate 50 1/s the region moved
 *                   at 0.168 m/s, 16% short); at 500 1/s it is small;
 *   pathFollow      a free blob (no gravity) pulled along a table of two
 *                   points: the region's centroid is on the table's position
 *                   within LAG_TOL while the path moves and within 0.5 l0 once
 *                   it has stopped;
 *   bit for bit     removing the control forces from directedSplash gives
 *                   the scene's plain run, and the three forces with their
 *                   regions above the tank (where no fluid goes) give it too:
 *                   every snapshot's positions and velocities identical, so
 *                   a force that is in the case but acts nowhere changes
 *                   nothing (no field, no pass, no change of the solver's
 *                   neighbour lists or their order).
 *
 *   shapes          (no run) a closed OBJ box, read through core/scene's mesh
 *                   import and sampled on the lattice, holds the same lattice
 *                   points as the box shape; a sphere's level-set offset grows
 *                   it by the offset; a point is sampled by one control
 *                   particle at its centre.
 *
 * argv[1]: mpsflow; argv[2]: tutorials/directedSplash. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_util.h"
#include "force/control/control_shape.h"
#include "mf_mesh_import.h"
#include "mf_test.h"

#define L0 0.02
/* pathFollow: rate 100 1/s, gain 20 1/s; the path moves at 0.4 m/s. The
 * fluid's velocity follows the path's within 1/rate = 0.01 s, so the centroid
 * lags by about |V| / rate = 4 mm while it moves (measured: 1.8 mm). */
#define LAG_TOL (0.5 * L0)

/* The text without the lines from the one holding "control begin" to the one
 * holding "control end" (what the tutorial's Allrun does with sed). */
static char *without_control(const char *text)
{
    char *out = malloc(strlen(text) + 1), *o = out;
    bool skip = false;
    for (const char *s = text; out && *s;) {
        const char *e = strchr(s, '\n');
        size_t len = e ? (size_t)(e - s + 1) : strlen(s);
        char line[1024];
        snprintf(line, sizeof line, "%.*s", (int)(len < sizeof line ? len : sizeof line - 1), s);
        if (strstr(line, "control begin"))
            skip = true;
        if (!skip) {
            memcpy(o, s, len);
            o += len;
        }
        if (strstr(line, "control end"))
            skip = false;
        s += len;
    }
    if (out)
        *o = '\0';
    return out;
}

/* The solver dictionary text with its forces block (the last part of the
 * file, as the tutorial writes it) replaced by `forces` (malloc'ed). */
/* The fluid particles' fraction inside the box [lo, hi] (2-D). */
static double fraction_in_box(const mf_particles *p, const double lo[2], const double hi[2])
{
    size_t in = 0, n = 0;
    for (size_t i = 0; i < p->n; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        n++;
        const double *x = &p->pos[3 * i];
        in += x[0] > lo[0] && x[0] < hi[0] && x[1] > lo[1] && x[1] < hi[1];
    }
    return n ? (double)in / (double)n : 0;
}

static double last_fraction(const tc_case *c, const double lo[2], const double hi[2])
{
    tc_snapshots s;
    if (tc_snapshots_list(c->dir, &s) != 0 || s.n == 0)
        return NAN;
    mf_sim sim;
    double f = NAN;
    if (tc_snapshot_load(c->dir, s.index[s.n - 1], &sim, NULL) == 0) {
        f = fraction_in_box(sim.p, lo, hi);
        tc_sim_free(&sim);
    }
    tc_snapshots_free(&s);
    return f;
}

static bool run_case(tc_case *c, const char *what)
{
    const char *args[] = {"-l0", "0.02", NULL};
    int status = tc_case_run(c, NULL, args);
    CHECK_MSG(status == 0, "%s: mpsflow exited with %d", what, status);
    if (status != 0)
        tc_case_log_tail(c, 20);
    return status == 0;
}

/* Every snapshot of a and b: the same count, positions and velocities bit
 * for bit. */
static void check_identical(const tc_case *a, const tc_case *b, const char *what)
{
    tc_snapshots sa, sb;
    CHECK_OK(tc_snapshots_list(a->dir, &sa));
    CHECK_OK(tc_snapshots_list(b->dir, &sb));
    CHECK_MSG(sa.n == sb.n && sa.n > 10, "%s: %zu and %zu snapshots", what, sa.n, sb.n);
    size_t differ = 0, compared = 0;
    for (size_t k = 0; k < sa.n && k < sb.n; k++) {
        mf_sim x, y;
        CHECK_OK(tc_snapshot_load(a->dir, sa.index[k], &x, NULL));
        CHECK_OK(tc_snapshot_load(b->dir, sb.index[k], &y, NULL));
        if (x.p->n != y.p->n || x.time != y.time ||
            memcmp(x.p->pos, y.p->pos, 3 * x.p->n * sizeof(double)) != 0 ||
            memcmp(x.p->vel, y.p->vel, 3 * x.p->n * sizeof(double)) != 0)
            differ++;
        compared++;
        tc_sim_free(&x);
        tc_sim_free(&y);
    }
    printf("  %s: %zu snapshots compared, %zu differ\n", what, compared, differ);
    CHECK_MSG(differ == 0, "%s: %zu of %zu snapshots differ", what, differ, compared);
    tc_snapshots_free(&sa);
    tc_snapshots_free(&sb);
}

/* ---- attraction, and bit for bit ------------------------------------------ */

static void check_directed_splash(const char *exe, const char *tutorial)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/system/solverDict", tutorial);
    char *solver = tc_read_text(path);
    CHECK_MSG(solver != NULL, "%s: cannot read", path);
    if (!solver)
        return;
    char *plain = without_control(solver);
    CHECK(plain && strstr(solver, "attraction") && !strstr(plain, "attraction"));
    tc_case ctl, unc, ref, away;
    CHECK_OK(tc_case_from_dir(&ctl, exe, "control-splash", tutorial));
    CHECK_OK(tc_case_from_dir(&unc, exe, "control-uncontrolled", tutorial));
    CHECK_OK(tc_case_write(&unc, TC_SOLVER, plain));
    /* The scene's plain run, written here with only gravity. */
    CHECK_OK(tc_case_from_dir(&ref, exe, "control-plain", tutorial));
    char *ref_solver = tc_with_forces(plain, "forces { gravity { g (0 -9.81 0); } }\n");
    CHECK_OK(tc_case_write(&ref, TC_SOLVER, ref_solver));
    /* The three forces with their regions above the tank (it is 0.6 m high). */
    CHECK_OK(tc_case_from_dir(&away, exe, "control-away", tutorial));
    char *away_solver = tc_with_forces(plain,
                 "forces {\n gravity { g (0 -9.81 0); }\n"
                 " steer { type attraction; shape box; min (0.7 1.5 0); max (1.0 1.7 0);"
                 " attraction 150; influenceRadius 10; }\n"
                 " push { type velocityRegion; shape sphere; centre (0.5 2 0); radius 0.2;"
                 " velocity (1 0 0); }\n"
                 " drag { type pathFollow; shape box; min (0 1.2 0); max (0.3 1.4 0);"
                 " path { table ((0 (0.15 1.3 0)) (1 (0.8 1.3 0))); } }\n}\n");
    CHECK_OK(tc_case_write(&away, TC_SOLVER, away_solver));
    free(solver);
    free(plain);
    free(ref_solver);
    free(away_solver);
    const bool ran[4] = {run_case(&ctl, "directedSplash"),
                         run_case(&unc, "directedSplash uncontrolled"),
                         run_case(&ref, "the plain scene"),
                         run_case(&away, "control forces away")};
    if (ran[0] && ran[1] && ran[2] && ran[3]) {
        const double lo[2] = {0.75, 0.25}, hi[2] = {1.0, 0.45};
        const double fc = last_fraction(&ctl, lo, hi), fu = last_fraction(&unc, lo, hi);
        printf("attraction: fluid inside the target at the end: %.4f controlled, %.4f "
               "uncontrolled\n", fc, fu);
        CHECK_MSG(fc > 0.15, "attraction: only %g of the fluid in the target", fc);
        CHECK_MSG(fu < 0.05 && fc > 5 * fu, "uncontrolled: %g of the fluid in the target (the scene should "
                  "leave it almost empty)", fu);
        printf("bit for bit:\n");
        check_identical(&unc, &ref, "directedSplash without its control force = the plain scene");
        check_identical(&away, &ref, "three control forces acting nowhere = the plain scene");
    }
    tc_case_destroy(&ctl);
    tc_case_destroy(&unc);
    tc_case_destroy(&ref);
    tc_case_destroy(&away);
}

/* ---- velocityRegion ----------------------------------------------------------- */

static const char *const pool_geometry =
    "dimension 2;\nparticleSpacing 0.02;\n"
    "fluidBlocks { pool { type box; min (0 0 0); max (1.0 0.3 0); fluid water; } }\n"
    "walls { tank { type box; min (0 0 0); max (1.0 0.5 0); open (ymax); } }\n";
static const char *const fluids = "water { rho 1000; nu 1e-6; }\n";
static const char *const scheme =
    "solver MPS;\nMPSCoeffs { relaxation 0.2; collision yes; }\n"
    "pressure { solver PCG_BoomerAMG; tolerance 1e-8; }\n";

/* Mean velocity of the fluid inside [lo, hi] at the last snapshot. */
static void region_velocity(const tc_case *c, const double lo[2], const double hi[2],
                            double u[2], size_t *n)
{
    tc_snapshots s;
    *n = 0;
    u[0] = u[1] = 0;
    if (tc_snapshots_list(c->dir, &s) != 0 || s.n == 0)
        return;
    mf_sim sim;
    if (tc_snapshot_load(c->dir, s.index[s.n - 1], &sim, NULL) == 0) {
        for (size_t i = 0; i < sim.p->n; i++) {
            const double *x = &sim.p->pos[3 * i];
            if (sim.p->kind[i] != MF_FLUID || !(x[0] > lo[0] && x[0] < hi[0] && x[1] > lo[1] &&
                                                 x[1] < hi[1]))
                continue;
            u[0] += sim.p->vel[3 * i];
            u[1] += sim.p->vel[3 * i + 1];
            (*n)++;
        }
        tc_sim_free(&sim);
    }
    if (*n) {
        u[0] /= (double)*n;
        u[1] /= (double)*n;
    }
    tc_snapshots_free(&s);
}

static void check_velocity_region(const char *exe)
{
    static const char *const control =
        "endTime 0.5;\ndeltaT 1e-4;\nadjustTimeStep yes;\nmaxCo 0.2;\nmaxDeltaT 1e-3;\n"
        "writeControl adjustableRunTime;\nwriteInterval 0.05;\n";
    char with[2048], without[2048];
    snprintf(without, sizeof without, "%sforces { gravity { g (0 -9.81 0); } }\n", scheme);
    snprintf(with, sizeof with,
             "%sforces { gravity { g (0 -9.81 0); }\n"
             " push { type velocityRegion; shape box; min (0.4 0.08 0); max (0.6 0.22 0);"
             " velocity (0.2 0 0); rate 500; } }\n", scheme);
    tc_case a, b;
    CHECK_OK(tc_case_from_strings(&a, exe, "control-vregion", control, with, fluids,
                                  pool_geometry));
    CHECK_OK(tc_case_from_strings(&b, exe, "control-vregion-free", control, without, fluids,
                                  pool_geometry));
    const bool ran_a = run_case(&a, "velocityRegion"), ran_b = run_case(&b, "pool");
    if (ran_a && ran_b) {
        const double lo[2] = {0.4, 0.08}, hi[2] = {0.6, 0.22};
        double ua[2], ub[2];
        size_t na, nb;
        region_velocity(&a, lo, hi, ua, &na);
        region_velocity(&b, lo, hi, ub, &nb);
        printf("velocityRegion: the region's %zu fluid particles at (%.4f %.4f) m/s, "
               "prescribed (0.2 0); without the force (%.4f %.4f)\n", na, ua[0], ua[1], ub[0],
               ub[1]);
        CHECK(na > 20);
        CHECK_MSG(fabs(ua[0] - 0.2) < 0.02 && fabs(ua[1]) < 0.02,
                  "velocityRegion: (%g %g) m/s is not within 10%% of (0.2 0)", ua[0], ua[1]);
        CHECK_MSG(fabs(ub[0]) < 0.02, "the pool without the force moves at %g m/s", ub[0]);
    }
    tc_case_destroy(&a);
    tc_case_destroy(&b);
}

/* ---- pathFollow --------------------------------------------------------------- */

static void check_path(const char *exe)
{
    static const char *const control =
        "endTime 1.0;\ndeltaT 1e-4;\nadjustTimeStep yes;\nmaxCo 0.2;\nmaxDeltaT 1e-3;\n"
        "writeControl adjustableRunTime;\nwriteInterval 0.05;\n";
    static const char *const geometry =
        "dimension 2;\nparticleSpacing 0.02;\n"
        "fluidBlocks { blob { type sphere; centre (0.2 0.2 0); radius 0.06; fluid water; } }\n"
        "walls { tank { type box; min (0 0 0); max (0.8 0.6 0); } }\n";
    char solver[2048];
    snprintf(solver, sizeof solver,
             "%sforces { drag { type pathFollow; shape sphere; centre (0.2 0.2 0);"
             " radius 0.1; rate 100; gain 20;"
             " path { table ((0.1 (0.2 0.2 0)) (0.6 (0.36 0.32 0))); } } }\n", scheme);
    tc_case c;
    CHECK_OK(tc_case_from_strings(&c, exe, "control-path", control, solver, fluids, geometry));
    if (run_case(&c, "pathFollow")) {
        tc_snapshots s;
        CHECK_OK(tc_snapshots_list(c.dir, &s));
        double worst_moving = 0, worst_held = 0;
        for (size_t k = 0; k < s.n; k++) {
            mf_sim sim;
            mf_hdf5_header h;
            if (tc_snapshot_load(c.dir, s.index[k], &sim, &h) != 0)
                continue;
            const double t = h.time;
            const double f = t < 0.1 ? 0 : t > 0.6 ? 1 : (t - 0.1) / 0.5;
            const double P[2] = {0.2 + 0.16 * f, 0.2 + 0.12 * f};
            double X[2] = {0, 0};
            size_t n = 0;
            for (size_t i = 0; i < sim.p->n; i++) {
                const double *x = &sim.p->pos[3 * i];
                const double shift[2] = {x[0] - P[0], x[1] - P[1]};
                if (sim.p->kind[i] != MF_FLUID ||
                    shift[0] * shift[0] + shift[1] * shift[1] >= 0.1 * 0.1)
                    continue;
                X[0] += x[0];
                X[1] += x[1];
                n++;
            }
            if (n) {
                const double e = hypot(X[0] / n - P[0], X[1] / n - P[1]);
                if (t <= 0.7)
                    worst_moving = fmax(worst_moving, e);
                else
                    worst_held = fmax(worst_held, e);
            }
            CHECK_MSG(n > 20, "pathFollow: t = %g: only %zu particles in the region", t, n);
            tc_sim_free(&sim);
        }
        tc_snapshots_free(&s);
        printf("pathFollow: the region's centroid off the table's position by at most %.4f m "
               "while it moves (tolerance %.3g), %.4f m after it stopped (tolerance %.3g)\n",
               worst_moving, LAG_TOL, worst_held, 0.5 * L0);
        CHECK(worst_moving < LAG_TOL);
        CHECK(worst_held < 0.5 * L0);
    }
    tc_case_destroy(&c);
}

/* ---- the shapes ---------------------------------------------------------------- */

/* A closed box [lo, hi] as an OBJ file, its faces wound outward. */
static void write_obj_box(const char *path, const double lo[3], const double hi[3])
{
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    for (int k = 0; k < 8; k++)
        fprintf(f, "v %g %g %g\n", k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1],
                k & 4 ? hi[2] : lo[2]);
    static const int quads[6][4] = {{1, 3, 4, 2}, {5, 6, 8, 7}, {1, 2, 6, 5},
                                    {3, 7, 8, 4}, {1, 5, 7, 3}, {2, 4, 8, 6}};
    for (int q = 0; q < 6; q++)
        fprintf(f, "f %d %d %d\nf %d %d %d\n", quads[q][0], quads[q][1], quads[q][2],
                quads[q][0], quads[q][2], quads[q][3]);
    fclose(f);
}

static void check_shapes(const char *exe)
{
    tc_case c;
    CHECK_OK(tc_case_create(&c, exe, "control-shapes"));
    char obj[700], geometry[700];
    snprintf(obj, sizeof obj, "%s/constant/target.obj", c.dir);
    snprintf(geometry, sizeof geometry, "%s/constant/geometry", c.dir);
    const double lo[3] = {0.3, 0.2, -0.1}, hi[3] = {0.6, 0.5, 0.1};
    write_obj_box(obj, lo, hi);
    const mf_trimesh_reader reader = mf_mesh_import_reader();
    mf_log log;
    mf_log_init(&log, stdout, MF_LOG_QUIET);
    mf_sim sim = {.dim = 2, .l0 = 0.01, .log = &log, .mesh_reader = &reader,
                  .mesh_relative_to = geometry};
    control_shape_settings s = {.shape = "mesh", .file = "target.obj", .scale = 1,
                                .radius = 0.1, .offset = 0};
    control_shape mesh, box, sphere, grown, point;
    CHECK_OK(control_shape_create(&s, "test", &sim, &mesh));
    s.shape = "box";
    memcpy(s.min, lo, sizeof lo);
    memcpy(s.max, hi, sizeof hi);
    CHECK_OK(control_shape_create(&s, "test", &sim, &box));
    s.shape = "sphere";
    s.centre[0] = 0.45;
    s.centre[1] = 0.35;
    s.centre[2] = 0;
    CHECK_OK(control_shape_create(&s, "test", &sim, &sphere));
    s.offset = 0.05;
    CHECK_OK(control_shape_create(&s, "test", &sim, &grown));
    s.shape = "point";
    s.offset = 0;
    CHECK_OK(control_shape_create(&s, "test", &sim, &point));
    size_t agree = 0, inside = 0, total = 0, sphere_bad = 0;
    for (int j = 0; j < 70; j++)
        for (int i = 0; i < 90; i++) {
            const double x[3] = {(i + 0.5) * 0.01, (j + 0.5) * 0.01, 0};
            const bool m = control_shape_contains(&mesh, x, NULL);
            agree += m == control_shape_contains(&box, x, NULL);
            inside += m;
            total++;
            const double r = hypot(x[0] - 0.45, x[1] - 0.35);
            sphere_bad += control_shape_contains(&sphere, x, NULL) != (r < 0.1);
            sphere_bad += control_shape_contains(&grown, x, NULL) != (r < 0.15);
        }
    printf("shapes: the OBJ box holds %zu lattice points, the same as the box shape at %zu of "
           "%zu; sphere and grown sphere wrong at %zu\n", inside, agree, total, sphere_bad);
    CHECK(inside == 30 * 30);
    CHECK(agree == total);
    CHECK(sphere_bad == 0);
    double xyz[6];
    CHECK(control_shape_lattice(&point, 0.02, xyz, 2) == 1 && xyz[0] == 0.45 && xyz[1] == 0.35);
    CHECK(control_shape_lattice(&box, 0.02, NULL, 0) == 15 * 15);
    CHECK(control_shape_lattice(&mesh, 0.02, NULL, 0) == 15 * 15);
    /* A mesh with an offset is refused, saying why. */
    s.shape = "mesh";
    s.offset = 0.01;
    control_shape bad;
    CHECK(control_shape_create(&s, "test", &sim, &bad) == MF_ERR_INPUT);
    CHECK(strstr(mf_error_message(), "offset") != NULL);
    control_shape_free(&bad);
    control_shape_free(&mesh);
    control_shape_free(&box);
    control_shape_free(&sphere);
    control_shape_free(&grown);
    control_shape_free(&point);
    tc_case_destroy(&c);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_control MPSFLOW TUTORIAL_DIRECTEDSPLASH\n");
        return 2;
    }
    check_shapes(argv[1]);
    check_velocity_region(argv[1]);
    check_path(argv[1]);
    check_directed_splash(argv[1], argv[2]);
    return mf_test_summary("control");
}
