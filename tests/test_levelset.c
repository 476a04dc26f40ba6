/* test_levelset.c: the level set and blobby surface reconstructions on
 * particles filling a sphere and a box at spacing l0 (issue "Surface
 * reconstruction"):
 *   - the mean distance of the mesh vertices to the true surface is below
 *     0.25 l0 and the largest below l0; the mesh is closed and manifold, with
 *     Euler characteristic 2;
 *   - a sphere moved between frames gives the moved surface, and the warm
 *     start needs fewer steps than a cold start on the same frame;
 *   - explicit (ERKStep) and IMEX (ARKStep) agree; the explicit count of
 *     right-hand sides grows at most as l0/h from h = l0/2 to l0/8 (its
 *     damped Chebyshev stages stretch the stability interval as s^2; a
 *     forward-Euler-like method's count grows as (l0/h)^2, 16 times); both
 *     counts are printed;
 *   - bad input (no fluid particle, a NaN position, a grid too fine for the
 *     memory) gives an error that says so.
 * The particles are a cubic lattice: the true surface of "particles filling
 * a sphere of radius R" is the sphere the lattice points |x - c| <= R fill
 * (each particle stands for a cube l0^3, and their union has the ball's
 * volume); for the box, the faces of the l0-cubes around the points. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surface/levelset/levelset.h"
#include "mf_dictio.h"
#include "mf_test.h"

#define L0 0.01

typedef struct shape {
    int kind; /* 0 sphere, 1 box */
    double c[3], R;
    double lo[3], hi[3];
} shape;

static double surface_distance(const shape *s, const float *x)
{
    if (s->kind == 0) {
        double d2 = 0;
        for (int a = 0; a < 3; a++)
            d2 += (x[a] - s->c[a]) * (x[a] - s->c[a]);
        return fabs(sqrt(d2) - s->R);
    }
    /* box: inside, the nearest face; outside, the distance to the box */
    double out2 = 0, in = INFINITY;
    for (int a = 0; a < 3; a++) {
        double below = s->lo[a] - x[a], above = x[a] - s->hi[a];
        double e = fmax(below, above);
        if (e > 0)
            out2 += e * e;
        in = fmin(in, -e);
    }
    return out2 > 0 ? sqrt(out2) : in;
}

static int add_fluid(mf_particles *p, const double x[3], const double v[3])
{
    return mf_particles_add(p, MF_FLUID, x, v, NULL);
}

/* Deterministic jitter in [-1, 1) (a linear congruential generator). */
static double jitter_value(unsigned long *state)
{
    *state = *state * 6364136223846793005UL + 1442695040888963407UL;
    return (double)(*state >> 11) / (double)(1UL << 53) * 2 - 1;
}

static double sphere_jitter = 0; /* in l0: MPS-like disorder of the lattice */

/* Lattice points of spacing l0 inside the sphere (c, R), moving with v. */
static mf_particles *sphere_particles(const double c[3], double R, const double v[3])
{
    unsigned long state = 12345;
    mf_particles *p = NULL;
    if (mf_particles_create(3, 1024, &p) != 0)
        return NULL;
    int n = (int)ceil(R / L0) + 1;
    for (int k = -n; k <= n; k++)
        for (int j = -n; j <= n; j++)
            for (int i = -n; i <= n; i++) {
                double x[3] = {c[0] + i * L0, c[1] + j * L0, c[2] + k * L0};
                for (int a = 0; a < 3; a++)
                    x[a] += sphere_jitter * L0 * jitter_value(&state);
                if (i * i + j * j + k * k <= (R / L0) * (R / L0) + 1e-9 && add_fluid(p, x, v) != 0)
                    return NULL;
            }
    return p;
}

static mf_particles *box_particles(const double lo[3], const int n[3])
{
    mf_particles *p = NULL;
    if (mf_particles_create(3, 1024, &p) != 0)
        return NULL;
    const double v[3] = {0, 0, 0};
    for (int k = 0; k < n[2]; k++)
        for (int j = 0; j < n[1]; j++)
            for (int i = 0; i < n[0]; i++) {
                double x[3] = {lo[0] + (i + 0.5) * L0, lo[1] + (j + 0.5) * L0,
                               lo[2] + (k + 0.5) * L0};
                if (add_fluid(p, x, v) != 0)
                    return NULL;
            }
    return p;
}

typedef struct recon {
    mf_module m;
    const mf_surface_ops *ops;
    mf_registry *reg;
    mf_log log;
} recon;

/* A surface module from a coefficients text, e.g. "gridSpacing 0.005;". */
static int recon_open(recon *r, mf_registry *reg, const char *method, const char *coeffs)
{
    memset(r, 0, sizeof *r);
    r->reg = reg;
    mf_log_init(&r->log, stdout, getenv("MF_TEST_VERBOSE") ? MF_LOG_NORMAL : MF_LOG_QUIET);
    r->log.progress = false;
    mf_dict *d = NULL;
    MF_CALL(mf_dict_parse_string(coeffs, strlen(coeffs), "test coefficients", &d));
    int rc = mf_module_prepare(reg, MF_KIND_SURFACE, method, d, NULL, NULL, &r->m);
    if (rc == 0) {
        r->ops = (const mf_surface_ops *)r->m.info;
        rc = r->ops->create(r->m.settings, &r->m.data);
    }
    /* the modules keep no pointer into the dictionary: it may go */
    mf_dict_free(d);
    return rc;
}

static void recon_close(recon *r)
{
    if (r->ops && r->m.data)
        r->ops->destroy(r->m.data);
    mf_module_release(&r->m);
}

static int recon_run(recon *r, mf_particles *p, double time, mf_mesh *mesh)
{
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    sim.dim = 3;
    sim.l0 = L0;
    sim.p = p;
    sim.time = time;
    sim.log = &r->log;
    sim.reg = r->reg;
    return r->ops->reconstruct(r->m.data, &sim, mesh);
}

typedef struct fit {
    double mean, max;
} fit;

static fit mesh_fit(const mf_mesh *m, const shape *s)
{
    fit f = {0, 0};
    for (size_t v = 0; v < m->nverts; v++) {
        double d = surface_distance(s, &m->xyz[3 * v]);
        f.mean += d;
        f.max = fmax(f.max, d);
    }
    f.mean /= m->nverts ? (double)m->nverts : 1;
    f.mean /= L0;
    f.max /= L0;
    return f;
}

/* Normals must point away from the body: mean dot with the radial direction. */
static double mean_outward(const mf_mesh *m, const double c[3])
{
    double s = 0;
    for (size_t v = 0; v < m->nverts; v++) {
        double r[3], rn = 0, dot = 0;
        for (int a = 0; a < 3; a++) {
            r[a] = m->xyz[3 * v + a] - c[a];
            rn += r[a] * r[a];
        }
        rn = sqrt(rn);
        for (int a = 0; a < 3; a++)
            dot += m->normal[3 * v + a] * r[a] / rn;
        s += dot;
    }
    return m->nverts ? s / (double)m->nverts : 0;
}

static void check_topology(const mf_mesh *m, const char *what)
{
    ls_topology t;
    CHECK_OK(ls_mesh_topology(m, &t));
    printf("%s: %zu vertices, %zu triangles, Euler characteristic %ld, %zu component(s), "
           "closed %s, manifold %s\n",
           what, t.vertices, t.faces, t.euler, t.components, t.closed ? "yes" : "no",
           t.manifold ? "yes" : "no");
    CHECK_MSG(m->ntris > 0, "%s: empty mesh", what);
    CHECK_MSG(t.closed, "%s: %zu boundary and %zu non-manifold edges", what, t.boundary_edges,
              t.nonmanifold_edges);
    CHECK_MSG(t.manifold, "%s: %zu non-manifold vertices", what, t.nonmanifold_vertices);
    CHECK_MSG(t.euler == 2 && t.components == 1, "%s: Euler characteristic %ld, %zu components",
              what, t.euler, t.components);
}

static long rhs_total(const ls_stats *st)
{
    return st->rhs_explicit + st->rhs_implicit + st->rhs_jtimes;
}

/* ---- the tests ----------------------------------------------------------- */

static void test_sphere_and_box(mf_registry *reg, const char *method)
{
    const double c[3] = {0.0312, -0.0123, 0.0057}, v0[3] = {0, 0, 0};
    shape sph = {.kind = 0, .c = {c[0], c[1], c[2]}, .R = 8 * L0};
    mf_particles *p = sphere_particles(c, sph.R, v0);
    CHECK(p != NULL);
    recon r;
    CHECK_OK(recon_open(&r, reg, method, "gridSpacing 0.005;"));
    mf_mesh mesh;
    mf_mesh_init(&mesh);
    char what[128];
    if (p && r.ops) {
        CHECK_OK(recon_run(&r, p, 0.0, &mesh));
        fit f = mesh_fit(&mesh, &sph);
        snprintf(what, sizeof what, "%s, sphere R = 8 l0 (%zu particles), h = l0/2", method,
                 p->n);
        printf("%s: vertex distance to the sphere mean %.3f l0, max %.3f l0\n", what, f.mean,
               f.max);
        CHECK_MSG(f.mean < 0.25, "%s: mean distance %.3f l0", what, f.mean);
        CHECK_MSG(f.max < 1.0, "%s: max distance %.3f l0", what, f.max);
        check_topology(&mesh, what);
        CHECK_MSG(mean_outward(&mesh, c) > 0.95, "%s: normals do not point outward (%.3f)", what,
                  mean_outward(&mesh, c));
    }
    mf_particles_destroy(p);
    recon_close(&r);

    const double lo[3] = {-0.05, 0.02, 0.0};
    const int n[3] = {12, 9, 15};
    shape box = {.kind = 1, .lo = {lo[0], lo[1], lo[2]},
                 .hi = {lo[0] + n[0] * L0, lo[1] + n[1] * L0, lo[2] + n[2] * L0}};
    p = box_particles(lo, n);
    CHECK(p != NULL);
    CHECK_OK(recon_open(&r, reg, method, "gridSpacing 0.005;"));
    if (p && r.ops) {
        CHECK_OK(recon_run(&r, p, 0.0, &mesh));
        fit f = mesh_fit(&mesh, &box);
        snprintf(what, sizeof what, "%s, box 12 x 9 x 15 l0 (%zu particles), h = l0/2", method,
                 p->n);
        printf("%s: vertex distance to the box mean %.3f l0, max %.3f l0\n", what, f.mean,
               f.max);
        CHECK_MSG(f.mean < 0.25, "%s: mean distance %.3f l0", what, f.mean);
        CHECK_MSG(f.max < 1.0, "%s: max distance %.3f l0", what, f.max);
        check_topology(&mesh, what);
    }
    mf_particles_destroy(p);
    recon_close(&r);
    mf_mesh_free(&mesh);
}

/* Centroid of the surface (area-weighted over the triangles). */
static void mesh_centroid(const mf_mesh *m, double c[3])
{
    double area = 0;
    c[0] = c[1] = c[2] = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        const float *A = &m->xyz[3 * m->tri[3 * t]], *B = &m->xyz[3 * m->tri[3 * t + 1]],
                    *C = &m->xyz[3 * m->tri[3 * t + 2]];
        double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
        double v[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
        double a = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++)
            c[k] += a * (A[k] + B[k] + C[k]) / 3;
        area += a;
    }
    for (int k = 0; k < 3; k++)
        c[k] /= area > 0 ? area : 1;
}

/* Frame 1 at c1, frame 2 moved by `shift` (in l0, along a fixed direction):
 * returns the steps of the warm start (module that did frame 1) and of a
 * cold start on frame 2, and checks the warm-started surface. */
static void warm_vs_cold(mf_registry *reg, double shift, long *warm_steps, long *cold_steps)
{
    const double dir[3] = {0.8, 0.55, 0.24}, rest[3] = {0, 0, 0}, c1[3] = {0, 0, 0};
    double nd = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    double c2[3];
    for (int k = 0; k < 3; k++)
        c2[k] = c1[k] + shift * L0 * dir[k] / nd;
    mf_particles *p1 = sphere_particles(c1, 8 * L0, rest), *p2 = sphere_particles(c2, 8 * L0, rest);
    CHECK(p1 && p2);
    recon warm, cold;
    CHECK_OK(recon_open(&warm, reg, "levelSet", "gridSpacing 0.005;"));
    CHECK_OK(recon_open(&cold, reg, "levelSet", "gridSpacing 0.005;"));
    mf_mesh mesh;
    mf_mesh_init(&mesh);
    *warm_steps = *cold_steps = 0;
    if (p1 && p2 && warm.ops && cold.ops) {
        CHECK_OK(recon_run(&warm, p1, 0.0, &mesh));
        ls_stats first = ((ls_data *)warm.m.data)->last;
        CHECK_OK(recon_run(&warm, p2, 0.01, &mesh));
        ls_stats ws = ((ls_data *)warm.m.data)->last;
        shape moved = {.kind = 0, .c = {c2[0], c2[1], c2[2]}, .R = 8 * L0};
        fit f = mesh_fit(&mesh, &moved);
        double cm[3], err = 0;
        mesh_centroid(&mesh, cm);
        for (int k = 0; k < 3; k++)
            err += (cm[k] - c2[k]) * (cm[k] - c2[k]);
        err = sqrt(err) / L0;
        char what[96];
        snprintf(what, sizeof what, "sphere moved by %.2f l0, warm start", shift);
        printf("%s: distance to the moved sphere mean %.3f max %.3f l0; surface centroid %.3f l0 "
               "from the moved centre\n",
               what, f.mean, f.max, err);
        CHECK_MSG(f.mean < 0.25 && f.max < 1.0, "%s: mean %.3f max %.3f l0", what, f.mean, f.max);
        /* the jitter alone moves the centroid by about 0.01 l0 */
        CHECK_MSG(err < 0.05 + 0.1 * shift, "%s: centroid %.3f l0 from the moved centre", what,
                  err);
        check_topology(&mesh, what);
        CHECK_OK(recon_run(&cold, p2, 0.01, &mesh));
        ls_stats cs = ((ls_data *)cold.m.data)->last;
        printf("%s: first frame %ld steps (pseudo-time %.2f); second frame warm %ld steps "
               "(pseudo-time %.2f, %ld right-hand sides), cold %ld steps (pseudo-time %.2f, %ld "
               "right-hand sides)\n",
               what, first.steps, first.pseudo_time, ws.steps, ws.pseudo_time, rhs_total(&ws),
               cs.steps, cs.pseudo_time, rhs_total(&cs));
        CHECK(ws.converged && cs.converged);
        *warm_steps = ws.steps;
        *cold_steps = cs.steps;
    }
    mf_particles_destroy(p1);
    mf_particles_destroy(p2);
    recon_close(&warm);
    recon_close(&cold);
    mf_mesh_free(&mesh);
}

static void test_warm_start(mf_registry *reg)
{
    /* MPS-like disorder of the particles (+-0.15 l0 jitter, the same in both
     * frames; no velocities: a rigid translation would make eq. 32 stretch
     * them all). The cold start begins at F = 0, which the curvature term
     * moves by about 0.2 l0 here; the warm start begins at the last frame's
     * surface, off by the motion. Small motions between frames (a few time
     * steps at Courant 0.2) favour the warm start. */
    sphere_jitter = 0.15;
    long w, c;
    warm_vs_cold(reg, 0.05, &w, &c);
    CHECK_MSG(w < c, "motion 0.05 l0: warm start %ld steps, cold start %ld", w, c);
    /* A large motion: the surface still follows, the warm start is no
     * longer cheaper (printed, not asserted). */
    warm_vs_cold(reg, 0.5, &w, &c);
    sphere_jitter = 0;
}

/* Nearest-vertex distance from every vertex of a to b (brute force over a
 * uniform hash would be faster; the meshes here are small). */
static double mesh_gap(const mf_mesh *a, const mf_mesh *b)
{
    double worst = 0;
    for (size_t i = 0; i < a->nverts; i++) {
        double best = INFINITY;
        for (size_t j = 0; j < b->nverts; j++) {
            double d2 = 0;
            for (int k = 0; k < 3; k++) {
                double d = a->xyz[3 * i + k] - b->xyz[3 * j + k];
                d2 += d * d;
            }
            best = fmin(best, d2);
        }
        worst = fmax(worst, sqrt(best));
    }
    return worst;
}

static void test_explicit_imex(mf_registry *reg)
{
    const double c[3] = {0, 0, 0}, v0[3] = {0, 0, 0};
    mf_particles *p = sphere_particles(c, 4 * L0, v0);
    shape sph = {.kind = 0, .c = {0, 0, 0}, .R = 4 * L0};
    CHECK(p != NULL);
    const char *grids[2] = {"0.005", "0.00125"};
    const char *names[2] = {"h = l0/2", "h = l0/8"};
    long rhs[2][2] = {{0}};
    for (int g = 0; g < 2 && p; g++) {
        mf_mesh mesh[2];
        fit f[2];
        for (int k = 0; k < 2; k++) {
            mf_mesh_init(&mesh[k]);
            char coeffs[256];
            /* a tighter convergence tolerance than the default, so that
             * both runs are close to the same steady state */
            snprintf(coeffs, sizeof coeffs, "gridSpacing %s; integrator %s; tolerance 0.01;",
                     grids[g],
                     k ? "imex" : "explicit");
            recon r;
            CHECK_OK(recon_open(&r, reg, "levelSet", coeffs));
            if (!r.ops)
                continue;
            CHECK_OK(recon_run(&r, p, 0.0, &mesh[k]));
            ls_stats st = ((ls_data *)r.m.data)->last;
            rhs[g][k] = rhs_total(&st);
            f[k] = mesh_fit(&mesh[k], &sph);
            printf("%s, %s: %ld steps, right-hand sides %ld (explicit part %ld, implicit %ld, "
                   "Jacobian-vector %ld), pseudo-time %.2f, %s; sphere fit mean %.3f max "
                   "%.3f l0\n",
                   names[g], k ? "IMEX" : "explicit", st.steps, rhs[g][k], st.rhs_explicit,
                   st.rhs_implicit, st.rhs_jtimes, st.pseudo_time,
                   st.converged ? "converged" : "NOT converged", f[k].mean, f[k].max);
            CHECK(st.converged);
            recon_close(&r);
        }
        if (g == 0) {
            /* same steady state: the meshes lie within a small fraction of l0 */
            double gap = fmax(mesh_gap(&mesh[0], &mesh[1]), mesh_gap(&mesh[1], &mesh[0]));
            printf("%s: explicit and IMEX meshes within %.4f l0 of each other\n", names[g],
                   gap / L0);
            CHECK_MSG(gap < 0.1 * L0, "explicit and IMEX differ by %.3f l0", gap / L0);
        } else {
            CHECK_MSG(fabs(f[0].mean - f[1].mean) < 0.05,
                      "fine grid: explicit fit %.3f, IMEX fit %.3f l0", f[0].mean, f[1].mean);
        }
        mf_mesh_free(&mesh[0]);
        mf_mesh_free(&mesh[1]);
    }
    printf("right-hand-side evaluations, explicit / IMEX: h = l0/2 %ld / %ld, h = l0/8 %ld / "
           "%ld\n",
           rhs[0][0], rhs[0][1], rhs[1][0], rhs[1][1]);
    /* the curvature's stiffness grows as (l0/h)^2 from grid to grid (16
     * times here); the explicit work may grow at most as l0/h (4 times) */
    CHECK_MSG(rhs[1][0] < 4 * rhs[0][0],
              "explicit: %ld right-hand sides at h = l0/8 against %ld at l0/2", rhs[1][0],
              rhs[0][0]);
    mf_particles_destroy(p);
}

static void expect_error(int rc, int code, const char *text, const char *what)
{
    const char *msg = mf_error_message();
    printf("%s: %s\n", what, rc ? msg : "(no error)");
    CHECK_MSG(rc == code, "%s: status %d, expected %d", what, rc, code);
    CHECK_MSG(strstr(msg, text) != NULL, "%s: message lacks '%s': %s", what, text, msg);
    mf_error_clear();
}

static void test_bad_input(mf_registry *reg)
{
    const char *methods[2] = {"levelSet", "blobby"};
    for (int k = 0; k < 2; k++) {
        recon r;
        CHECK_OK(recon_open(&r, reg, methods[k], "gridSpacing 0.005;"));
        if (!r.ops)
            continue;
        mf_mesh mesh;
        mf_mesh_init(&mesh);
        mf_particles *p = NULL;
        CHECK_OK(mf_particles_create(3, 16, &p));
        /* only a wall particle: no fluid */
        const double x[3] = {0, 0, 0}, v[3] = {0, 0, 0};
        CHECK_OK(mf_particles_add(p, MF_WALL, x, v, NULL));
        char what[64];
        snprintf(what, sizeof what, "%s, no fluid particle", methods[k]);
        expect_error(recon_run(&r, p, 0.0, &mesh), MF_ERR_INPUT, "no fluid particles", what);
        /* a NaN position */
        const double bad[3] = {0.01, NAN, 0};
        CHECK_OK(mf_particles_add(p, MF_FLUID, x, v, NULL));
        CHECK_OK(mf_particles_add(p, MF_FLUID, bad, v, NULL));
        snprintf(what, sizeof what, "%s, NaN position", methods[k]);
        expect_error(recon_run(&r, p, 0.0, &mesh), MF_ERR_INPUT, "non-finite position", what);
        recon_close(&r);
        mf_particles_destroy(p);
        /* a grid far too fine for the memory limit */
        CHECK_OK(recon_open(&r, reg, methods[k], "gridSpacing 1e-6; maxMemory 64;"));
        const double c[3] = {0, 0, 0};
        p = sphere_particles(c, 3 * L0, v);
        snprintf(what, sizeof what, "%s, grid too fine", methods[k]);
        if (p && r.ops)
            expect_error(recon_run(&r, p, 0.0, &mesh), MF_ERR_MEMORY, "too fine", what);
        recon_close(&r);
        mf_particles_destroy(p);
        mf_mesh_free(&mesh);
    }
}

/* Eq. 32: a particle moving along x reaches further along x than across. */
static void test_anisotropy(void)
{
    mf_particles *p = NULL;
    CHECK_OK(mf_particles_create(3, 4, &p));
    const double x0[3] = {0, 0, 0}, x1[3] = {0.3, 0, 0}, v[3] = {1, 0, 0}, rest[3] = {0, 0, 0};
    CHECK_OK(mf_particles_add(p, MF_FLUID, x0, v, NULL));
    CHECK_OK(mf_particles_add(p, MF_FLUID, x1, rest, NULL)); /* s = 1 for the first */
    for (int aniso = 0; aniso < 2; aniso++) {
        ls_field f;
        ls_field_init(&f);
        const double h = 0.005;
        CHECK_OK(ls_field_setup(&f, p, LS_KERNEL_LEVELSET, h, L0, 0.73, 2.5, 2, -2, aniso,
                                (size_t)1 << 30, "anisotropy test"));
        /* two cells from the moving particle along x and along y */
        int32_t bx = ls_bricks_find(&f.touched, ls_brick_of(-2), 0, 0);
        int32_t by = ls_bricks_find(&f.touched, 0, ls_brick_of(2), 0);
        double along = ls_field_at(&f, bx, -2, 0, 0), across = ls_field_at(&f, by, 0, 2, 0);
        printf("eq. 32 %s: F - T two cells from a moving particle: along %.4f, across %.4f\n",
               aniso ? "on" : "off", along + 2, across + 2);
        if (aniso)
            CHECK_MSG(along + 2 > 4 * (across + 2), "anisotropic: along %.4f, across %.4f",
                      along + 2, across + 2);
        else
            CHECK_NEAR(along, across, 1e-12);
        ls_field_free(&f);
    }
    mf_particles_destroy(p);
}

int main(void)
{
    test_anisotropy();
    mf_registry *reg = NULL;
    CHECK_OK(mf_registry_create(&reg));
    CHECK_OK(mf_registry_add(reg, &mf_surface_levelSet.info));
    CHECK_OK(mf_registry_add(reg, &mf_surface_blobby.info));
    test_sphere_and_box(reg, "levelSet");
    test_sphere_and_box(reg, "blobby");
    test_warm_start(reg);
    test_explicit_imex(reg);
    test_bad_input(reg);
    mf_registry_destroy(reg);
    return mf_test_summary("levelset");
}
