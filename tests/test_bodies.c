/* test_bodies.c: rigid bodies moved by the fluid (issue 18; core/scene/
 * mf_bodies.h, solvers/solver/mps/mps_bodies.c).
 *
 *   momentum   a free blob of water (no gravity) in a closed box, never
 *              touching its walls, with a neutrally buoyant box body in it
 *              set moving at U: the total momentum of fluid and body,
 *                P = sum_i m_i u_i + m_b v_b + J,
 *              (J the impulse the body has received but not yet taken, the
 *              step's force times its dt) stays what it was. The scheme is
 *              the one whose pair forces are all antisymmetric (gradient
 *              corrected, the CMPS pair term of Khayyer & Gotoh 2008; the
 *              eq. 7 Laplacian; no collision model, no shifting): the fluid
 *              alone conserves its momentum, and the body receives the exact
 *              reaction of the pressure and viscous pair forces the fluid
 *              received from its particles (mps_bodies.c). What is left is
 *              round-off and the 9 significant digits of bodyState.csv's
 *              velocity and force: |P(t) - P(0)| <= MOMENTUM_TOL P(0), with
 *              MOMENTUM_TOL = 1e-8 (10 ulp of the CSV's digits; a wrong sign,
 *              factor or one-step lag of the exchange is an error of order
 *              the impulse exchanged, 0.4 P(0) here);
 *   snapshot   the last snapshot holds the body's state (/RigidBodies/body):
 *              its Velocity is the CSV's at that time (to the CSV's digits);
 *   at rest    the same body with the blob at rest stays at rest (no force
 *              from nothing): |v_b| below 1e-6 m/s;
 *   restart    the momentum case stopped at t = 0.04 s and restarted from
 *              that snapshot (-latestTime) ends as the straight run does, bit
 *              for bit: every particle's position and velocity, the body's
 *              state in the last snapshot (/RigidBodies/body), and the text of
 *              bodyState.csv (the rows up to the restart kept, the rest
 *              appended);
 *   contact    two boxes (0.1 x 0.05 m, density 500) dropped in a dry tank,
 *              the upper 0.1 m above the lower and 0.02 m to the side: the
 *              lower lands on the floor, the upper on it (body_contact.c):
 *              at t = 0.5 s their centres are within l0/4 of resting (y =
 *              0.025 and 0.075 m: bottom on the floor, bottom on the lower's
 *              top), moving up or down at less than 0.05 m/s, turned by less
 *              than 2 degrees (without friction they may slide sideways). Without
 *              contact both fall through the floor (a box falls 0.1 m in
 *              0.14 s);
 *   waterEntry the tutorial at l0 = 0.011 m (10 particles across D = 0.11 m),
 *              then `mpsflow validate`: its momentum-theory curves at
 *              t = 0.03 s are an independent RK4 of the same equation's
 *              (von Karman 0.0550 m, Wagner 0.0494 m, to 1e-4 m); the
 *              penetration there lies between them widened by l0/2 (the
 *              body's surface is l0/2 from its particles); the RMS error
 *              is below l0/2 of D.
 *
 * argv[1]: mpsflow; argv[2]: tutorials/waterEntry. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <hdf5.h>

#include "body_cases.h"
#include "case_util.h"
#include "mf_test.h"

#define L0 0.01
#define MOMENTUM_TOL 1e-8 /* of P(0): the CSV's 9 significant digits */

static const char *const control =
    "endTime 0.2;\ndeltaT 1e-4;\nadjustTimeStep yes;\nmaxCo 0.2;\nmaxDeltaT 1e-3;\n"
    "writeControl adjustableRunTime;\nwriteInterval 0.02;\n";
static const char *const fluids = "water { rho 1000; nu 1e-4; }\n";
/* Attribute `name` (n doubles) of /RigidBodies/<body> in snapshot `path`. */
static int body_attribute(const char *path, const char *body, const char *name, double *v)
{
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return -1;
    char obj[256];
    snprintf(obj, sizeof obj, "/RigidBodies/%s", body);
    int rc = -1;
    hid_t a = H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT);
    if (a >= 0) {
        rc = H5Aread(a, H5T_NATIVE_DOUBLE, v) < 0 ? -1 : 0;
        H5Aclose(a);
    }
    H5Fclose(f);
    return rc;
}

static bool run(tc_case *c, const char *what)
{
    int status = tc_case_run(c, NULL, NULL);
    CHECK_MSG(status == 0, "%s: mpsflow exited with %d", what, status);
    if (status != 0)
        tc_case_log_tail(c, 20);
    return status == 0;
}

static void check_momentum(const char *exe)
{
    const double U = 0.05;
    char geo[2048];
    tc_momentum_geometry(geo, sizeof geo, L0, U);
    tc_case c;
    CHECK_OK(tc_case_from_strings(&c, exe, "bodies-momentum", control, TC_MOMENTUM_SOLVER, fluids,
                                  geo));
    tc_body_track tr;
    bool ok = run(&c, "momentum");
    if (ok) {
        ok = tc_body_track_read(c.dir, "body", &tr) == 0;
        CHECK_MSG(ok, "momentum: no postProcessing/body/bodyState.csv with rows");
    }
    if (ok) {
        tc_snapshots s;
        CHECK_OK(tc_snapshots_list(c.dir, &s));
        const double P0 = tr.mass * U;
        double worst = 0, worst_ratio = 0, impulse = 0;
        size_t row = 0, checked = 0;
        for (size_t k = 0; k < s.n; k++) {
            mf_sim sim;
            mf_hdf5_header h;
            if (tc_snapshot_load(c.dir, s.index[k], &sim, &h) != 0)
                continue;
            double P[2] = {0, 0};
            const double m = 1000 * L0 * L0;
            for (size_t i = 0; i < sim.p->n; i++)
                if (sim.p->kind[i] == MF_FLUID) {
                    P[0] += m * sim.p->vel[3 * i];
                    P[1] += m * sim.p->vel[3 * i + 1];
                }
            tc_sim_free(&sim);
            /* the body's row at this time; the impulse received up to it */
            while (row + 1 < tr.n && tr.t[row] < h.time * (1 - 1e-12)) {
                row++;
                const double dt = tr.t[row] - tr.t[row - 1];
                impulse += hypot(tr.f[3 * row], tr.f[3 * row + 1]) * dt;
            }
            if (fabs(tr.t[row] - h.time) > 1e-9 * fmax(1, h.time))
                continue;
            const double dt = row > 0 ? tr.t[row] - tr.t[row - 1] : 0;
            for (int a = 0; a < 2; a++)
                P[a] += tr.mass * tr.v[3 * row + a] + tr.f[3 * row + a] * dt;
            const double err = hypot(P[0] - P0, P[1]);
            worst = fmax(worst, err);
            if (impulse > 0)
                worst_ratio = fmax(worst_ratio, err / impulse);
            printf("t = %.3f: P = (%.6g %.6g) kg m/s (P(0) = %.6g), body v = %.5f m/s, "
                   "|P - P(0)| = %.3g = %.3g of the impulse %.4g\n",
                   h.time, P[0], P[1], P0, tr.v[3 * row], err, impulse > 0 ? err / impulse : 0,
                   impulse);
            CHECK_MSG(err <= MOMENTUM_TOL * P0,
                      "momentum: t = %g: |P - P(0)| = %g above %g P(0) (the impulse exchanged: "
                      "%g)", h.time, err, MOMENTUM_TOL, impulse);
            checked++;
        }
        if (s.n > 0) {
            char path[1024];
            tc_snapshot_path(c.dir, s.index[s.n - 1], path, sizeof path);
            double v[3] = {NAN, NAN, NAN};
            CHECK_OK(body_attribute(path, "body", "Velocity", v));
            const double vl = tr.v[3 * (tr.n - 1)];
            printf("snapshot: /RigidBodies/body Velocity (%.9g %.9g), the CSV's last row %.9g\n",
                   v[0], v[1], vl);
            CHECK(fabs(v[0] - vl) <= 1e-8 * fabs(vl) && fabs(v[1]) < 1e-12);
        }
        tc_snapshots_free(&s);
        CHECK_MSG(checked >= 5, "momentum: only %zu snapshots matched the body's rows", checked);
        /* the body must have exchanged momentum at all for this to mean anything */
        CHECK_MSG(tr.v[3 * (tr.n - 1)] < 0.95 * U && impulse > 0.05 * P0,
                  "momentum: the body kept its velocity (%g of %g m/s): no exchange with the "
                  "fluid", tr.v[3 * (tr.n - 1)], U);
        printf("momentum: worst |P - P(0)| %.3g kg m/s = %.3g P(0) (tolerance %.2g P(0)), %.3g of "
               "the impulse exchanged\n", worst, worst / P0, MOMENTUM_TOL, worst_ratio);
        tc_body_track_free(&tr);
    }
    tc_case_destroy(&c);
}

static void check_rest(const char *exe)
{
    char geo[2048];
    tc_momentum_geometry(geo, sizeof geo, L0, 0.0);
    tc_case c;
    CHECK_OK(tc_case_from_strings(&c, exe, "bodies-rest", control, TC_MOMENTUM_SOLVER, fluids,
                                  geo));
    tc_body_track tr;
    bool ok = run(&c, "at rest");
    if (ok) {
        ok = tc_body_track_read(c.dir, "body", &tr) == 0;
        CHECK_MSG(ok, "at rest: no postProcessing/body/bodyState.csv with rows");
    }
    if (ok) {
        double vmax = 0;
        for (size_t k = 0; k < tr.n; k++)
            vmax = fmax(vmax, hypot(tr.v[3 * k], tr.v[3 * k + 1]));
        printf("at rest: the body's largest speed %.3g m/s\n", vmax);
        CHECK(vmax < 1e-6);
        tc_body_track_free(&tr);
    }
    tc_case_destroy(&c);
}

/* The whole text of a file (NULL if unreadable); free it. */
static char *slurp(const char *dir, const char *rel)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    return tc_read_text(path);
}

/* The particles and the body's attributes of the last snapshots of x and y
 * are identical; returns the number of differences. */
static int compare_ends(const tc_case *x, const tc_case *y)
{
    tc_snapshots sx, sy;
    if (tc_snapshots_list(x->dir, &sx) != 0)
        return 1;
    if (tc_snapshots_list(y->dir, &sy) != 0) {
        tc_snapshots_free(&sx);
        return 1;
    }
    int diff = 0;
    mf_sim a, b;
    mf_hdf5_header ha, hb;
    if (sx.n == 0 || sy.n == 0 || tc_snapshot_load(x->dir, sx.index[sx.n - 1], &a, &ha) != 0) {
        diff++;
    } else {
        if (tc_snapshot_load(y->dir, sy.index[sy.n - 1], &b, &hb) != 0) {
            diff++;
        } else {
            size_t pos = 0, vel = 0;
            if (a.p->n != b.p->n || ha.time != hb.time || ha.step != hb.step) {
                diff++;
            } else {
                for (size_t i = 0; i < a.p->n; i++) {
                    pos += memcmp(&a.p->pos[3 * i], &b.p->pos[3 * i], 3 * sizeof(double)) != 0;
                    vel += memcmp(&a.p->vel[3 * i], &b.p->vel[3 * i], 3 * sizeof(double)) != 0;
                }
            }
            printf("restart: t = %g, step %ld against %ld: %zu positions and %zu velocities "
                   "differ of %zu\n", hb.time, ha.step, hb.step, pos, vel, a.p->n);
            diff += pos > 0 || vel > 0;
            tc_sim_free(&b);
        }
        tc_sim_free(&a);
    }
    static const char *const names[] = {"Centre", "Rotation", "Velocity", "AngularMomentum",
                                        "Impulse"};
    static const int counts[] = {3, 9, 3, 3, 3};
    for (size_t k = 0; diff == 0 && k < sizeof names / sizeof names[0]; k++) {
        char pa[1024], pb[1024];
        tc_snapshot_path(x->dir, sx.index[sx.n - 1], pa, sizeof pa);
        tc_snapshot_path(y->dir, sy.index[sy.n - 1], pb, sizeof pb);
        double va[9], vb[9];
        if (body_attribute(pa, "body", names[k], va) != 0 ||
            body_attribute(pb, "body", names[k], vb) != 0 ||
            memcmp(va, vb, (size_t)counts[k] * sizeof(double)) != 0) {
            printf("restart: /RigidBodies/body %s differs\n", names[k]);
            diff++;
        }
    }
    tc_snapshots_free(&sx);
    tc_snapshots_free(&sy);
    return diff;
}

static void check_restart(const char *exe)
{
    const double U = 0.05;
    char geo[2048];
    tc_momentum_geometry(geo, sizeof geo, L0, U);
    static const char *const ctl =
        "endTime 0.1;\ndeltaT 1e-4;\nadjustTimeStep yes;\nmaxCo 0.2;\nmaxDeltaT 1e-3;\n"
        "writeControl adjustableRunTime;\nwriteInterval 0.02;\n";
    tc_case whole, split;
    CHECK_OK(tc_case_from_strings(&whole, exe, "bodies-whole", ctl, TC_MOMENTUM_SOLVER, fluids,
                                  geo));
    CHECK_OK(tc_case_from_strings(&split, exe, "bodies-split", ctl, TC_MOMENTUM_SOLVER, fluids,
                                  geo));
    bool ok = run(&whole, "restart: the straight run");
    int s1 = tc_case_run(&split, NULL, (const char *const[]){"-endTime", "0.04", NULL});
    int s2 = s1 == 0 ? tc_case_run(&split, NULL, (const char *const[]){"-latestTime", NULL}) : -1;
    CHECK_MSG(s1 == 0 && s2 == 0, "restart: the split run exited with %d, %d", s1, s2);
    if (s1 != 0 || s2 != 0)
        tc_case_log_tail(&split, 20);
    CHECK_MSG(tc_case_log_contains(&split, "Restarting from time 0.04"),
              "restart: the second run did not restart at t = 0.04");
    if (ok && s1 == 0 && s2 == 0) {
        CHECK_MSG(compare_ends(&whole, &split) == 0, "restart: the ends differ");
        char *a = slurp(whole.dir, "postProcessing/body/bodyState.csv");
        char *b = slurp(split.dir, "postProcessing/body/bodyState.csv");
        CHECK_MSG(a && b && strcmp(a, b) == 0,
                  "restart: bodyState.csv differs from the straight run's (%zu against %zu "
                  "bytes)", a ? strlen(a) : 0, b ? strlen(b) : 0);
        free(a);
        free(b);
    }
    tc_case_destroy(&whole);
    tc_case_destroy(&split);
}

/* The last row (time, x, y, |vy|, qz) of postProcessing/<body>/bodyState.csv. */
static int last_row(const char *dir, const char *body, double row[5])
{
    char path[1024];
    snprintf(path, sizeof path, "%s/postProcessing/%s/bodyState.csv", dir, body);
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    char line[4096];
    int got = -1;
    while (fgets(line, sizeof line, f)) {
        double c[20];
        if (!tc_body_csv_row(line, c))
            continue;
        row[0] = c[0];
        row[1] = c[1];
        row[2] = c[2];
        row[3] = fabs(c[9]); /* vertical: without friction the stack may slide */
        row[4] = c[7];
        got = 0;
    }
    fclose(f);
    return got;
}

static void check_contact(const char *exe)
{
    static const char *const ctl =
        "endTime 0.5;\ndeltaT 1e-4;\nadjustTimeStep yes;\nmaxCo 0.2;\nmaxDeltaT 1e-3;\n"
        "writeControl adjustableRunTime;\nwriteInterval 0.1;\n";
    static const char *const slv = "solver MPS;\n"
                                   "pressure { solver PCG_BoomerAMG; tolerance 1e-8; }\n"
                                   "forces { gravity { g (0 -9.81 0); } }\n";
    /* a puddle in a corner: a case needs fluid */
    static const char *const geo =
        "dimension 2;\nparticleSpacing 0.01;\n"
        "fluidBlocks { water { type box; min (0 0 0); max (0.1 0.05 0); fluid water; } }\n"
        "walls { tank { type box; min (0 0 0); max (0.6 0.5 0); open (ymax); } }\n"
        "obstacles {\n"
        " lower { type box; min (0.3 0.1 0); max (0.4 0.15 0);\n"
        "  motion { type rigid; density 500; } }\n"
        " upper { type box; min (0.32 0.25 0); max (0.42 0.3 0);\n"
        "  motion { type rigid; density 500; } } }\n";
    tc_case c;
    CHECK_OK(tc_case_from_strings(&c, exe, "bodies-contact", ctl, slv, fluids, geo));
    if (run(&c, "contact")) {
        double lo[5], up[5];
        const bool ok = last_row(c.dir, "lower", lo) == 0 && last_row(c.dir, "upper", up) == 0;
        CHECK_MSG(ok, "contact: no bodyState.csv rows");
        if (ok) {
            /* qz = sin(angle/2) */
            const double alo = 2 * asin(fabs(lo[4])) * 180 / M_PI,
                         aup = 2 * asin(fabs(up[4])) * 180 / M_PI;
            printf("contact: t = %g: lower at y = %.5f m (%.3g m/s, %.3g deg), upper at y = "
                   "%.5f m (%.3g m/s, %.3g deg), %.4f m to the side\n", lo[0], lo[2], lo[3], alo,
                   up[2], up[3], aup, up[1] - lo[1]);
            CHECK(fabs(lo[0] - 0.5) < 1e-9);
            CHECK(fabs(lo[2] - 0.025) < 0.25 * L0);
            CHECK(fabs(up[2] - 0.075) < 0.25 * L0);
            CHECK(lo[3] < 0.05 && up[3] < 0.05);
            CHECK(alo < 2 && aup < 2);
        }
    }
    tc_case_destroy(&c);
}

static void check_water_entry(const char *exe, const char *tutorial)
{
    const double l0 = 0.011, D = 0.11;
    tc_case c;
    CHECK_OK(tc_case_from_dir(&c, exe, "bodies-waterEntry", tutorial));
    int status = tc_case_run(&c, NULL, (const char *const[]){"-l0", "0.011", NULL});
    CHECK_MSG(status == 0, "waterEntry: mpsflow exited with %d", status);
    if (status == 0)
        status = tc_case_run(&c, "validate", NULL);
    CHECK_MSG(status == 0, "waterEntry: validate exited with %d", status);
    if (status != 0) {
        tc_case_log_tail(&c, 20);
        tc_case_destroy(&c);
        return;
    }
    char path[1024];
    snprintf(path, sizeof path, "%s/validation/result.csv", c.dir);
    FILE *f = fopen(path, "r");
    CHECK_MSG(f != NULL, "waterEntry: no %s", path);
    double last[4] = {NAN, NAN, NAN, NAN}, sum = 0;
    size_t rows = 0;
    char line[1024];
    while (f && fgets(line, sizeof line, f)) {
        double v[4];
        if (line[0] == '#' || sscanf(line, "%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3]) != 4)
            continue;
        if (rows++ > 0) /* the first row is t = 0, h = 0 */
            sum += (v[1] - v[2]) * (v[1] - v[2]) / (D * D);
        memcpy(last, v, sizeof v);
    }
    if (f)
        fclose(f);
    const double rms = rows > 1 ? sqrt(sum / (double)(rows - 1)) : NAN;
    printf("waterEntry: t = %g: h = %.5f m, von Karman %.5f m, Wagner %.5f m; RMS (h - "
           "h_vK)/D = %.4g over %zu rows\n", last[0], last[1], last[2], last[3], rms, rows);
    CHECK(fabs(last[0] - 0.03) < 1e-6);
    CHECK(fabs(last[2] - 0.0550) < 1e-4 && fabs(last[3] - 0.0494) < 1e-4);
    CHECK(last[1] > last[3] - 0.5 * l0 && last[1] < last[2] + 0.5 * l0);
    CHECK(rms < 0.5 * l0 / D);
    tc_case_destroy(&c);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_bodies MPSFLOW TUTORIALS/waterEntry\n");
        return 2;
    }
    check_momentum(argv[1]);
    check_rest(argv[1]);
    check_restart(argv[1]);
    check_contact(argv[1]);
    check_water_entry(argv[1], argv[2]);
    return mf_test_summary("bodies");
}
