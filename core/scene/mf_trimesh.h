/* mf_trimesh.h: polygon geometry turned into particles.
 *
 * A triangle mesh read from a polygon file (OBJ, STL, PLY... through the
 * reader io/ hands the scene builder: io/mesh/mf_mesh_import.h) and what the
 * scene builder does with it. In constant/geometry, beside the boxes:
 *
 *   walls      { corridor { type mesh; file "corridor.obj"; side inside;
 *                           wallLayers 1; dummyLayers 2; } }
 *   fluidBlocks { tank    { type mesh; file "tank.stl"; fluid water; } }
 *   obstacles  { plate    { type mesh; file "plate.obj"; } }   // side both
 *
 * `file` is relative to the folder of the dictionary that names it
 * (constant/), then to constant/triSurface/ (OpenFOAM's place for surfaces).
 * `scale` multiplies the coordinates (0.001 for a file in millimetres).
 *
 * Particles sit on the case's lattice x = (i + 1/2) l0 on every axis (z = 0
 * in 2-D), the lattice of a fluid block whose corner is a multiple of l0.
 * A lattice point on the solid side of a surface, at a distance d from it,
 * is in layer floor(d / l0): layers [0, wallLayers) are MF_WALL (in the
 * pressure equation), the next dummyLayers MF_DUMMY (number density only).
 * A plane surface therefore gets one particle per layer on each lattice
 * line that crosses it, as a wall box does. A solid point with a lattice
 * neighbour (26 in 3-D, 8 in 2-D) on the fluid side is MF_WALL whatever its
 * depth: where two faces meet off the lattice the point at their edge can
 * lie more than l0 from both, and a dummy particle there, with no pressure,
 * is a hole the fluid leaks through. (On a plane tilted against the lattice
 * this makes the wall layer up to sqrt(3) l0 thick.)
 *
 * Which side is solid (`side`):
 *   normals  the fluid is on the side the face normals point to (the
 *            default for walls: the normals of a container drawn from the
 *            fluid's side point into the fluid);
 *   inside   the fluid is inside the closed surface (a tank or corridor
 *            drawn as a volume): layers outside it;
 *   outside  the fluid is outside the closed surface (a solid body): layers
 *            inside it (the default for a closed obstacle);
 *   both     a thin open surface (a plate) with fluid on both sides: the
 *            slab within thickness/2 of it is solid (the default for an open
 *            obstacle; thickness defaults to 2 (wallLayers + dummyLayers) l0).
 * inside and outside need a closed surface and do not care which way its
 * normals point (the signed volume says which way is out).
 *
 * Signs come from angle-weighted pseudo-normals (Baerentzen & Aanaes, "Signed
 * distance computation using the angle weighted pseudonormal", IEEE TVCG
 * 11(3), 2005): exact for a closed, consistently oriented surface. A fluid
 * mesh is filled by casting rays along a lattice axis (crossings counted with
 * the sign of the normal), near the surface by the same signed distance as
 * the walls, so a mesh used both as a fluid block and as a wall never puts
 * two particles on one lattice point.
 *
 * In 2-D the lattice lies in the plane z = 0 and the distance is that to
 * the 3-D triangles: a 2-D profile extruded across z = 0 gives the profile.
 *
 * Bad files: a missing, unreadable or empty file is an error; degenerate
 * (zero-area) triangles are removed with a warning; triangles wound against
 * their neighbours are turned, with a warning; an open or non-manifold
 * surface is an error where a side must be decided from it (inside,
 * outside, a fluid mesh), a warning otherwise; a mesh three hundred or more
 * times larger than the rest of the geometry (a file in millimetres) is an
 * error that suggests `scale`, unless `scale` is given.
 */
#ifndef MF_TRIMESH_H
#define MF_TRIMESH_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mf_dict.h"
#include "mf_sim.h"

/* ---- the mesh ------------------------------------------------------------- */

typedef struct mf_trimesh {
    char name[512];       /* the file it came from, for messages */
    size_t nverts, ntris;
    double *xyz;          /* 3 * nverts, m */
    int32_t *tri;         /* 3 * ntris: vertex indices; (b - a) x (c - a) is the normal */
    size_t cap_verts, cap_tris;
    size_t dropped;       /* primitives the reader skipped (points, lines) */
} mf_trimesh;

void mf_trimesh_init(mf_trimesh *m);
void mf_trimesh_free(mf_trimesh *m);
/* Room for nverts vertices and ntris triangles (contents kept). */
int mf_trimesh_reserve(mf_trimesh *m, size_t nverts, size_t ntris);
/* Append a vertex / a triangle (indices checked against nverts). */
int mf_trimesh_add_vertex(mf_trimesh *m, const double x[3]);
int mf_trimesh_add_triangle(mf_trimesh *m, int32_t a, int32_t b, int32_t c);

/* Merge vertices closer than tol (per coordinate), drop unreferenced ones,
 * and renumber: STL stores every triangle's corners separately, and OBJ
 * corners with different normals are different vertices to a reader. */
int mf_trimesh_weld(mf_trimesh *m, double tol);
/* Multiply every coordinate by s. */
void mf_trimesh_scale(mf_trimesh *m, double s);
void mf_trimesh_bounds(const mf_trimesh *m, double min[3], double max[3]);

/* What mf_trimesh_check found and did. */
typedef struct mf_trimesh_report {
    size_t ndegenerate;          /* zero-area triangles removed */
    size_t nboundary;            /* edges of one triangle: the surface is open there */
    size_t nnonmanifold;         /* edges of three or more triangles */
    size_t nflipped;             /* triangles turned to agree with their neighbours */
    bool orientable;             /* false: no consistent winding exists (a Moebius strip) */
    bool closed;                 /* no boundary edge, no non-manifold edge */
    size_t ncomponents;          /* connected pieces */
    double area;                 /* m^2 */
    double volume;               /* signed, by the divergence theorem (closed meshes) */
    double min[3], max[3];
    double at_degenerate[3], at_boundary[3], at_nonmanifold[3]; /* first of each, for messages */
} mf_trimesh_report;

/* Remove degenerate triangles (repeated vertices, or area below 1e-10 of
 * the longest edge squared), turn triangles so that each shared edge is
 * walked in opposite directions by its two triangles (within each connected
 * piece, the first triangle's winding wins), and measure. Empty afterwards
 * (every triangle degenerate) is MF_ERR_INPUT. */
int mf_trimesh_check(mf_trimesh *m, mf_trimesh_report *r);

/* The solid a closed, outward-wound mesh bounds (core/scene/trimesh_mass.c,
 * by the divergence theorem: Eberly 2002, Mirtich 1996): its signed volume
 * (negative: wound inward), its centroid and its inertia tensor about the
 * centroid per unit mass (row-major, m^2), exact for the polyhedron. The
 * mesh is not checked: mf_trimesh_check says whether it is closed. */
void mf_trimesh_mass(const mf_trimesh *m, double *volume, double centre[3], double I[9]);

/* Generalized winding number of point x (van Oosterom & Strackee's solid
 * angle of each triangle over 4 pi): +1 inside a closed outward-wound
 * surface, -1 inward-wound, 0 outside; fractional for open surfaces. */
double mf_trimesh_winding(const mf_trimesh *m, const double x[3]);

/* ---- reading files: the scene builder asks the driver's reader ---------- */

typedef struct mf_trimesh_reader {
    /* Read `file` as written in the case into *out (initialised by the
     * caller); `relative_to` is the dictionary file that names it. */
    int (*read)(void *ctx, const char *file, const char *relative_to, mf_trimesh *out);
    void *ctx;
} mf_trimesh_reader;

/* ---- scene building (core/scene/scene_mesh.c, called by core/scene/scene.c) --------- */

/* The meshes of one scene: read, scaled and checked up front so that each
 * can be compared with the rest of the geometry (units), and the lattice
 * points already taken by mesh walls (two meshes that meet share them). */
typedef struct mf_scene_meshes mf_scene_meshes;

/* True when the entry is `type mesh;`. */
bool mf_scene_entry_is_mesh(const mf_dict *entry);

/* Read every `type mesh` entry of fluidBlocks, walls and obstacles of the
 * geometry. With no such entry *out is NULL (no reader needed). */
int mf_scene_meshes_create(const mf_dict *geometry, const mf_trimesh_reader *reader, int dim,
                           double l0, mf_log *log, mf_scene_meshes **out);
void mf_scene_meshes_destroy(mf_scene_meshes *sm);
/* Particles the meshes will make on the lattice (for the memory budget):
 * a fluid mesh its bounding box's volume over l0^dim, a wall or obstacle
 * its area (3-D) or its bounding box's perimeter (2-D) times its layers. */
double mf_scene_meshes_estimate(const mf_scene_meshes *sm);

/* A fluid block `type mesh`: fill the closed surface with fluid particles
 * (fluid_field: the FluidId field or -1). */
int mf_scene_mesh_fluid(mf_scene_meshes *sm, mf_sim *sim, const char *name, const mf_dict *d,
                        int fluid_field, mf_dict *resolved);
/* A wall (obstacle = false) or an obstacle (true) `type mesh`. */
int mf_scene_mesh_wall(mf_scene_meshes *sm, mf_sim *sim, const char *name, const mf_dict *d,
                       bool obstacle, mf_dict *resolved);

#pragma GCC visibility pop
#endif
