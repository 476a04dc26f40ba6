/* test_mesh.c: mesh extraction and mesh files.
 *   - marching tetrahedra on analytic fields sampled on a brick grid: a
 *     sphere (Euler characteristic 2) and a torus (0) come out closed and
 *     manifold, with outward normals, vertices on the analytic surface, and
 *     the same mesh for 1 and 2 threads;
 *   - fields known only near the surface (bricks missing elsewhere) still
 *     give a closed mesh;
 *   - binary PLY round trip (header as Blender reads it), OBJ counts, the
 *     HDF5 copy and the XDMF index that points at it; a truncated PLY and a
 *     missing folder give errors naming the file. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "surface/levelset/levelset.h"
#include "mf_mesh_writer.h"
#include "mf_test.h"

/* A field on the bricks of a box of grid points [lo, hi)^3, spacing h. */
typedef struct grid_field {
    ls_bricks b;
    double *v;
    int32_t *nb;
} grid_field;

typedef double (*field_fn)(const double x[3]);

static const double C[3] = {0.013, -0.021, 0.007};

static double sphere_fn(const double x[3])
{
    double r = sqrt((x[0] - C[0]) * (x[0] - C[0]) + (x[1] - C[1]) * (x[1] - C[1]) +
                    (x[2] - C[2]) * (x[2] - C[2]));
    return 0.1 - r; /* > 0 inside */
}

static double torus_fn(const double x[3])
{
    double dx = x[0] - C[0], dy = x[1] - C[1], dz = x[2] - C[2];
    double q = sqrt(dx * dx + dy * dy) - 0.1;
    return 0.04 - sqrt(q * q + dz * dz);
}

/* Sample f at the grid points of the bricks that hold a point within
 * `band` of the zero level (|f| < band), or all bricks if band <= 0. */
static int sample(grid_field *g, field_fn f, double h, int lo, int hi, double band)
{
    ls_bricks_init(&g->b);
    g->v = NULL;
    g->nb = NULL;
    int blo = ls_brick_of(lo), bhi = ls_brick_of(hi);
    for (int bz = blo; bz <= bhi; bz++)
        for (int by = blo; by <= bhi; by++)
            for (int bx = blo; bx <= bhi; bx++) {
                bool keep = band <= 0;
                for (int l = 0; l < LS_B3 && !keep; l++) {
                    double x[3] = {h * (8 * bx + (l & 7)), h * (8 * by + ((l >> 3) & 7)),
                                   h * (8 * bz + (l >> 6))};
                    keep = fabs(f(x)) < band;
                }
                if (!keep)
                    continue;
                int32_t idx;
                MF_CALL(ls_bricks_insert(&g->b, bx, by, bz, &idx, NULL));
            }
    g->v = malloc(g->b.n * LS_B3 * sizeof *g->v);
    if (!g->v)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    for (size_t b = 0; b < g->b.n; b++)
        for (int l = 0; l < LS_B3; l++) {
            const int32_t *c = &g->b.coord[3 * b];
            double x[3] = {h * (8 * c[0] + (l & 7)), h * (8 * c[1] + ((l >> 3) & 7)),
                           h * (8 * c[2] + (l >> 6))};
            g->v[b * LS_B3 + l] = f(x);
        }
    MF_CALL(ls_bricks_neighbours(&g->b, &g->nb));
    return 0;
}

static void grid_free(grid_field *g)
{
    ls_bricks_free(&g->b);
    free(g->v);
    free(g->nb);
}

static void check_mesh(const mf_mesh *m, field_fn f, long euler, const char *what)
{
    ls_topology t;
    CHECK_OK(ls_mesh_topology(m, &t));
    printf("%s: %zu vertices, %zu triangles, Euler characteristic %ld, closed %s, manifold %s\n",
           what, t.vertices, t.faces, t.euler, t.closed ? "yes" : "no",
           t.manifold ? "yes" : "no");
    CHECK_MSG(t.closed && t.manifold && t.components == 1, "%s: not a closed manifold", what);
    CHECK_MSG(t.euler == euler, "%s: Euler characteristic %ld, expected %ld", what, t.euler, euler);
    /* vertices on the level (linear interpolation: error O(h^2)) and normals
     * along -grad f (outward) */
    double worst = 0, dotmin = 1;
    for (size_t v = 0; v < m->nverts; v++) {
        double x[3] = {m->xyz[3 * v], m->xyz[3 * v + 1], m->xyz[3 * v + 2]};
        worst = fmax(worst, fabs(f(x)));
        double g[3], e = 1e-6;
        for (int a = 0; a < 3; a++) {
            double xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]};
            xp[a] += e;
            xm[a] -= e;
            g[a] = (f(xp) - f(xm)) / (2 * e);
        }
        double gn = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        double dot = -(g[0] * m->normal[3 * v] + g[1] * m->normal[3 * v + 1] +
                       g[2] * m->normal[3 * v + 2]) / gn;
        dotmin = fmin(dotmin, dot);
    }
    printf("%s: largest |f| at a vertex %.2e, smallest normal . (-grad f) %.3f\n", what, worst,
           dotmin);
    CHECK_MSG(worst < 1e-3, "%s: vertices off the surface by %g", what, worst);
    CHECK_MSG(dotmin > 0.9, "%s: a normal points the wrong way (%.3f)", what, dotmin);
    /* triangles oriented outward: (b - a) x (c - a) along the vertex normals */
    size_t wrong = 0;
    for (size_t k = 0; k < m->ntris; k++) {
        const int32_t *tr = &m->tri[3 * k];
        const float *A = &m->xyz[3 * tr[0]], *B = &m->xyz[3 * tr[1]], *Cc = &m->xyz[3 * tr[2]];
        double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
        double w[3] = {Cc[0] - A[0], Cc[1] - A[1], Cc[2] - A[2]};
        double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                       u[0] * w[1] - u[1] * w[0]};
        double s = 0;
        for (int a = 0; a < 3; a++)
            s += n[a] * (m->normal[3 * tr[0] + a] + m->normal[3 * tr[1] + a] +
                         m->normal[3 * tr[2] + a]);
        wrong += s < 0;
    }
    CHECK_MSG(wrong == 0, "%s: %zu of %zu triangles face inward", what, wrong, m->ntris);
}

static void test_extraction(void)
{
    const double h = 0.01;
    field_fn fns[2] = {sphere_fn, torus_fn};
    const char *names[2] = {"sphere", "torus"};
    const long euler[2] = {2, 0};
    for (int k = 0; k < 2; k++) {
        for (int narrow = 0; narrow < 2; narrow++) {
            grid_field g;
            CHECK_OK(sample(&g, fns[k], h, -20, 20, narrow ? 2.5 * h : 0));
            mf_mesh m1, m2;
            mf_mesh_init(&m1);
            mf_mesh_init(&m2);
            omp_set_num_threads(1);
            CHECK_OK(ls_mesh_extract(&g.b, g.nb, NULL, g.v, NULL, h, &m1));
            omp_set_num_threads(2);
            CHECK_OK(ls_mesh_extract(&g.b, g.nb, NULL, g.v, NULL, h, &m2));
            char what[64];
            snprintf(what, sizeof what, "%s, %s", names[k],
                     narrow ? "bricks near the surface only" : "all bricks");
            check_mesh(&m1, fns[k], euler[k], what);
            CHECK_MSG(m1.nverts == m2.nverts && m1.ntris == m2.ntris &&
                          !memcmp(m1.xyz, m2.xyz, 3 * m1.nverts * sizeof(float)) &&
                          !memcmp(m1.tri, m2.tri, 3 * m1.ntris * sizeof(int32_t)),
                      "%s: the mesh depends on the thread count", what);
            mf_mesh_free(&m1);
            mf_mesh_free(&m2);
            grid_free(&g);
        }
    }
}

static bool file_contains(const char *path, const char *text)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return false;
    static char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return strstr(buf, text) != NULL;
}

static void test_files(void)
{
    char dir[] = "/tmp/mpsflow-test-mesh-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    grid_field g;
    CHECK_OK(sample(&g, sphere_fn, 0.01, -20, 20, 0.025));
    mf_mesh m;
    mf_mesh_init(&m);
    CHECK_OK(ls_mesh_extract(&g.b, g.nb, NULL, g.v, NULL, 0.01, &m));
    grid_free(&g);
    m.time = 0.25;
    CHECK_OK(mf_mesh_write_frame(dir, "surface", 3, &m, true, true));
    m.time = 0.5;
    CHECK_OK(mf_mesh_write_frame(dir, "surface", 7, &m, true, false));
    char path[600];
    /* PLY: the header Blender's importer expects, and a byte-exact round trip */
    snprintf(path, sizeof path, "%s/surface_000003.ply", dir);
    CHECK(file_contains(path, "format binary_little_endian 1.0"));
    CHECK(file_contains(path, "property list uchar int vertex_indices"));
    CHECK(file_contains(path, "property float nx"));
    mf_mesh r;
    mf_mesh_init(&r);
    CHECK_OK(mf_mesh_read_ply(path, &r));
    CHECK(r.nverts == m.nverts && r.ntris == m.ntris);
    if (r.nverts == m.nverts && r.ntris == m.ntris) {
        CHECK(!memcmp(r.xyz, m.xyz, 3 * m.nverts * sizeof(float)));
        CHECK(!memcmp(r.normal, m.normal, 3 * m.nverts * sizeof(float)));
        CHECK(!memcmp(r.tri, m.tri, 3 * m.ntris * sizeof(int32_t)));
    }
    /* OBJ: one v, vn per vertex and one f per triangle, 1-based */
    snprintf(path, sizeof path, "%s/surface_000003.obj", dir);
    FILE *f = fopen(path, "r");
    CHECK(f != NULL);
    size_t nv = 0, nn = 0, nf = 0;
    long maxidx = 0;
    char line[256];
    while (f && fgets(line, sizeof line, f)) {
        long a, b, c;
        if (!strncmp(line, "v ", 2))
            nv++;
        else if (!strncmp(line, "vn ", 3))
            nn++;
        else if (sscanf(line, "f %ld//%*d %ld//%*d %ld//%*d", &a, &b, &c) == 3) {
            nf++;
            maxidx = a > maxidx ? a : maxidx;
            CHECK(a >= 1 && b >= 1 && c >= 1);
        }
    }
    if (f)
        fclose(f);
    CHECK(nv == m.nverts && nn == m.nverts && nf == m.ntris && maxidx <= (long)m.nverts);
    snprintf(path, sizeof path, "%s/surface_000007.obj", dir);
    CHECK(access(path, F_OK) != 0); /* writeOBJ no */
    /* the index: both frames, in time order, pointing at the HDF5 copies */
    snprintf(path, sizeof path, "%s/surface.xdmf", dir);
    CHECK(file_contains(path, "surface_000003.h5:/Triangles"));
    CHECK(file_contains(path, "surface_000007.h5:/Vertices"));
    CHECK(file_contains(path, "<Time Value=\"0.25\"/>"));
    char expect[128];
    snprintf(expect, sizeof expect, "NumberOfElements=\"%zu\"", m.ntris);
    CHECK(file_contains(path, expect));
    CHECK(mf_mesh_last_index(dir, "surface") == 7);
    /* a truncated PLY */
    snprintf(path, sizeof path, "%s/surface_000003.ply", dir);
    FILE *pf = fopen(path, "r+b");
    CHECK(pf != NULL);
    if (pf) {
        fseek(pf, 0, SEEK_END);
        long size = ftell(pf);
        fclose(pf);
        CHECK(truncate(path, size / 2) == 0);
    }
    int rc = mf_mesh_read_ply(path, &r);
    printf("truncated PLY: %s\n", mf_error_message());
    CHECK(rc == MF_ERR_INPUT && strstr(mf_error_message(), "surface_000003.ply"));
    mf_error_clear();
    rc = mf_mesh_write_ply("/nonexistent-folder/x.ply", &m);
    printf("unwritable PLY: %s\n", mf_error_message());
    CHECK(rc == MF_ERR_IO && strstr(mf_error_message(), "/nonexistent-folder/x.ply"));
    mf_error_clear();
    mf_mesh_free(&r);
    mf_mesh_free(&m);
    if (!getenv("MF_TEST_KEEP")) {
        char cmd[700];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        CHECK(system(cmd) == 0);
    } else {
        printf("kept %s\n", dir);
    }
}

int main(void)
{
    test_extraction();
    test_files();
    return mf_test_summary("mesh");
}
