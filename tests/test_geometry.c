/* test_geometry.c: polygon files into particles (core/scene/mf_trimesh.h,
 * io/mesh/mf_mesh_import.h).
 *
 * - mesh checks on meshes built here: a cube is closed with volume 1;
 *   degenerate triangles go; a turned face is turned back; an open box has
 *   open edges; three triangles on one edge are non-manifold; a Moebius strip
 *   has no consistent winding; winding numbers inside and outside;
 * - files written here (OBJ, ASCII and binary STL) read through assimp: the
 *   same 8 vertices and 12 triangles; missing, empty, garbage and
 *   point-only files give errors naming the file;
 * - walls: a closed box mesh with `side inside` makes exactly the wall layer
 *   of the equivalent wall box (3-D, and 2-D from a box extruded across
 *   z = 0); every point of a tilted plane within l0 behind it is a wall
 *   particle, and every wall particle lies within sqrt(3) l0 of it
 *   and behind it, dummies within [l0, 3 l0); about 1/l0^2 per layer; a
 *   tank whose faces are off the lattice has no dummy particle next to the
 *   fluid (the lattice points at its edges are walls though more than l0
 *   deep);
 * - a sphere filled with fluid: the count is its volume / l0^3 within 2%,
 *   every particle inside; the same sphere as a wall around the fluid leaves
 *   no two particles closer than l0/2;
 * - a plate obstacle (open, side both): a slab symmetric about the plate;
 * - two meshes that meet share their lattice points (no overlap);
 * - units: a mesh in millimetres is an error that suggests `scale 0.001`,
 *   and with that scale the scene equals the one in metres;
 * - warnings for degenerate and turned triangles say what was done; a
 *   non-closed fluid mesh, `side inside` on an open one and a non-manifold
 *   fluid mesh are errors; a non-manifold wall is a warning. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_mesh_import.h"
#include "mf_scene.h"
#include "mf_walls.h"
#include "mf_test.h"
#include "mf_trimesh.h"

static char tmpdir[256];

/* ---- meshes built here --------------------------------------------------- */

static void mesh_box(mf_trimesh *m, const double mn[3], const double mx[3])
{
    for (int k = 0; k < 8; k++) {
        double x[3] = {k & 1 ? mx[0] : mn[0], k & 2 ? mx[1] : mn[1], k & 4 ? mx[2] : mn[2]};
        mf_trimesh_add_vertex(m, x);
    }
    /* Outward winding: (b - a) x (c - a) points out. */
    static const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int f = 0; f < 6; f++) {
        mf_trimesh_add_triangle(m, q[f][0], q[f][1], q[f][2]);
        mf_trimesh_add_triangle(m, q[f][0], q[f][2], q[f][3]);
    }
}

/* A latitude-longitude sphere, outward, closed (one vertex at each pole). */
static void mesh_sphere(mf_trimesh *m, const double c[3], double r, int nlat, int nlon)
{
    double x[3] = {c[0], c[1], c[2] + r};
    mf_trimesh_add_vertex(m, x);
    for (int i = 1; i < nlat; i++) {
        double th = M_PI * i / nlat;
        for (int j = 0; j < nlon; j++) {
            double ph = 2 * M_PI * j / nlon;
            double y[3] = {c[0] + r * sin(th) * cos(ph), c[1] + r * sin(th) * sin(ph),
                           c[2] + r * cos(th)};
            mf_trimesh_add_vertex(m, y);
        }
    }
    double s[3] = {c[0], c[1], c[2] - r};
    mf_trimesh_add_vertex(m, s);
    int south = 1 + (nlat - 1) * nlon;
#define RING(i, j) (1 + ((i) - 1) * nlon + ((j) % nlon))
    for (int j = 0; j < nlon; j++)
        mf_trimesh_add_triangle(m, 0, RING(1, j), RING(1, j + 1));
    for (int i = 1; i < nlat - 1; i++)
        for (int j = 0; j < nlon; j++) {
            mf_trimesh_add_triangle(m, RING(i, j), RING(i + 1, j), RING(i + 1, j + 1));
            mf_trimesh_add_triangle(m, RING(i, j), RING(i + 1, j + 1), RING(i, j + 1));
        }
    for (int j = 0; j < nlon; j++)
        mf_trimesh_add_triangle(m, RING(nlat - 1, j), south, RING(nlat - 1, j + 1));
#undef RING
}

static int write_obj(const char *path, const mf_trimesh *m, double scale)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "# written by test_geometry\no mesh\n");
    for (size_t v = 0; v < m->nverts; v++)
        fprintf(f, "v %.17g %.17g %.17g\n", scale * m->xyz[3 * v], scale * m->xyz[3 * v + 1],
                scale * m->xyz[3 * v + 2]);
    for (size_t t = 0; t < m->ntris; t++)
        fprintf(f, "f %d %d %d\n", m->tri[3 * t] + 1, m->tri[3 * t + 1] + 1,
                m->tri[3 * t + 2] + 1);
    return fclose(f);
}

static void face_normal(const mf_trimesh *m, size_t t, float n[3])
{
    const double *a = &m->xyz[3 * m->tri[3 * t]], *b = &m->xyz[3 * m->tri[3 * t + 1]],
                 *c = &m->xyz[3 * m->tri[3 * t + 2]];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double w[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                   u[0] * v[1] - u[1] * v[0]};
    double l = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (int k = 0; k < 3; k++)
        n[k] = (float)(w[k] / l);
}

static int write_stl_ascii(const char *path, const mf_trimesh *m)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "solid test\n");
    for (size_t t = 0; t < m->ntris; t++) {
        float n[3];
        face_normal(m, t, n);
        fprintf(f, " facet normal %g %g %g\n  outer loop\n", n[0], n[1], n[2]);
        for (int k = 0; k < 3; k++) {
            const double *x = &m->xyz[3 * m->tri[3 * t + k]];
            fprintf(f, "   vertex %.9g %.9g %.9g\n", x[0], x[1], x[2]);
        }
        fprintf(f, "  endloop\n endfacet\n");
    }
    fprintf(f, "endsolid test\n");
    return fclose(f);
}

static int write_stl_binary(const char *path, const mf_trimesh *m)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    char header[80] = "binary STL written by test_geometry";
    fwrite(header, 1, 80, f);
    uint32_t n = (uint32_t)m->ntris;
    fwrite(&n, 4, 1, f);
    for (size_t t = 0; t < m->ntris; t++) {
        float rec[12];
        face_normal(m, t, rec);
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                rec[3 + 3 * k + a] = (float)m->xyz[3 * m->tri[3 * t + k] + a];
        uint16_t attr = 0;
        fwrite(rec, sizeof rec, 1, f);
        fwrite(&attr, 2, 1, f);
    }
    return fclose(f);
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static void tmp_path(char *buf, size_t len, const char *name)
{
    snprintf(buf, len, "%s/constant/%s", tmpdir, name);
}

/* ---- scenes ---------------------------------------------------------------- */

typedef struct scene {
    mf_sim sim;
    mf_log log;
    FILE *log_file;
    mf_dict *geometry, *fluids;
    char log_text[16384];
    int rc;
    char error[2048];
} scene;

/* Build a scene from the text of constant/geometry (named as if it were the
 * file tmpdir/constant/geometry, so relative mesh names resolve there). */
static int scene_build(scene *s, const char *geometry_text)
{
    memset(s, 0, sizeof *s);
    static const char fluids[] = "water { rho 1000; nu 1e-6; } oil { rho 900; nu 1e-5; }";
    char name[512];
    snprintf(name, sizeof name, "%s/constant/geometry", tmpdir);
    s->log_file = tmpfile();
    mf_log_init(&s->log, s->log_file, MF_LOG_NORMAL);
    s->sim.log = &s->log;
    int rc = mf_dict_parse_string(geometry_text, strlen(geometry_text), name, &s->geometry);
    if (rc == 0)
        rc = mf_dict_parse_string(fluids, strlen(fluids), "fluids", &s->fluids);
    if (rc == 0)
        rc = mf_scene_read_fluids(s->fluids, &s->sim);
    s->sim.nfluids = 1; /* one fluid: no FluidId field */
    mf_trimesh_reader reader = mf_mesh_import_reader();
    if (rc == 0)
        rc = mf_scene_build_with_reader(s->geometry, 0, &s->sim, NULL, &reader);
    if (rc != 0) {
        snprintf(s->error, sizeof s->error, "%s", mf_error_message());
        mf_error_clear();
    }
    fflush(s->log_file);
    rewind(s->log_file);
    size_t n = fread(s->log_text, 1, sizeof s->log_text - 1, s->log_file);
    s->log_text[n] = '\0';
    s->rc = rc;
    return rc;
}

static void scene_free(scene *s)
{
    mf_particles_destroy(s->sim.p);
    mf_walls_destroy(s->sim.walls);
    mf_dict_free(s->geometry);
    mf_dict_free(s->fluids);
    if (s->log_file)
        fclose(s->log_file);
    memset(s, 0, sizeof *s);
}

static size_t count_kind(const mf_particles *p, int kind)
{
    size_t n = 0;
    for (size_t i = 0; i < p->n; i++)
        n += p->kind[i] == kind;
    return n;
}

/* Sorted positions of one kind (rounded to 1e-9 m) for set comparisons. */
typedef struct pt {
    long long q[3];
} pt;

static int cmp_pt(const void *a, const void *b)
{
    const pt *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->q[k] != y->q[k])
            return x->q[k] < y->q[k] ? -1 : 1;
    return 0;
}

static pt *points_of(const mf_particles *p, int kind, size_t *n)
{
    pt *v = malloc((p->n + 1) * sizeof *v);
    *n = 0;
    for (size_t i = 0; i < p->n; i++)
        if (p->kind[i] == kind) {
            for (int a = 0; a < 3; a++)
                v[*n].q[a] = llround(p->pos[3 * i + a] * 1e9);
            (*n)++;
        }
    qsort(v, *n, sizeof *v, cmp_pt);
    return v;
}

/* Every point of a found in b (both sorted). */
static bool subset(const pt *a, size_t na, const pt *b, size_t nb)
{
    for (size_t i = 0; i < na; i++)
        if (!bsearch(&a[i], b, nb, sizeof *b, cmp_pt))
            return false;
    return true;
}

/* ---- mesh checks ------------------------------------------------------------ */

static void test_checks(void)
{
    const double mn[3] = {0, 0, 0}, mx[3] = {1, 1, 1};
    mf_trimesh m;
    mf_trimesh_report r;

    mf_trimesh_init(&m);
    mesh_box(&m, mn, mx);
    CHECK_OK(mf_trimesh_check(&m, &r));
    CHECK(r.closed && r.orientable && r.nflipped == 0 && r.ndegenerate == 0);
    CHECK(r.ncomponents == 1);
    CHECK_NEAR(r.volume, 1.0, 1e-12);
    CHECK_NEAR(r.area, 6.0, 1e-12);
    const double in[3] = {0.3, 0.6, 0.2}, out[3] = {1.3, 0.6, 0.2};
    CHECK_NEAR(mf_trimesh_winding(&m, in), 1.0, 1e-9);
    CHECK_NEAR(mf_trimesh_winding(&m, out), 0.0, 1e-9);
    mf_trimesh_free(&m);

    /* One face (two triangles) turned, plus a zero-area triangle and one
     * with a repeated vertex. */
    mf_trimesh_init(&m);
    mesh_box(&m, mn, mx);
    for (int t = 0; t < 2; t++) {
        int32_t tmp = m.tri[3 * t + 1];
        m.tri[3 * t + 1] = m.tri[3 * t + 2];
        m.tri[3 * t + 2] = tmp;
    }
    double mid[3] = {0.5, 0, 0};
    mf_trimesh_add_vertex(&m, mid);
    mf_trimesh_add_triangle(&m, 0, 8, 1); /* collinear: zero area */
    mf_trimesh_add_triangle(&m, 2, 2, 3);
    CHECK_OK(mf_trimesh_check(&m, &r));
    CHECK(r.ndegenerate == 2);
    CHECK(r.nflipped == 2);
    CHECK(m.ntris == 12 && r.closed);
    CHECK_NEAR(r.volume, 1.0, 1e-12);
    mf_trimesh_free(&m);

    /* Open box: the top (two triangles) removed -> 4 open edges. */
    mf_trimesh_init(&m);
    mesh_box(&m, mn, mx);
    memmove(&m.tri[3 * 6], &m.tri[3 * 8], 3 * 4 * sizeof(int32_t)); /* drop face y = max */
    m.ntris -= 2;
    CHECK_OK(mf_trimesh_check(&m, &r));
    CHECK(!r.closed && r.nboundary == 4 && r.nnonmanifold == 0);
    CHECK_NEAR(r.at_boundary[1], 1.0, 1e-12);
    mf_trimesh_free(&m);

    /* Three triangles on one edge. */
    mf_trimesh_init(&m);
    double v[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
    for (int k = 0; k < 5; k++)
        mf_trimesh_add_vertex(&m, v[k]);
    mf_trimesh_add_triangle(&m, 0, 1, 2);
    mf_trimesh_add_triangle(&m, 1, 0, 3);
    mf_trimesh_add_triangle(&m, 0, 1, 4);
    CHECK_OK(mf_trimesh_check(&m, &r));
    CHECK(r.nnonmanifold == 1 && !r.closed);
    CHECK_NEAR(r.at_nonmanifold[0], 0.5, 1e-12);
    mf_trimesh_free(&m);

    /* A Moebius strip of 6 quads has no consistent winding. */
    mf_trimesh_init(&m);
    const int n = 6;
    for (int i = 0; i < n; i++) {
        double phi = 2 * M_PI * i / n, psi = 0.5 * phi;
        for (int s = -1; s <= 1; s += 2) {
            double rr = 1 + 0.3 * s * cos(psi);
            double p[3] = {rr * cos(phi), rr * sin(phi), 0.3 * s * sin(psi)};
            mf_trimesh_add_vertex(&m, p);
        }
    }
    for (int i = 0; i < n; i++) {
        int a = 2 * i, b = 2 * i + 1;
        int c = i + 1 < n ? 2 * (i + 1) : 1, d = i + 1 < n ? 2 * (i + 1) + 1 : 0; /* the twist */
        mf_trimesh_add_triangle(&m, a, c, b);
        mf_trimesh_add_triangle(&m, b, c, d);
    }
    CHECK_OK(mf_trimesh_check(&m, &r));
    CHECK(!r.orientable);
    mf_trimesh_free(&m);

    /* Welding: a cube whose triangles each have their own corners (STL). */
    mf_trimesh a, b;
    mf_trimesh_init(&a);
    mf_trimesh_init(&b);
    mesh_box(&a, mn, mx);
    for (size_t t = 0; t < a.ntris; t++) {
        for (int k = 0; k < 3; k++)
            mf_trimesh_add_vertex(&b, &a.xyz[3 * a.tri[3 * t + k]]);
        mf_trimesh_add_triangle(&b, (int32_t)(3 * t), (int32_t)(3 * t + 1), (int32_t)(3 * t + 2));
    }
    CHECK(b.nverts == 36);
    CHECK_OK(mf_trimesh_weld(&b, 1e-9));
    CHECK(b.nverts == 8 && b.ntris == 12);
    CHECK_OK(mf_trimesh_check(&b, &r));
    CHECK(r.closed && r.nflipped == 0);
    mf_trimesh_free(&a);
    mf_trimesh_free(&b);
}

/* ---- files through assimp ------------------------------------------------- */

static void test_files(void)
{
    const double mn[3] = {0, 0, 0}, mx[3] = {1, 2, 3};
    mf_trimesh box;
    mf_trimesh_init(&box);
    mesh_box(&box, mn, mx);
    char path[512];
    const char *names[] = {"cube.obj", "cube_ascii.stl", "cube_binary.stl"};
    tmp_path(path, sizeof path, names[0]);
    CHECK(write_obj(path, &box, 1) == 0);
    tmp_path(path, sizeof path, names[1]);
    CHECK(write_stl_ascii(path, &box) == 0);
    tmp_path(path, sizeof path, names[2]);
    CHECK(write_stl_binary(path, &box) == 0);
    for (int k = 0; k < 3; k++) {
        mf_trimesh m;
        mf_trimesh_init(&m);
        mf_trimesh_report r;
        tmp_path(path, sizeof path, names[k]);
        int rc = mf_mesh_import(path, &m);
        CHECK_MSG(rc == 0, "%s: %s", names[k], mf_error_message());
        mf_error_clear();
        CHECK_MSG(m.nverts == 8 && m.ntris == 12, "%s: %zu vertices, %zu triangles", names[k],
                  m.nverts, m.ntris);
        if (rc == 0) {
            CHECK_OK(mf_trimesh_check(&m, &r));
            CHECK(r.closed && r.nflipped == 0);
            CHECK_NEAR(r.volume, 6.0, 1e-5);
            CHECK_NEAR(r.max[2], 3.0, 1e-6);
        }
        mf_trimesh_free(&m);
    }
    mf_trimesh_free(&box);

    /* PLY, ASCII and binary (the header checked before assimp reads it). */
    static const char tetra_ascii[] =
        "ply\nformat ascii 1.0\ncomment a unit tetrahedron\nelement vertex 4\n"
        "property float x\nproperty float y\nproperty float z\n"
        "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    tmp_path(path, sizeof path, "tetra_ascii.ply");
    write_text(path, tetra_ascii);
    tmp_path(path, sizeof path, "tetra_binary.ply");
    {
        FILE *f = fopen(path, "wb");
        CHECK(f != NULL);
        if (f) {
            fputs("ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
                  "property float y\nproperty float z\nelement face 4\n"
                  "property list uchar int vertex_indices\nend_header\n", f);
            const float v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
            fwrite(v, sizeof v, 1, f);
            const int32_t faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
            for (int k = 0; k < 4; k++) {
                unsigned char three = 3;
                fwrite(&three, 1, 1, f);
                fwrite(faces[k], sizeof faces[k], 1, f);
            }
            fclose(f);
        }
    }
    const char *plys[] = {"tetra_ascii.ply", "tetra_binary.ply"};
    for (int k = 0; k < 2; k++) {
        mf_trimesh m;
        mf_trimesh_init(&m);
        tmp_path(path, sizeof path, plys[k]);
        int rc = mf_mesh_import(path, &m);
        CHECK_MSG(rc == 0 && m.nverts == 4 && m.ntris == 4, "%s: rc %d, %zu vertices, %zu "
                  "triangles: %s", plys[k], rc, m.nverts, m.ntris, mf_error_message());
        mf_error_clear();
        mf_trimesh_free(&m);
    }

    /* Bad files: each error names the file and says what is wrong. */
    struct {
        const char *name, *content, *expect;
    } bad[] = {
        {"missing.obj", NULL, "cannot open"},
        {"empty.stl", "", "empty"},
        {"garbage.stl", "this is not a polygon file\n", "assimp"},
        {"points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1\np 2\n", "no triangle"},
        /* assimp's PLY reader ran for minutes on this header (fuzz_mesh) */
        {"keyword.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproper yoltfat x\n"
                        "end_header\n0\n", "not a PLY header keyword"},
        {"counts.ply", "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\n"
                       "end_header\n0\n", "need at least"},
        {"noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\n", "without end_header"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        tmp_path(path, sizeof path, bad[k].name);
        if (bad[k].content)
            write_text(path, bad[k].content);
        mf_trimesh m;
        mf_trimesh_init(&m);
        int rc = mf_mesh_import(path, &m);
        const char *msg = mf_error_message();
        CHECK_MSG(rc != 0 && strstr(msg, bad[k].name) && strstr(msg, bad[k].expect),
                  "%s: rc %d, message '%s'", bad[k].name, rc, msg);
        mf_error_clear();
        mf_trimesh_free(&m);
    }
}

/* ---- walls ------------------------------------------------------------------- */

/* The box wall and the closed box mesh (side inside) enclosing the same
 * region: the same wall layer; the mesh's dummies are the box's, less the
 * corners beyond 3 l0 of the surface (layers by distance, not by axis). */
static void test_box_equivalence(int dim)
{
    const double mn[3] = {0, 0, dim == 3 ? 0 : -0.5}, mx[3] = {1, 0.6, dim == 3 ? 0.2 : 0.5};
    mf_trimesh box;
    mf_trimesh_init(&box);
    mesh_box(&box, mn, mx);
    char path[512];
    tmp_path(path, sizeof path, "tank.obj");
    CHECK(write_obj(path, &box, 1) == 0);
    mf_trimesh_free(&box);
    char text[1024];
    scene a, b;
    snprintf(text, sizeof text,
             "dimension %d; particleSpacing 0.025;"
             "walls { tank { type box; min (0 0 0); max (1 0.6 0.2); } }", dim);
    CHECK_OK(scene_build(&a, text));
    snprintf(text, sizeof text,
             "dimension %d; particleSpacing 0.025;"
             "walls { tank { type mesh; file \"tank.obj\"; side inside; } }", dim);
    CHECK_MSG(scene_build(&b, text) == 0, "%s", b.error);
    if (a.rc == 0 && b.rc == 0) {
        size_t nwa, nwb, nda, ndb;
        pt *wa = points_of(a.sim.p, MF_WALL, &nwa), *wb = points_of(b.sim.p, MF_WALL, &nwb);
        pt *da = points_of(a.sim.p, MF_DUMMY, &nda), *db = points_of(b.sim.p, MF_DUMMY, &ndb);
        CHECK_MSG(nwa == nwb && subset(wb, nwb, wa, nwa), "%d-D: wall %zu (box) vs %zu (mesh)",
                  dim, nwa, nwb);
        CHECK_MSG(subset(db, ndb, da, nda) && ndb <= nda && ndb > nda * 9 / 10,
                  "%d-D: dummy %zu (box) vs %zu (mesh)", dim, nda, ndb);
        printf("%d-D tank: box wall %zu wall + %zu dummy; mesh wall %zu + %zu\n", dim, nwa, nda,
               nwb, ndb);
        CHECK_OK(mf_scene_check_overlap(&b.sim));
        free(wa); free(wb); free(da); free(db);
    }
    scene_free(&a);
    scene_free(&b);
}

/* Faces off the lattice: a wall 0.97 l0 deep meets a floor 0.5 l0 deep,
 * and the lattice point at the edge between them lies 1.08 l0 from the
 * surface. It must still be a wall particle: no dummy particle may have a
 * lattice neighbour (26 of them) inside the tank. */
static void test_closed_shell(void)
{
    const double l0 = 0.025;
    const double mn[3] = {0, 0, 0.0123}, mx[3] = {0.9993, 0.6, 0.4123};
    mf_trimesh box;
    mf_trimesh_init(&box);
    mesh_box(&box, mn, mx);
    char path[512];
    tmp_path(path, sizeof path, "offset_tank.obj");
    CHECK(write_obj(path, &box, 1) == 0);
    mf_trimesh_free(&box);
    scene sc;
    CHECK_MSG(scene_build(&sc, "dimension 3; particleSpacing 0.025;"
                               "walls { tank { type mesh; file \"offset_tank.obj\"; side inside; } }")
                  == 0, "%s", sc.error);
    if (sc.rc == 0) {
        const mf_particles *p = sc.sim.p;
        size_t open = 0, deep = 0;
        for (size_t i = 0; i < p->n; i++) {
            if (p->kind[i] != MF_DUMMY)
                continue;
            for (int k = 0; k < 27; k++) {
                double y[3] = {p->pos[3 * i] + (k % 3 - 1) * l0,
                               p->pos[3 * i + 1] + (k / 3 % 3 - 1) * l0,
                               p->pos[3 * i + 2] + (k / 9 - 1) * l0};
                bool in = true;
                for (int a = 0; a < 3; a++)
                    in = in && y[a] > mn[a] && y[a] < mx[a];
                open += in;
            }
        }
        /* And every wall particle is within sqrt(3) l0 of the tank. */
        for (size_t i = 0; i < p->n; i++) {
            if (p->kind[i] != MF_WALL)
                continue;
            double d2 = 0;
            for (int a = 0; a < 3; a++) {
                double x = p->pos[3 * i + a], out = x < mn[a] ? mn[a] - x : (x > mx[a] ? x - mx[a] : 0);
                d2 += out * out;
            }
            deep += d2 > 3 * l0 * l0;
        }
        printf("offset tank: %zu wall, %zu dummy; %zu dummy-fluid contacts, %zu walls too deep\n",
               count_kind(p, MF_WALL), count_kind(p, MF_DUMMY), open, deep);
        CHECK(open == 0);
        CHECK(deep == 0);
        CHECK_OK(mf_scene_check_overlap(&sc.sim));
    }
    scene_free(&sc);
}

/* A large tilted square (open): layers behind it, by distance. */
static void test_tilted_plane(void)
{
    const double l0 = 0.02, ta = 0.5, pa = 0.7;
    mf_trimesh m;
    mf_trimesh_init(&m);
    /* Square of side 1 through o with normal n (0.5 rad from z, 0.7 rad
     * round it: along no lattice plane, so that the count per layer is not
     * aliased), wound so the normal is n; (u, v, n) right-handed. */
    const double n[3] = {sin(ta) * cos(pa), sin(ta) * sin(pa), cos(ta)};
    const double u[3] = {cos(ta) * cos(pa), cos(ta) * sin(pa), -sin(ta)};
    const double v[3] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2],
                         n[0] * u[1] - n[1] * u[0]};
    const double o[3] = {0.51, 0.503, 0.507};
    for (int k = 0; k < 4; k++) {
        double a = (k == 1 || k == 2) ? 0.5 : -0.5, b = k >= 2 ? 0.5 : -0.5;
        double x[3];
        for (int d = 0; d < 3; d++)
            x[d] = o[d] + a * u[d] + b * v[d];
        mf_trimesh_add_vertex(&m, x);
    }
    mf_trimesh_add_triangle(&m, 0, 1, 2);
    mf_trimesh_add_triangle(&m, 0, 2, 3);
    char path[512];
    tmp_path(path, sizeof path, "plane.obj");
    CHECK(write_obj(path, &m, 1) == 0);
    mf_trimesh_free(&m);
    scene sc;
    CHECK_MSG(scene_build(&sc, "dimension 3; particleSpacing 0.02;"
                               "walls { plane { type mesh; file \"plane.obj\"; } }") == 0,
              "%s", sc.error);
    if (sc.rc == 0) {
        const mf_particles *p = sc.sim.p;
        size_t bad = 0, nwall = 0, ndummy = 0, interior[3] = {0, 0, 0};
        for (size_t i = 0; i < p->n; i++) {
            double d[3], sd = 0, along_u = 0, along_v = 0;
            for (int k = 0; k < 3; k++) {
                d[k] = p->pos[3 * i + k] - o[k];
                sd += d[k] * n[k];
                along_u += d[k] * u[k];
                along_v += d[k] * v[k];
            }
            bool inner = fabs(along_u) < 0.5 && fabs(along_v) < 0.5; /* not near the rim */
            /* Layer 0 (within l0 behind the plane) is wall; deeper points are
             * dummy unless a lattice neighbour is on the fluid side (within
             * sqrt(3) l0 of the plane). */
            if (p->kind[i] == MF_WALL) {
                nwall++;
                if (inner && !(sd <= 1e-12 && sd > -sqrt(3.0) * l0))
                    bad++;
            } else {
                ndummy++;
                if (inner && !(sd <= -l0 + 1e-12 && sd > -3 * l0))
                    bad++;
            }
            if (inner)
                interior[sd > -l0 ? 0 : (sd > -2 * l0 ? 1 : 2)]++;
        }
        CHECK_MSG(bad == 0, "%zu particles in the wrong layer", bad);
        /* Each layer holds one point per lattice line crossing it: about
         * area / l0^2 * (the lines' density across the plane, 1/cos) ... the
         * lattice has 1/l0^3 points per volume, a layer l0 thick holds
         * area / l0^2 of them. */
        for (int k = 0; k < 3; k++)
            CHECK_MSG(fabs(interior[k] / (1.0 / (l0 * l0)) - 1) < 0.02,
                      "layer %d: %zu points for %g expected", k, interior[k], 1 / (l0 * l0));
        printf("tilted plane: %zu wall, %zu dummy; layers %zu %zu %zu (expected %g each)\n",
               nwall, ndummy, interior[0], interior[1], interior[2], 1 / (l0 * l0));
    }
    scene_free(&sc);
}

/* ---- fluid -------------------------------------------------------------------- */

static void test_sphere_fill(void)
{
    const double c[3] = {0.5013, 0.4987, 0.5}, r = 0.3, l0 = 0.02;
    mf_trimesh m;
    mf_trimesh_init(&m);
    mesh_sphere(&m, c, r, 48, 96);
    char path[512];
    tmp_path(path, sizeof path, "ball.obj");
    CHECK(write_obj(path, &m, 1) == 0);
    mf_trimesh_report rep;
    mf_trimesh copy;
    mf_trimesh_init(&copy);
    for (size_t v = 0; v < m.nverts; v++)
        mf_trimesh_add_vertex(&copy, &m.xyz[3 * v]);
    for (size_t t = 0; t < m.ntris; t++)
        mf_trimesh_add_triangle(&copy, m.tri[3 * t], m.tri[3 * t + 1], m.tri[3 * t + 2]);
    CHECK_OK(mf_trimesh_check(&copy, &rep));
    CHECK(rep.closed && rep.nflipped == 0 && rep.volume > 0);

    scene sc;
    CHECK_MSG(scene_build(&sc, "dimension 3; particleSpacing 0.02;"
                               "fluidBlocks { ball { type mesh; file \"ball.obj\"; fluid water; } }")
                  == 0, "%s", sc.error);
    if (sc.rc == 0) {
        const mf_particles *p = sc.sim.p;
        size_t outside = 0;
        for (size_t i = 0; i < p->n; i++)
            if (mf_trimesh_winding(&copy, &p->pos[3 * i]) < 0.5)
                outside++;
        double expected = rep.volume / (l0 * l0 * l0);
        printf("sphere fill: %zu particles, volume / l0^3 = %.0f (%+.2f%%)\n", p->n, expected,
               100 * (p->n / expected - 1));
        CHECK(outside == 0);
        CHECK(fabs(p->n / expected - 1) < 0.02);
        CHECK(count_kind(p, MF_FLUID) == p->n);
    }
    scene_free(&sc);

    /* The same surface as the fluid and as its container. */
    CHECK_MSG(scene_build(&sc, "dimension 3; particleSpacing 0.02;"
                               "fluidBlocks { ball { type mesh; file \"ball.obj\"; fluid water; } }"
                               "walls { shell { type mesh; file \"ball.obj\"; side inside; } }")
                  == 0, "%s", sc.error);
    if (sc.rc == 0) {
        CHECK_OK(mf_scene_check_overlap(&sc.sim));
        /* Every wall particle is outside (or on) the surface. */
        size_t wrong = 0;
        for (size_t i = 0; i < sc.sim.p->n; i++)
            if (sc.sim.p->kind[i] != MF_FLUID && mf_trimesh_winding(&copy, &sc.sim.p->pos[3 * i]) > 0.5 + 1e-6)
                wrong++;
        CHECK(wrong == 0);
    }
    scene_free(&sc);

    /* 2-D: a cylinder along z (the sphere's section is a disk too, but a
     * cylinder's section is exact): an extruded 64-gon of radius r. */
    mf_trimesh cyl;
    mf_trimesh_init(&cyl);
    const int ns = 64;
    for (int k = 0; k < ns; k++)
        for (int e = 0; e < 2; e++) {
            double x[3] = {c[0] + r * cos(2 * M_PI * k / ns), c[1] + r * sin(2 * M_PI * k / ns),
                           e ? 0.5 : -0.5};
            mf_trimesh_add_vertex(&cyl, x);
        }
    double cb[3] = {c[0], c[1], -0.5}, ct[3] = {c[0], c[1], 0.5};
    mf_trimesh_add_vertex(&cyl, cb);
    mf_trimesh_add_vertex(&cyl, ct);
    for (int k = 0; k < ns; k++) {
        int a = 2 * k, b = 2 * ((k + 1) % ns);
        mf_trimesh_add_triangle(&cyl, a, b, b + 1);
        mf_trimesh_add_triangle(&cyl, a, b + 1, a + 1);
        mf_trimesh_add_triangle(&cyl, 2 * ns, b, a);
        mf_trimesh_add_triangle(&cyl, 2 * ns + 1, a + 1, b + 1);
    }
    tmp_path(path, sizeof path, "cylinder.stl");
    CHECK(write_stl_binary(path, &cyl) == 0);
    CHECK_MSG(scene_build(&sc, "dimension 2; particleSpacing 0.02;"
                               "fluidBlocks { disk { type mesh; file \"cylinder.stl\"; fluid water; } }")
                  == 0, "%s", sc.error);
    if (sc.rc == 0) {
        double area = 0.5 * ns * r * r * sin(2 * M_PI / ns);
        double expected = area / (l0 * l0);
        printf("2-D disk fill: %zu particles, area / l0^2 = %.0f (%+.2f%%)\n", sc.sim.p->n,
               expected, 100 * (sc.sim.p->n / expected - 1));
        CHECK(fabs(sc.sim.p->n / expected - 1) < 0.03);
        size_t off = 0;
        for (size_t i = 0; i < sc.sim.p->n; i++)
            off += sc.sim.p->pos[3 * i + 2] != 0;
        CHECK(off == 0);
    }
    scene_free(&sc);
    mf_trimesh_free(&cyl);
    mf_trimesh_free(&copy);
    mf_trimesh_free(&m);
}

/* ---- obstacles, meeting meshes, units, warnings, errors -------------------- */

static void test_plate(void)
{
    /* A square plate in z = 0.5, tilted 30 degrees about x. */
    const double l0 = 0.02, a = M_PI / 6;
    const double n[3] = {0, -sin(a), cos(a)}, o[3] = {0.5, 0.5, 0.5};
    mf_trimesh m;
    mf_trimesh_init(&m);
    double corners[4][2] = {{-0.3, -0.3}, {0.3, -0.3}, {0.3, 0.3}, {-0.3, 0.3}};
    for (int k = 0; k < 4; k++) {
        double x[3] = {o[0] + corners[k][0], o[1] + corners[k][1] * cos(a),
                       o[2] + corners[k][1] * sin(a)};
        mf_trimesh_add_vertex(&m, x);
    }
    mf_trimesh_add_triangle(&m, 0, 1, 2);
    mf_trimesh_add_triangle(&m, 0, 2, 3);
    char path[512];
    tmp_path(path, sizeof path, "plate.obj");
    CHECK(write_obj(path, &m, 1) == 0);
    mf_trimesh_free(&m);
    scene sc;
    CHECK_MSG(scene_build(&sc, "dimension 3; particleSpacing 0.02;"
                               "obstacles { plate { type mesh; file \"plate.obj\"; thickness 0.08; } }")
                  == 0, "%s", sc.error);
    if (sc.rc == 0) {
        const mf_particles *p = sc.sim.p;
        size_t above = 0, below = 0, wrong = 0;
        const double t[3] = {0, cos(a), sin(a)}; /* in the plate, across x */
        for (size_t i = 0; i < p->n; i++) {
            double sd = 0, along = 0;
            for (int k = 0; k < 3; k++) {
                sd += (p->pos[3 * i + k] - o[k]) * n[k];
                along += (p->pos[3 * i + k] - o[k]) * t[k];
            }
            if (fabs(sd) >= 0.04)
                wrong++;
            /* Away from the rim, the outer l0 of the slab is wall, and so is
             * what touches the fluid (within sqrt(3) l0 of the slab's face). */
            bool inner = fabs(p->pos[3 * i] - o[0]) < 0.3 && fabs(along) < 0.3;
            if (inner && p->kind[i] == MF_WALL && !(fabs(sd) > 0.04 - sqrt(3.0) * l0 - 1e-12))
                wrong++;
            if (inner && p->kind[i] == MF_DUMMY && !(fabs(sd) <= 0.04 - l0 + 1e-12))
                wrong++;
            above += sd > 0;
            below += sd < 0;
        }
        CHECK(wrong == 0);
        CHECK(p->n > 0 && fabs((double)above - (double)below) < 0.05 * p->n);
        printf("plate (side both, 0.08 m): %zu wall, %zu dummy; above %zu, below %zu\n",
               count_kind(p, MF_WALL), count_kind(p, MF_DUMMY), above, below);
        CHECK(strstr(sc.log_text, "side both") != NULL);
    }
    scene_free(&sc);
}

static void test_meeting_meshes(void)
{
    /* A floor and a side wall as two files that share an edge: an L. */
    mf_trimesh f, w;
    mf_trimesh_init(&f);
    mf_trimesh_init(&w);
    double fl[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
    double wl[4][3] = {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}};
    for (int k = 0; k < 4; k++) {
        mf_trimesh_add_vertex(&f, fl[k]);
        mf_trimesh_add_vertex(&w, wl[k]);
    }
    /* Normals into the fluid: +y for the floor, +x for the wall. */
    mf_trimesh_add_triangle(&f, 0, 2, 1);
    mf_trimesh_add_triangle(&f, 0, 3, 2);
    mf_trimesh_add_triangle(&w, 0, 2, 1);
    mf_trimesh_add_triangle(&w, 0, 3, 2);
    char path[512];
    tmp_path(path, sizeof path, "floor.obj");
    CHECK(write_obj(path, &f, 1) == 0);
    tmp_path(path, sizeof path, "side.obj");
    CHECK(write_obj(path, &w, 1) == 0);
    mf_trimesh_free(&f);
    mf_trimesh_free(&w);
    scene sc;
    CHECK_MSG(scene_build(&sc, "dimension 3; particleSpacing 0.05;"
                               "walls { floor { type mesh; file \"floor.obj\"; }"
                               "        side  { type mesh; file \"side.obj\"; } }") == 0,
              "%s", sc.error);
    if (sc.rc == 0) {
        CHECK_OK(mf_scene_check_overlap(&sc.sim));
        /* Nothing on the fluid side (x > 0 and y > 0). */
        size_t inside = 0;
        for (size_t i = 0; i < sc.sim.p->n; i++)
            inside += sc.sim.p->pos[3 * i] > 0 && sc.sim.p->pos[3 * i + 1] > 0;
        CHECK(inside == 0);
        CHECK(sc.sim.p->n > 0);
    }
    scene_free(&sc);
}

static void test_units(void)
{
    const double mn[3] = {0, 0, 0}, mx[3] = {1, 0.6, 0.4};
    mf_trimesh box;
    mf_trimesh_init(&box);
    mesh_box(&box, mn, mx);
    char path[512];
    tmp_path(path, sizeof path, "tank_mm.obj");
    CHECK(write_obj(path, &box, 1000) == 0);
    tmp_path(path, sizeof path, "tank_m.obj");
    CHECK(write_obj(path, &box, 1) == 0);
    mf_trimesh_free(&box);
    static const char head[] =
        "dimension 3; particleSpacing 0.05;"
        "fluidBlocks { column { type box; min (0 0 0); max (0.3 0.4 0.4); fluid water; } }";
    char text[1024];
    scene sc;
    snprintf(text, sizeof text, "%s walls { tank { type mesh; file \"tank_mm.obj\"; side inside; } }",
             head);
    CHECK(scene_build(&sc, text) != 0);
    CHECK_MSG(strstr(sc.error, "tank_mm.obj") && strstr(sc.error, "scale 0.001") &&
                  strstr(sc.error, "times the rest of the geometry") && strstr(sc.error, "geometry:1:"),
              "message: %s", sc.error);
    printf("units error: %s\n", sc.error);
    scene_free(&sc);
    snprintf(text, sizeof text,
             "%s walls { tank { type mesh; file \"tank_mm.obj\"; scale 0.001; side inside; } }", head);
    CHECK_MSG(scene_build(&sc, text) == 0, "%s", sc.error);
    scene ref;
    snprintf(text, sizeof text, "%s walls { tank { type mesh; file \"tank_m.obj\"; side inside; } }",
             head);
    CHECK_MSG(scene_build(&ref, text) == 0, "%s", ref.error);
    if (sc.rc == 0 && ref.rc == 0) {
        CHECK(sc.sim.p->n == ref.sim.p->n);
        size_t na, nb;
        pt *a = points_of(sc.sim.p, MF_WALL, &na), *b = points_of(ref.sim.p, MF_WALL, &nb);
        CHECK(na == nb && subset(a, na, b, nb));
        free(a);
        free(b);
    }
    scene_free(&sc);
    scene_free(&ref);
}

static void test_warnings_and_errors(void)
{
    const double mn[3] = {0.1, 0.1, 0.1}, mx[3] = {0.9, 0.9, 0.9};
    mf_trimesh m;
    mf_trimesh_init(&m);
    mesh_box(&m, mn, mx);
    int32_t tmp = m.tri[1]; /* turn one triangle */
    m.tri[1] = m.tri[2];
    m.tri[2] = tmp;
    double mid[3] = {0.5, 0.1, 0.1};
    mf_trimesh_add_vertex(&m, mid);
    mf_trimesh_add_triangle(&m, 0, 8, 1); /* zero area */
    char path[512];
    tmp_path(path, sizeof path, "flawed.obj");
    CHECK(write_obj(path, &m, 1) == 0);
    /* The same box, open (the last face dropped). */
    m.ntris = 10;
    tmp_path(path, sizeof path, "open.obj");
    CHECK(write_obj(path, &m, 1) == 0);
    mf_trimesh_free(&m);

    scene sc;
    CHECK_MSG(scene_build(&sc, "dimension 3; particleSpacing 0.05;"
                               "fluidBlocks { f { type mesh; file \"flawed.obj\"; fluid water; } }")
                  == 0, "%s", sc.error);
    CHECK_MSG(strstr(sc.log_text, "Warning") && strstr(sc.log_text, "removed 1 degenerate") &&
                  strstr(sc.log_text, "1 triangles were wound against") &&
                  strstr(sc.log_text, "flawed.obj"),
              "log: %s", sc.log_text);
    if (sc.rc == 0)
        CHECK(sc.sim.p->n == 16 * 16 * 16); /* 0.8 / 0.05 per axis */
    scene_free(&sc);

    struct {
        const char *geometry, *expect;
    } bad[] = {
        {"fluidBlocks { f { type mesh; file \"open.obj\"; fluid water; } }",
         "not a closed surface: 4 open edges"},
        {"walls { w { type mesh; file \"open.obj\"; side inside; } }", "needs a closed surface"},
        {"walls { w { type mesh; file \"nowhere.obj\"; } }", "triSurface/nowhere.obj"},
        {"walls { w { type mesh; file \"empty.stl\"; } }", "empty"},
        {"walls { w { type mesh; file \"open.obj\"; side insde; } }", "did you mean 'inside'"},
        {"walls { w { type mesh; fiel \"open.obj\"; } }", "did you mean 'file'"},
        {"obstacles { o { type cylinder; centre (0.5 0.5 0.5); } }", "needs a centre and a radius"},
        {"fluidBlocks { f { type mesh; file \"open.obj\"; fluid watr; } }", "did you mean"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char text[512];
        snprintf(text, sizeof text, "dimension 3; particleSpacing 0.05; %s", bad[k].geometry);
        int rc = scene_build(&sc, text);
        CHECK_MSG(rc != 0 && strstr(sc.error, bad[k].expect) && strstr(sc.error, "geometry:1:"),
                  "case %zu: rc %d, message '%s'", k, rc, sc.error);
        scene_free(&sc);
    }
    /* Two cubes that share one edge: that edge has four triangles. As a
     * fluid it is an error; as a wall (side normals) a warning. */
    mf_trimesh_init(&m);
    const double a0[3] = {0.1, 0.1, 0.1}, a1[3] = {0.5, 0.5, 0.5};
    const double b0[3] = {0.5, 0.5, 0.1}, b1[3] = {0.9, 0.9, 0.5};
    mf_trimesh cube;
    mf_trimesh_init(&cube);
    mesh_box(&cube, a0, a1);
    mf_trimesh other;
    mf_trimesh_init(&other);
    mesh_box(&other, b0, b1);
    for (size_t v = 0; v < cube.nverts; v++)
        mf_trimesh_add_vertex(&m, &cube.xyz[3 * v]);
    for (size_t v = 0; v < other.nverts; v++)
        mf_trimesh_add_vertex(&m, &other.xyz[3 * v]);
    for (size_t t = 0; t < cube.ntris; t++)
        mf_trimesh_add_triangle(&m, cube.tri[3 * t], cube.tri[3 * t + 1], cube.tri[3 * t + 2]);
    for (size_t t = 0; t < other.ntris; t++)
        mf_trimesh_add_triangle(&m, other.tri[3 * t] + 8, other.tri[3 * t + 1] + 8,
                                other.tri[3 * t + 2] + 8);
    tmp_path(path, sizeof path, "bowtie.stl");
    CHECK(write_stl_ascii(path, &m) == 0); /* the reader merges the shared corners */
    mf_trimesh_free(&m);
    mf_trimesh_free(&cube);
    mf_trimesh_free(&other);
    int rc = scene_build(&sc, "dimension 3; particleSpacing 0.05;"
                              "fluidBlocks { f { type mesh; file \"bowtie.stl\"; fluid water; } }");
    CHECK_MSG(rc != 0 && strstr(sc.error, "1 edges shared by more than two triangles") &&
                  strstr(sc.error, "(0.5 0.5 0.3)"),
              "message: %s", sc.error);
    scene_free(&sc);
    rc = scene_build(&sc, "dimension 3; particleSpacing 0.05;"
                          "walls { w { type mesh; file \"bowtie.stl\"; side normals; } }");
    CHECK_MSG(rc == 0 && strstr(sc.log_text, "Warning") &&
                  strstr(sc.log_text, "1 edges are shared by more than two triangles"),
              "rc %d, log: %s", rc, sc.log_text);
    scene_free(&sc);

    /* Without a reader (mf_scene_build) a mesh entry is an error, not a crash. */
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    static const char text[] = "dimension 3; particleSpacing 0.05; walls { w { type mesh; file \"open.obj\"; } }";
    mf_dict *g = NULL;
    CHECK_OK(mf_dict_parse_string(text, strlen(text), "geometry", &g));
    CHECK(mf_scene_build(g, 0, &sim, NULL) != 0 && strstr(mf_error_message(), "reader"));
    mf_error_clear();
    mf_particles_destroy(sim.p);
    mf_dict_free(g);
}


/* ---- solids: obstacles of every shape, prescribed motions, size warnings --- */

/* The particles of solid k (WallId k + 1). */
static size_t solid_particles(const scene *sc, size_t k, size_t *first)
{
    const mf_particles *p = sc->sim.p;
    const int f = sc->sim.walls->f_wall_id;
    size_t n = 0;
    *first = SIZE_MAX;
    for (size_t i = 0; f >= 0 && i < p->n; i++)
        if (mf_particles_fi(p, f)[i] == (int32_t)k + 1) {
            if (n++ == 0)
                *first = i;
        }
    return n;
}

static void test_solids(void)
{
    scene sc;
    /* A tank shaken sideways, a disk turning about its centre, a box on a
     * table of positions, a fixed sphere: 2-D. */
    const char *g =
        "dimension 2; particleSpacing 0.01;"
        "fluidBlocks { f { type box; min (0 0 0); max (0.4 0.1 0); fluid water; } }"
        "walls { tank { type box; min (0 0 0); max (1 0.5 0); open (ymax);"
        "  motion { type oscillating; amplitude (0.02 0 0); omega 3; } } }"
        "obstacles {"
        "  disk { type cylinder; centre (0.6 0.2 0); radius 0.05;"
        "         motion { type rotation; origin (0.6 0.2 0); omega 2; } }"
        "  block { type box; min (0.8 0 0); max (0.9 0.1 0);"
        "          motion { type table; displacement ((0 (0 0 0)) (1 (0.1 0.05 0))); } }"
        "  ball { type sphere; centre (0.6 0.4 0); radius 0.04; } }";
    CHECK_MSG(scene_build(&sc, g) == 0, "%s", sc.error);
    if (sc.rc != 0)
        return;
    mf_walls *ws = sc.sim.walls;
    mf_particles *p = sc.sim.p;
    CHECK(ws->n == 4 && ws->f_wall_id >= 0);
    CHECK(ws->w[0].shape == MF_SOLID_TANK && ws->w[1].shape == MF_SOLID_CYLINDER &&
          ws->w[2].shape == MF_SOLID_BOX && ws->w[3].shape == MF_SOLID_SPHERE);
    CHECK(mf_walls_any_moving(ws) && !mf_wall_moves(&ws->w[3]));
    /* Moving solids' particles carry their index; the block's 10 x 10 points
     * less the 4 x 4 deeper than its three layers. */
    size_t first[4], count[4];
    for (size_t k = 0; k < 4; k++)
        count[k] = solid_particles(&sc, k, &first[k]);
    CHECK_MSG(count[0] > 0 && count[1] > 0 && count[2] == 84 && count[3] == 0,
              "counts %zu %zu %zu %zu (a fixed solid is not tagged)", count[0], count[1],
              count[2], count[3]);
    double *x0 = malloc(3 * p->n * sizeof *x0);
    memcpy(x0, p->pos, 3 * p->n * sizeof *x0);
    const double t = 0.3;
    CHECK(mf_walls_advance(ws, p, 0, 0.1) == 0);
    CHECK(mf_walls_advance(ws, p, 0.1, t) == 0); /* in two steps: the moves compose */
    const int32_t *id = mf_particles_fi(p, ws->f_wall_id);
    double err_tank = 0, err_disk = 0, err_block = 0, err_v = 0, still = 0;
    for (size_t i = 0; i < p->n; i++) {
        const double *x = &p->pos[3 * i], *v = &p->vel[3 * i], *a = &x0[3 * i];
        if (id[i] == 1) { /* x = x0 + A sin(omega t), v = A omega cos(omega t) */
            err_tank = fmax(err_tank, fabs(x[0] - a[0] - 0.02 * sin(3 * t)) + fabs(x[1] - a[1]));
            err_v = fmax(err_v, fabs(v[0] - 0.06 * cos(3 * t)) + fabs(v[1]));
        } else if (id[i] == 2) { /* turned by omega t about the centre */
            const double rx = a[0] - 0.6, ry = a[1] - 0.2, c = cos(2 * t), s_ = sin(2 * t);
            const double ex = 0.6 + c * rx - s_ * ry, ey = 0.2 + s_ * rx + c * ry;
            err_disk = fmax(err_disk, hypot(x[0] - ex, x[1] - ey));
            err_v = fmax(err_v, hypot(v[0] + 2 * (x[1] - 0.2), v[1] - 2 * (x[0] - 0.6)));
        } else if (id[i] == 3) { /* linear in the table: (0.1 0.05) t */
            err_block = fmax(err_block, hypot(x[0] - a[0] - 0.1 * t, x[1] - a[1] - 0.05 * t));
            err_v = fmax(err_v, hypot(v[0] - 0.1, v[1] - 0.05));
        } else {
            still = fmax(still, hypot(x[0] - a[0], x[1] - a[1]));
        }
    }
    CHECK_MSG(err_tank < 1e-12 && err_disk < 1e-12 && err_block < 1e-12 && err_v < 1e-12 &&
                  still == 0,
              "moved: tank %g, disk %g, block %g, velocity %g, fixed and fluid %g", err_tank,
              err_disk, err_block, err_v, still);
    /* The watch's throughWall follows the solid: a point inside the moved
     * block is inside it, the block's old place is free. */
    int axis, side;
    const double inside[3] = {0.85 + 0.1 * t, 0.05 + 0.05 * t, 0};
    const double old[3] = {0.81, 0.01, 0};
    CHECK(mf_wall_passed(&ws->w[2], 0.01, 2, inside, &axis, &side));
    CHECK(!mf_wall_passed(&ws->w[2], 0.01, 2, old, &axis, &side));
    CHECK(mf_walls_max_speed(ws, p) > 0.1);
    free(x0);
    scene_free(&sc);

    /* A fluid block overlapping an obstacle is refused with both names. */
    mf_dict *geometry = NULL;
    const char *overlap =
        "dimension 2; particleSpacing 0.01;"
        "fluidBlocks { f { type box; min (0 0 0); max (0.4 0.2 0); fluid water; } }"
        "walls { tank { type box; min (0 0 0); max (1 0.5 0); open (ymax); } }"
        "obstacles { pillar { type cylinder; centre (0.2 0.1 0); radius 0.03; } }";
    CHECK_MSG(scene_build(&sc, overlap) == 0, "%s", sc.error);
    if (sc.rc == 0) {
        geometry = sc.geometry;
        int rc = mf_scene_check_start(geometry, &sc.sim);
        const char *msg = rc ? mf_error_message() : "";
        CHECK_MSG(rc != 0 && strstr(msg, "pillar") && strstr(msg, "fluid block 'f'") &&
                      strstr(msg, "geometry:1:"),
                  "rc %d: %s", rc, msg);
        mf_error_clear();
    }
    scene_free(&sc);

    /* The lattice snaps sizes: a 0.016 m step at l0 = 0.01 becomes 0.01 m,
     * a 0.25 m column at 0.02 m becomes 0.24 m: half a spacing or more is
     * said, naming the entry and its file:line; a 0.3 m block at 0.01 m is
     * exact and says nothing. */
    CHECK_MSG(scene_build(&sc, "dimension 2; particleSpacing 0.01;"
                               "fluidBlocks { f { type box; min (0 0 0); max (0.3 0.2 0); "
                               "fluid water; } }"
                               "walls { tank { type box; min (0 0 0); max (1 0.5 0); } }"
                               "obstacles { step { type box; min (0.5 0 0); max (0.516 0.1 0); } }")
                  == 0, "%s", sc.error);
    CHECK_MSG(strstr(sc.log_text, "Warning") && strstr(sc.log_text, "obstacle 'step'") &&
                  strstr(sc.log_text, "geometry:1:") && strstr(sc.log_text, "along x"),
              "log: %s", sc.log_text);
    CHECK_MSG(!strstr(sc.log_text, "fluid block 'f'"), "log: %s", sc.log_text);
    scene_free(&sc);

    /* The solid's record is the box its particles stand for: the tutorial
     * damBreakObstacle's block (0.024 x 0.048 m at x = 0.292) at l0 = 0.00487
     * is 4 x 9 particles, [0.292, 0.31148] x [0, 0.04383]. Fluid at rest
     * l0 beside the last wall column (x = 0.309045 + l0), even 0.93 l0 from
     * it (the throughWall that stopped the run at t = 0.445 s with the
     * asked box), is outside it; a point l0/2 past the particles' face is
     * inside it by more than l0/2 (docs/notes/mps.md). */
    const double l0b = 0.00487;
    CHECK_MSG(scene_build(&sc, "dimension 2; particleSpacing 0.00487;"
                               "fluidBlocks { f { type box; min (0 0 0); max (0.146 0.292 0); "
                               "fluid water; } }"
                               "walls { tank { type box; min (0 0 0); max (0.584 0.584 0); "
                               "open (ymax); } }"
                               "obstacles { block { type box; min (0.292 0 0); "
                               "max (0.316 0.048 0); } }")
                  == 0, "%s", sc.error);
    if (sc.rc == 0) {
        const mf_wall *b = &sc.sim.walls->w[1];
        CHECK_MSG(fabs(b->max[0] - (0.292 + 4 * l0b)) < 1e-12 &&
                      fabs(b->max[1] - 9 * l0b) < 1e-12 && b->min[0] == 0.292 &&
                      b->min[1] == 0,
                  "block record [%.17g %.17g] x [%.17g %.17g]", b->min[0], b->max[0],
                  b->min[1], b->max[1]);
        int ax, sd;
        const double last = 0.292 + 3.5 * l0b; /* the last wall column */
        const double rest[3] = {last + l0b, 0.0196, 0}, close[3] = {last + 0.927 * l0b, 0.0196, 0};
        const double top[3] = {0.30, 9 * l0b - 0.3 * l0b, 0};
        const double deep[3] = {0.292 + 3.4 * l0b, 0.0196, 0};
        CHECK(!mf_wall_passed(b, l0b, 2, rest, &ax, &sd));
        CHECK(!mf_wall_passed(b, l0b, 2, close, &ax, &sd));
        CHECK(!mf_wall_passed(b, l0b, 2, top, &ax, &sd));
        CHECK(mf_wall_passed(b, l0b, 2, deep, &ax, &sd));
        /* The tank's far wall (3 layers, 0.584 + 3 l0): fluid in its layers
         * went through it; fluid beyond them, outside before its step too,
         * came over its top (the splash at l0 0.00365, t = 0.535 s): the
         * watch lets it go. */
        const mf_wall *tank = &sc.sim.walls->w[0];
        CHECK(fabs(tank->thickness - 3 * l0b) < 1e-15);
        const double in_wall[3] = {0.584 + 2.9 * l0b, 0.5, 0};
        const double over[3] = {0.584 + 3.2 * l0b, 0.5838, 0};
        const double fall[3] = {0.1 * l0b, -0.1 * l0b, 0}, kick[3] = {3 * l0b, 0, 0};
        CHECK(mf_wall_passed(tank, l0b, 2, in_wall, &ax, &sd) && ax == 0 && sd == 1 &&
              !mf_wall_spilled(tank, l0b, in_wall, fall, ax, sd));
        CHECK(mf_wall_passed(tank, l0b, 2, over, &ax, &sd) && ax == 0 && sd == 1 &&
              mf_wall_spilled(tank, l0b, over, fall, ax, sd));
        /* ... but not one kicked through the wall in one step. */
        CHECK(!mf_wall_spilled(tank, l0b, over, kick, ax, sd));
    }
    scene_free(&sc);
    /* An exact box keeps its record as asked, bit for bit. */
    CHECK_MSG(scene_build(&sc, "dimension 2; particleSpacing 0.01;"
                               "fluidBlocks { f { type box; min (0 0 0); max (0.3 0.2 0); "
                               "fluid water; } }"
                               "walls { tank { type box; min (0 0 0); max (1 0.5 0); } }"
                               "obstacles { b { type box; min (0.5 0 0); max (0.7 0.3 0); } }")
                  == 0, "%s", sc.error);
    if (sc.rc == 0)
        CHECK(sc.sim.walls->w[1].max[0] == 0.7 && sc.sim.walls->w[1].max[1] == 0.3);
    scene_free(&sc);
    CHECK_MSG(scene_build(&sc, "dimension 2; particleSpacing 0.02;"
                               "fluidBlocks { f { type box; min (0 0 0); max (0.25 0.5 0); "
                               "fluid water; } }"
                               "walls { tank { type box; min (0 0 0); max (1 0.6 0); } }")
                  == 0, "%s", sc.error);
    CHECK_MSG(strstr(sc.log_text, "fluid block 'f' is 0.25 m along x") &&
                  strstr(sc.log_text, "makes it 0.24 m"),
              "log: %s", sc.log_text);
    scene_free(&sc);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/mpsflow-test-geometry-XXXXXX");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 1;
    }
    char sub[300];
    snprintf(sub, sizeof sub, "%s/constant", tmpdir);
    mkdir(sub, 0777);
    snprintf(sub, sizeof sub, "%s/constant/triSurface", tmpdir);
    mkdir(sub, 0777);

    test_checks();
    test_files();
    test_box_equivalence(3);
    test_box_equivalence(2);
    test_closed_shell();
    test_tilted_plane();
    test_sphere_fill();
    test_plate();
    test_meeting_meshes();
    test_units();
    test_warnings_and_errors();
    test_solids();

    if (!getenv("MF_TEST_KEEP")) {
        char cmd[400];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
        if (system(cmd) != 0)
            fprintf(stderr, "could not remove %s\n", tmpdir);
    } else {
        printf("kept %s\n", tmpdir);
    }
    return mf_test_summary("geometry");
}
