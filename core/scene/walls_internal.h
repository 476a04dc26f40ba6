/* walls_internal.h: what the files of the solids (walls*.c) share; not
 * installed. */
#ifndef MF_WALLS_INTERNAL_H
#define MF_WALLS_INTERNAL_H

#include "mf_trimesh.h"
#include "mf_walls.h"

/* Which side of a polygon surface the fluid is on (mf_trimesh.h: side). */
enum { MF_SIDE_NORMALS = 0, MF_SIDE_INSIDE, MF_SIDE_OUTSIDE, MF_SIDE_BOTH };

/* mf_wall_distance in the body frame. */
double mf_wall_body_distance(const mf_wall *w, const double xb[3], double nb[3]);

/* A polygon solid kept for the run (wall weight walls): its triangles in the
 * body frame, their pseudonormals, and the triangles near each cell of a
 * grid of cell size `cell` (the reach of the wall weight tables). */
int mf_wall_mesh_create(const mf_trimesh *m, int side, int out_sign, double half, double cell,
                        int dim, struct mf_wall_mesh **out);
void mf_wall_mesh_destroy(struct mf_wall_mesh *wm);
/* Its triangles (body frame), and mf_trimesh_check's report on a copy of
 * them (closed or not, open edges, signed volume). */
const mf_trimesh *mf_wall_mesh_surface(const struct mf_wall_mesh *wm);
int mf_wall_mesh_report(const struct mf_wall_mesh *wm, mf_trimesh_report *r);
/* The cell index again with another cell size; its current cell size. */
int mf_wall_mesh_index(struct mf_wall_mesh *wm, double cell);
double mf_wall_mesh_cell(const struct mf_wall_mesh *wm);
size_t mf_wall_mesh_memory(const struct mf_wall_mesh *wm);
/* Signed distance (fluid side positive) from body point xb, and the unit
 * normal into the fluid; +INFINITY with n zero beyond the grid's reach. */
double mf_wall_mesh_distance(const struct mf_wall_mesh *wm, const double xb[3], double n[3]);
/* The wall weight terms of the surface at xb (body frame): up to max terms. */
int mf_wall_mesh_terms(const struct mf_wall_mesh *wm, const mf_wall_tables *t,
                       const double xb[3], mf_wall_term *terms, int max);

#endif
