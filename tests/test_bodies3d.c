/* test_bodies3d.c: the rigid bodies of issue 18 in 3-D and the contacts'
 * friction (core/scene/rigid_bodies.c, body_contact.c; docs/topics/
 * rigid-bodies.md section 8).
 *
 *   cylinder float  a 3-D cylinder (radius R = 0.05 m, length 0.12 m, axis
 *              z, horizontal, density 500) released with its lowest line on
 *              water 0.16 m deep at l0 = 0.02 m (5 particles across; the
 *              default scheme, whose pressure force is the fluid's pressure
 *              over the round side, 2 pi R L, and the caps, pi R^2 each,
 *              shared among their outer wall particles): it falls in, heaves
 *              and floats half submerged, its axis at the water's level h.
 *              h from the fluid's volume V_f (its particles times l0^3) and
 *              the submerged section S(h - y_c) over the tank's floor A:
 *              h = (V_f + L S) / A, S(s) = R^2 acos(-s/R) + s sqrt(R^2 - s^2)
 *              (a fixed point; s = 0: half the section). The mean of y_c over
 *              t in (0.5, 1) s (about one heave period, 0.45 s) lies within
 *              0.3 l0 of the mean level: floatingBox's draft errors are 0.24
 *              l0 (l0 = 0.01 m) and 0.30 l0 (0.005 m) (rigid-bodies.md
 *              section 2); no pressure on the side, or twice it, is 0.5 R
 *              off;
 *   cylinder momentum  test_bodies' momentum case in 3-D: a free blob of
 *              water (no gravity) in a closed box around a neutrally buoyant
 *              cylinder body set moving at U; the scheme whose pair forces
 *              are antisymmetric (body_cases.h): the total momentum of the
 *              fluid, the body and the impulse it has not yet taken stays
 *              P(0) to 1e-8 P(0) (bodyState.csv's 9 digits), and the body
 *              exchanged momentum at all (more than 0.01 P(0): a wrong sign
 *              or a lag of the exchange is an error of that order).
 *
 * argv[1]: mpsflow. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "body_cases.h"
#include "case_util.h"
#include "mf_test.h"
#include "mf_trimesh.h"
#include "mf_walls.h"

#define MOMENTUM_TOL 1e-8 /* of P(0): the CSV's 9 significant digits */

static const char *const fluids = "water { rho 1000; nu 1e-6; }\n";
/* test_bodies' momentum fluid: viscous enough to drag the body in 0.2 s */
static const char *const viscous = "water { rho 1000; nu 1e-4; }\n";

static bool run(tc_case *c, const char *what)
{
    int status = tc_case_run(c, NULL, NULL);
    CHECK_MSG(status == 0, "%s: mpsflow exited with %d", what, status);
    if (status != 0)
        tc_case_log_tail(c, 20);
    return status == 0;
}

/* Write obj (NULL: none) to constant/body.obj, run the case and read the
 * body's track; false (reported) when either fails. */
static bool run_body(tc_case *c, const char *what, const char *obj, tc_body_track *tr)
{
    if (obj)
        CHECK_OK(tc_case_write(c, "constant/body.obj", obj));
    bool ok = run(c, what);
    if (ok) {
        ok = tc_body_track_read(c->dir, "body", tr) == 0;
        CHECK_MSG(ok, "%s: no bodyState.csv rows", what);
    }
    return ok;
}

/* The section of a circle of radius R below a level s above its centre. */
static double section_below(double R, double s)
{
    s = fmax(-R, fmin(R, s));
    return R * R * acos(-s / R) + s * sqrt(R * R - s * s);
}

/* The section of a rectangle W wide and H high below a level s above its
 * centre. */
static double rectangle_below(double W, double H, double s)
{
    return W * fmax(0, fmin(H, s + 0.5 * H));
}

/* A body of density 500 (its entry `obstacle`, named body; obj: a polygon
 * file constant/body.obj, NULL: none) released above water 0.16 m deep in
 * a tank 0.3 x 0.2 m, l0 = 0.02 m: the mean of its centre's y over t in
 * (0.5, 1) s against the mean level h = (V_f + L S(h - y_c)) / A, S the
 * section (S_cyl: circle of radius R; else a rectangle W x H), L its
 * length along z; mass its mass from its shape. */
static void check_float(const char *exe, const char *what, const char *obstacle,
                        const char *obj, double mass, double R, double W, double H, double L)
{
    const double l0 = 0.02, A = 0.3 * 0.2;
    static const char *const ctl =
        "endTime 1.0;\ndeltaT 1e-4;\nadjustTimeStep yes;\nmaxCo 0.2;\nmaxDeltaT 1e-3;\n"
        "writeControl adjustableRunTime;\nwriteInterval 0.5;\n";
    static const char *const slv = "solver MPS;\n"
                                   "pressure { solver PCG_BoomerAMG; tolerance 1e-8; }\n"
                                   "forces { gravity { g (0 -9.81 0); } }\n";
    char geo[2048];
    snprintf(geo, sizeof geo,
             "dimension 3;\nparticleSpacing 0.02;\n"
             "fluidBlocks { water { type box; min (0 0 0); max (0.3 0.16 0.2); fluid water; } }\n"
             "walls { tank { type box; min (0 0 0); max (0.3 0.35 0.2); open (ymax); } }\n"
             "obstacles { body { %s\n"
             " motion { type rigid; density 500; g (0 -9.81 0); } } }\n", obstacle);
    tc_case c;
    CHECK_OK(tc_case_from_strings(&c, exe, "bodies3d-float", ctl, slv, fluids, geo));
    tc_body_track tr = {0};
    bool ok = run_body(&c, what, obj, &tr);
    tc_snapshots s = {0};
    if (ok) {
        CHECK_OK(tc_snapshots_list(c.dir, &s));
        ok = s.n > 0;
    }
    mf_sim sim;
    mf_hdf5_header h;
    if (ok && tc_snapshot_load(c.dir, s.index[s.n - 1], &sim, &h) == 0) {
        const double Vf = (double)tc_count_kind(sim.p, MF_FLUID) * l0 * l0 * l0;
        tc_sim_free(&sim);
        /* the time means of the centre and of the level over t in (0.5, 1) */
        double yc = 0, level = 0, span = 0;
        for (size_t k = 1; k < tr.n; k++) {
            if (tr.t[k] <= 0.5)
                continue;
            const double dt = tr.t[k] - tr.t[k - 1], y = tr.x[3 * k + 1];
            double hk = Vf / A;
            for (int it = 0; it < 50; it++)
                hk = (Vf + L * (R > 0 ? section_below(R, hk - y) : rectangle_below(W, H, hk - y))) / A;
            yc += y * dt;
            level += hk * dt;
            span += dt;
        }
        yc /= span;
        level /= span;
        printf("%s: mass %.6g kg, %.0f fluid particles' volume %.6g m^3: mean centre "
               "y = %.5f m, mean level %.5f m over t in (0.5, %.3g) s: %.3g l0 off (tolerance "
               "0.3 l0)\n", what, tr.mass, Vf / (l0 * l0 * l0), Vf, yc, level, tr.t[tr.n - 1],
               (yc - level) / l0);
        CHECK_MSG(fabs(tr.mass / mass - 1) < 1e-8, "%s: mass %.9g, its shape's %.9g", what,
                  tr.mass, mass); /* 9 digits */
        CHECK(fabs(tr.t[tr.n - 1] - 1.0) < 1e-9);
        CHECK(fabs(yc - level) < 0.3 * l0);
    } else {
        CHECK_MSG(false, "%s: no snapshot to read", what);
    }
    tc_snapshots_free(&s);
    if (tr.n > 0)
        tc_body_track_free(&tr);
    tc_case_destroy(&c);
}

/* A blob 0.2 m across (x, y, z in 0.1..0.3) around a hole lo..hi holding
 * the body `obstacle` (its entry in obstacles, named body, moving at U
 * along x), in a closed tank 0.4 m across; obj: a polygon file written to
 * constant/body.obj (NULL: none); mass: the body's, from its shape. */
static void check_momentum(const char *exe, const char *what, const double lo[3],
                           const double hi[3], const char *obstacle, const char *obj,
                           double mass)
{
    const double l0 = 0.02, U = 0.05;
    static const char *const ctl =
        "endTime 0.2;\ndeltaT 1e-4;\nadjustTimeStep yes;\nmaxCo 0.2;\nmaxDeltaT 1e-3;\n"
        "writeControl adjustableRunTime;\nwriteInterval 0.02;\n";
    char geo[4096];
    snprintf(geo, sizeof geo,
             "dimension 3;\nparticleSpacing %g;\n"
             "fluidBlocks {\n"
             " a { type box; min (0.1 0.1 0.1); max (%g 0.3 0.3); fluid water; }\n"
             " b { type box; min (%g 0.1 0.1); max (0.3 0.3 0.3); fluid water; }\n"
             " c { type box; min (%g 0.1 0.1); max (%g %g 0.3); fluid water; }\n"
             " d { type box; min (%g %g 0.1); max (%g 0.3 0.3); fluid water; }\n"
             " e { type box; min (%g %g 0.1); max (%g %g %g); fluid water; }\n"
             " f { type box; min (%g %g %g); max (%g %g 0.3); fluid water; }\n}\n"
             "walls { tank { type box; min (0 0 0); max (0.4 0.4 0.4); } }\n"
             "obstacles { body { %s\n"
             " motion { type rigid; density 1000; g (0 0 0); velocity (%g 0 0); } } }\n",
             l0, lo[0], hi[0], lo[0], hi[0], lo[1], lo[0], hi[1], hi[0], lo[0], lo[1], hi[0],
             hi[1], lo[2], lo[0], lo[1], hi[2], hi[0], hi[1], obstacle, U);
    tc_case c;
    CHECK_OK(tc_case_from_strings(&c, exe, "bodies3d-momentum", ctl, TC_MOMENTUM_SOLVER,
                                  viscous, geo));
    tc_body_track tr = {0};
    bool ok = run_body(&c, what, obj, &tr);
    if (ok) {
        tc_snapshots s;
        CHECK_OK(tc_snapshots_list(c.dir, &s));
        const double P0 = tr.mass * U;
        double worst = 0, impulse = 0;
        size_t row = 0, checked = 0;
        for (size_t k = 0; k < s.n; k++) {
            mf_sim sim;
            mf_hdf5_header h;
            if (tc_snapshot_load(c.dir, s.index[k], &sim, &h) != 0)
                continue;
            double P[3] = {0, 0, 0};
            const double m = 1000 * l0 * l0 * l0;
            for (size_t i = 0; i < sim.p->n; i++)
                if (sim.p->kind[i] == MF_FLUID)
                    for (int a = 0; a < 3; a++)
                        P[a] += m * sim.p->vel[3 * i + a];
            tc_sim_free(&sim);
            while (row + 1 < tr.n && tr.t[row] < h.time * (1 - 1e-12)) {
                row++;
                const double dt = tr.t[row] - tr.t[row - 1];
                impulse += dt * sqrt(tr.f[3 * row] * tr.f[3 * row] +
                                     tr.f[3 * row + 1] * tr.f[3 * row + 1] +
                                     tr.f[3 * row + 2] * tr.f[3 * row + 2]);
            }
            if (fabs(tr.t[row] - h.time) > 1e-9 * fmax(1, h.time))
                continue;
            const double dt = row > 0 ? tr.t[row] - tr.t[row - 1] : 0;
            for (int a = 0; a < 3; a++)
                P[a] += tr.mass * tr.v[3 * row + a] + tr.f[3 * row + a] * dt;
            const double err = sqrt((P[0] - P0) * (P[0] - P0) + P[1] * P[1] + P[2] * P[2]);
            worst = fmax(worst, err);
            CHECK_MSG(err <= MOMENTUM_TOL * P0,
                      "%s: t = %g: |P - P(0)| = %g above %g P(0) (the impulse "
                      "exchanged: %g)", what, h.time, err, MOMENTUM_TOL, impulse);
            checked++;
        }
        tc_snapshots_free(&s);
        const double vl = tr.v[3 * (tr.n - 1)];
        printf("%s: mass %.6g kg, %zu snapshots, worst |P - P(0)| = %.3g P(0) "
               "(tolerance %.2g), the body at %.5f m/s of %g, impulse exchanged %.3g P(0)\n",
               what, tr.mass, checked, worst / P0, MOMENTUM_TOL, vl, U, impulse / P0);
        CHECK_MSG(fabs(tr.mass / mass - 1) < 1e-8, "%s: mass %.9g, its shape's %.9g", what, tr.mass,
                  mass); /* 9 digits */
        CHECK_MSG(checked >= 5, "%s: only %zu snapshots matched", what, checked);
        /* less than test_bodies' 2-D case (0.43 P(0)): the fluid beside the
         * voids the square hole leaves around the round body is free surface
         * (p = 0); still 1e6 times the tolerance */
        CHECK_MSG(vl < 0.99 * U && impulse > 0.01 * P0,
                  "%s: no exchange with the fluid (%g of %g m/s)", what, vl, U);
        tc_body_track_free(&tr);
    }
    tc_case_destroy(&c);
}

/* A cube 0.16..0.24 m, faces half a spacing (0.02 m) off the lattice's
 * planes, outward-wound. */
static const char *const cube_obj =
    "v 0.16 0.16 0.16\nv 0.24 0.16 0.16\nv 0.16 0.24 0.16\nv 0.24 0.24 0.16\n"
    "v 0.16 0.16 0.24\nv 0.24 0.16 0.24\nv 0.16 0.24 0.24\nv 0.24 0.24 0.24\n"
    "f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\n"
    "f 3 7 4\nf 4 7 8\nf 1 5 3\nf 3 5 7\nf 2 4 6\nf 4 8 6\n";

/* A rigid mesh body from a density whose mesh is open (the cube without
 * its last two triangles) or inside out (every triangle turned) is refused
 * at setup, the message naming the entry (file:line), the file and the
 * signed volume. */
static void check_mesh_refused(const char *exe)
{
    char open_obj[1024], inward[1024];
    snprintf(open_obj, sizeof open_obj, "%s", cube_obj);
    *strstr(open_obj, "f 2 4 6") = '\0';
    snprintf(inward, sizeof inward, "%s", cube_obj);
    for (char *f = strstr(inward, "\nf "); f; f = strstr(f + 1, "\nf ")) {
        char *b = strchr(f + 3, ' ') + 1, *c = strchr(b, ' ') + 1; /* swap b and c */
        char tb = *b, tc = *c;
        *b = tc;
        *c = tb;
    }
    static const char *const ctl = "endTime 0.01;\ndeltaT 1e-4;\nwriteInterval 0.01;\n";
    static const char *const geo =
        "dimension 3;\nparticleSpacing 0.02;\n"
        "fluidBlocks { water { type box; min (0 0 0); max (0.1 0.1 0.1); fluid water; } }\n"
        "walls { tank { type box; min (0 0 0); max (0.4 0.4 0.4); } }\n"
        "obstacles { body { type mesh; file \"body.obj\";\n"
        " motion { type rigid; density 500; } } }\n";
    const char *const objs[2] = {open_obj, inward};
    const char *const want[2] = {"not a closed surface", "inside out (signed volume -0.000512"};
    for (int k = 0; k < 2; k++) {
        tc_case c;
        CHECK_OK(tc_case_from_strings(&c, exe, "bodies3d-refused", ctl, TC_MOMENTUM_SOLVER,
                                      fluids, geo));
        CHECK_OK(tc_case_write(&c, "constant/body.obj", objs[k]));
        const int status = tc_case_run(&c, NULL, NULL);
        const bool said = tc_case_log_contains(&c, want[k]) &&
                          tc_case_log_contains(&c, "constant/geometry:5:13: obstacle 'body'") &&
                          tc_case_log_contains(&c, "body.obj");
        printf("mesh refused: %s: exit %d, the message %s\n", k ? "inside out" : "open", status,
               said ? "found" : "missing");
        CHECK(status != 0 && said);
        if (!said)
            tc_case_log_tail(&c, 12);
        tc_case_destroy(&c);
    }
}

/* A box x 0.08..0.2, y 0.18..0.24, z 0.04..0.16, outward-wound. */
static const char *const float_box_obj =
    "v 0.08 0.18 0.04\nv 0.20 0.18 0.04\nv 0.08 0.24 0.04\nv 0.20 0.24 0.04\n"
    "v 0.08 0.18 0.16\nv 0.20 0.18 0.16\nv 0.08 0.24 0.16\nv 0.20 0.24 0.16\n"
    "f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\n"
    "f 3 7 4\nf 4 7 8\nf 1 5 3\nf 3 5 7\nf 2 4 6\nf 4 8 6\n";

/* A box [lo, hi] as 12 outward-wound triangles, each vertex turned by R
 * about c (R NULL: not turned). */
static void box_mesh(mf_trimesh *m, const double lo[3], const double hi[3], const double R[9],
                     const double c[3])
{
    mf_trimesh_init(m);
    for (int k = 0; k < 8; k++) {
        const double x[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        double y[3];
        for (int i = 0; i < 3; i++) {
            y[i] = c[i];
            for (int j = 0; j < 3; j++)
                y[i] += (R ? R[3 * i + j] : i == j) * (x[j] - c[j]);
        }
        CHECK_OK(mf_trimesh_add_vertex(m, y));
    }
    static const int32_t tris[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                        {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                        {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (int t = 0; t < 12; t++)
        CHECK_OK(mf_trimesh_add_triangle(m, tris[t][0], tris[t][1], tris[t][2]));
}

/* mf_trimesh_mass (Eberly 2002) against the exact solids: a box far from
 * the origin, the same box turned (the tensor R D R^T: the off-diagonal
 * terms and their signs), the box wound inward (the volume's sign), and an
 * icosphere, which lies between the balls through its vertices (radius r)
 * and tangent to its faces (r_in): its volume and its moments of inertia
 * V <I_xx> lie between the two balls' (the integral of y^2 + z^2 grows
 * with the region), its centroid at the centre. */
static void check_mesh_mass(void)
{
    const double lo[3] = {10, -5, 3}, e[3] = {0.1, 0.2, 0.3};
    const double hi[3] = {lo[0] + e[0], lo[1] + e[1], lo[2] + e[2]};
    const double c[3] = {lo[0] + 0.05, lo[1] + 0.1, lo[2] + 0.15};
    const double D[3] = {(e[1] * e[1] + e[2] * e[2]) / 12, (e[0] * e[0] + e[2] * e[2]) / 12,
                         (e[0] * e[0] + e[1] * e[1]) / 12};
    double R[9];
    const double axis[3] = {1 / sqrt(3.0), 1 / sqrt(3.0), 1 / sqrt(3.0)};
    mf_rotation_matrix(axis, 0.7, R);
    for (int turned = 0; turned < 2; turned++) {
        mf_trimesh m;
        box_mesh(&m, lo, hi, turned ? R : NULL, c);
        double V, x[3], I[9], worst = 0;
        mf_trimesh_mass(&m, &V, x, I);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double want = 0;
                for (int k = 0; k < 3; k++)
                    want += (turned ? R[3 * i + k] * R[3 * j + k] : (i == k) * (j == k)) * D[k];
                worst = fmax(worst, fabs(I[3 * i + j] - want) / D[0]);
            }
        for (int a = 0; a < 3; a++)
            worst = fmax(worst, fabs(x[a] - c[a]) / e[0]);
        printf("mesh mass: box%s: volume %.15g (exact %.15g), worst relative difference of the "
               "centre and inertia %.3g\n", turned ? " turned" : "", V, e[0] * e[1] * e[2], worst);
        CHECK(fabs(V / (e[0] * e[1] * e[2]) - 1) < 1e-12);
        CHECK(worst < 1e-12);
        if (!turned) { /* wound inward: every triangle turned */
            for (size_t t = 0; t < m.ntris; t++) {
                const int32_t k = m.tri[3 * t + 1];
                m.tri[3 * t + 1] = m.tri[3 * t + 2];
                m.tri[3 * t + 2] = k;
            }
            mf_trimesh_mass(&m, &V, x, I);
            CHECK(fabs(V / (e[0] * e[1] * e[2]) + 1) < 1e-12);
        }
        mf_trimesh_free(&m);
    }
    /* the icosphere: an icosahedron subdivided 3 times, on radius r */
    const double r = 0.05, gr = (1 + sqrt(5.0)) / 2;
    mf_trimesh m;
    mf_trimesh_init(&m);
    const double v12[12][3] = {{-1, gr, 0}, {1, gr, 0}, {-1, -gr, 0}, {1, -gr, 0},
                               {0, -1, gr}, {0, 1, gr}, {0, -1, -gr}, {0, 1, -gr},
                               {gr, 0, -1}, {gr, 0, 1}, {-gr, 0, -1}, {-gr, 0, 1}};
    static const int32_t f20[20][3] = {
        {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    double *tri = malloc(9 * 20 * sizeof *tri);
    size_t nt = 20;
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                tri[9 * t + 3 * k + a] = v12[f20[t][k]][a];
    for (int level = 0; level < 3; level++) { /* each triangle into 4, on the sphere */
        double *next = malloc(4 * 9 * nt * sizeof *next);
        for (size_t t = 0; t < nt; t++) {
            double p[6][3];
            for (int k = 0; k < 3; k++)
                for (int a = 0; a < 3; a++) {
                    p[k][a] = tri[9 * t + 3 * k + a];
                    p[3 + k][a] = 0.5 * (tri[9 * t + 3 * k + a] + tri[9 * t + 3 * ((k + 1) % 3) + a]);
                }
            static const int sub[4][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};
            for (int s4 = 0; s4 < 4; s4++)
                for (int k = 0; k < 3; k++)
                    memcpy(&next[9 * (4 * t + s4) + 3 * k], p[sub[s4][k]], 3 * sizeof(double));
        }
        free(tri);
        tri = next;
        nt *= 4;
    }
    double r_in = r;
    for (size_t t = 0; t < nt; t++) {
        int32_t id[3];
        double q[3][3];
        for (int k = 0; k < 3; k++) {
            const double *y = &tri[9 * t + 3 * k];
            const double len = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
            for (int a = 0; a < 3; a++)
                q[k][a] = r * y[a] / len;
            id[k] = (int32_t)m.nverts;
            CHECK_OK(mf_trimesh_add_vertex(&m, q[k]));
        }
        CHECK_OK(mf_trimesh_add_triangle(&m, id[0], id[1], id[2]));
        const double e1[3] = {q[1][0] - q[0][0], q[1][1] - q[0][1], q[1][2] - q[0][2]};
        const double e2[3] = {q[2][0] - q[0][0], q[2][1] - q[0][1], q[2][2] - q[0][2]};
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        const double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        r_in = fmin(r_in, fabs(n[0] * q[0][0] + n[1] * q[0][1] + n[2] * q[0][2]) / nl);
    }
    free(tri);
    double V, x[3], I[9];
    mf_trimesh_mass(&m, &V, x, I);
    const double ball = 4.0 / 3.0 * M_PI;
    const double V_in = ball * pow(r_in, 3), V_out = ball * pow(r, 3);
    const double I_in = 0.4 * r_in * r_in * V_in, I_out = 0.4 * r * r * V_out;
    printf("mesh mass: icosphere of %zu triangles, r = %g, faces at r_in = %.6g: volume %.6g in "
           "(%.6g, %.6g), V I_xx %.6g, V I_yy %.6g, V I_zz %.6g in (%.6g, %.6g), centre (%.2g "
           "%.2g %.2g), I_xy %.2g\n", m.ntris, r, r_in, V, V_in, V_out, V * I[0], V * I[4],
           V * I[8], I_in, I_out, x[0], x[1], x[2], I[1]);
    CHECK(V > V_in && V < V_out);
    for (int a = 0; a < 3; a++) {
        CHECK(V * I[4 * a] > I_in && V * I[4 * a] < I_out);
        CHECK(fabs(x[a]) < 1e-12 * r);
    }
    CHECK(fabs(I[1]) < 1e-12 * r * r && fabs(I[2]) < 1e-12 * r * r && fabs(I[5]) < 1e-12 * r * r);
    mf_trimesh_free(&m);
}

/* Friction (body_contact.c): a box 0.1 x 0.05 m (2-D, density 500) on the
 * floor of a dry tank set sliding at v = 1 m/s: with friction mu it stops
 * after v^2/(2 mu g) (0.102 m at mu 0.5, in v/(mu g) = 0.20 s), within a
 * spacing; with friction 0 (the default) it slides on at v. */
static void check_friction(const char *exe)
{
    const double l0 = 0.01, v = 1, g = 9.81;
    static const char *const ctl =
        "endTime 0.4;\ndeltaT 1e-4;\nadjustTimeStep yes;\nmaxCo 0.2;\nmaxDeltaT 1e-3;\n"
        "writeControl adjustableRunTime;\nwriteInterval 0.1;\n";
    static const char *const slv = "solver MPS;\n"
                                   "pressure { solver PCG_BoomerAMG; tolerance 1e-8; }\n"
                                   "forces { gravity { g (0 -9.81 0); } }\n";
    const double mus[2] = {0.5, 0};
    for (int k = 0; k < 2; k++) {
        char geo[2048];
        /* a puddle in a corner: a case needs fluid */
        snprintf(geo, sizeof geo,
                 "dimension 2;\nparticleSpacing 0.01;\n"
                 "fluidBlocks { water { type box; min (0 0 0); max (0.05 0.05 0); fluid water; } }\n"
                 "walls { tank { type box; min (0 0 0); max (0.8 0.3 0); open (ymax); } }\n"
                 "obstacles { body { type box; min (0.2 0 0); max (0.3 0.05 0);\n"
                 " motion { type rigid; density 500; velocity (%g 0 0); friction %g; } } }\n",
                 v, mus[k]);
        tc_case c;
        CHECK_OK(tc_case_from_strings(&c, exe, "bodies3d-friction", ctl, slv, fluids, geo));
        tc_body_track tr = {0};
        const bool ok = run_body(&c, "friction", NULL, &tr);
        if (ok) {
            const size_t e = tr.n - 1;
            const double moved = tr.x[3 * e] - tr.x[0], vx = tr.v[3 * e];
            double stop = NAN; /* the first row at rest */
            for (size_t r = 0; r < tr.n && isnan(stop); r++)
                if (fabs(tr.v[3 * r]) < 1e-6)
                    stop = tr.t[r];
            if (mus[k] > 0) {
                const double want = v * v / (2 * mus[k] * g);
                printf("friction %g: moved %.5f m (v^2/(2 mu g) = %.5f m), at rest from t = %.4g "
                       "s (v/(mu g) = %.4g s), vx at t = %g: %.3g m/s\n", mus[k], moved, want,
                       stop, v / (mus[k] * g), tr.t[e], vx);
                CHECK(fabs(moved - want) < l0);
                CHECK(fabs(vx) < 1e-6);
            } else {
                printf("friction 0: moved %.5f m in %g s, vx %.6f m/s\n", moved, tr.t[e], vx);
                CHECK(fabs(vx - v) < 1e-6 && fabs(moved - v * tr.t[e]) < l0);
            }
            CHECK(fabs(tr.t[e] - 0.4) < 1e-9);
        }
        if (tr.n > 0)
            tc_body_track_free(&tr);
        tc_case_destroy(&c);
    }
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_bodies3d MPSFLOW\n");
        return 2;
    }
    const char *only = argc > 2 ? argv[2] : ""; /* a part's name: that part alone */
    if (!*only || strcmp(only, "mass") == 0) {
        check_mesh_mass();
        check_mesh_refused(argv[1]);
    }
    if (!*only || strcmp(only, "momentum") == 0) {
        /* the cylinder: radius 0.03, length 0.04 (caps half a spacing off
         * the lattice's planes, as the mesh's faces) */
        check_momentum(argv[1], "cylinder momentum", (const double[]){0.17, 0.17, 0.18},
                       (const double[]){0.23, 0.23, 0.22},
                       "type cylinder; centre (0.2 0.2 0.2); radius 0.03; axis (0 0 1); "
                       "length 0.04;", NULL, 1000 * M_PI * 0.03 * 0.03 * 0.04);
        /* the file's vertices through assimp's single precision (ai_real) */
        check_momentum(argv[1], "mesh box momentum", (const double[]){0.16, 0.16, 0.16},
                       (const double[]){0.24, 0.24, 0.24}, "type mesh; file \"body.obj\";",
                       cube_obj, 1000 * pow((double)0.24f - (double)0.16f, 3));
    }
    if (!*only || strcmp(only, "friction") == 0)
        check_friction(argv[1]);
    if (!*only || strcmp(only, "float") == 0) {
        /* the cylinder: its caps at z = 0.04 and 0.16, half a spacing off
         * the lattice's planes (a cap on a plane has its particles l0
         * inside it); released with its lowest line 0.005 m above the water */
        const double R = 0.05, L = 0.12;
        check_float(argv[1], "cylinder float",
                    "type cylinder; centre (0.15 0.215 0.1); radius 0.05; axis (0 0 1); "
                    "length 0.12;", NULL, 500 * M_PI * R * R * L, R, 0, 0, L);
    }
    if (!*only || strcmp(only, "meshfloat") == 0) {
        /* the mesh box 0.12 wide, 0.06 high, 0.12 long (stable upright:
         * B^2/(12 d) > (H - d)/2), its bottom 0.02 m above the water; its
         * vertices through assimp's single precision */
        const double W = (double)0.20f - (double)0.08f, H = (double)0.24f - (double)0.18f,
                     L = (double)0.16f - (double)0.04f;
        check_float(argv[1], "mesh box float", "type mesh; file \"body.obj\";", float_box_obj,
                    500 * W * H * L, 0, W, H, L);
    }
    return mf_test_summary("bodies3d");
}
