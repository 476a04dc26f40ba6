/* mf_mesh_writer.h: surface meshes on disk, for renderers and for ParaView.
 *
 * (Named mf_mesh_writer.h, not mf_mesh.h: core/output/mf_mesh.h holds the mesh
 * type, and two headers of one name on the include path would shadow each
 * other.)
 *
 * One frame of a surface is written as
 *   <dir>/<prefix>_NNNNNN.ply   binary little-endian PLY: vertex x y z nx ny nz
 *                               (float), face "list uchar int vertex_indices";
 *                               what Blender, MeshLab and ParaView import
 *   <dir>/<prefix>_NNNNNN.obj   Wavefront OBJ (v, vn, f a//a b//b c//c)
 *   <dir>/<prefix>_NNNNNN.h5    HDF5: /Vertices (N x 3 float), /Normals
 *                               (N x 3 float), /Triangles (M x 3 int), attribute
 *                               Time: what the XDMF index points at
 *   <dir>/<prefix>.xdmf         the index, a time series ParaView opens next
 *                               to output/particles.xdmf
 * XDMF cannot point into a PLY file (its faces are 13-byte records), hence
 * the small HDF5 copy. Every file goes through "<name>.tmp" and a rename.
 * NNNNNN is the index of the particle snapshot the frame was made from.
 *
 * All functions return 0 or a negative mf_error status naming the file. */
#ifndef MF_MESH_WRITER_H
#define MF_MESH_WRITER_H

#include <stdbool.h>

#include "mf_mesh.h"

int mf_mesh_write_ply(const char *path, const mf_mesh *m);
int mf_mesh_write_obj(const char *path, const mf_mesh *m);
int mf_mesh_write_h5(const char *path, const mf_mesh *m);

/* Read a binary little-endian PLY with float x y z (optionally nx ny nz)
 * and triangle faces "list uchar int|uint" (what mf_mesh_write_ply writes,
 * and what most tools write). *m must be initialised (mf_mesh_init). */
int mf_mesh_read_ply(const char *path, mf_mesh *m);

/* Write the frame's files (PLY and OBJ as asked, the HDF5 copy always) and
 * rebuild the index <dir>/<prefix>.xdmf. Creates dir if needed. */
int mf_mesh_write_frame(const char *dir, const char *prefix, int index, const mf_mesh *m,
                        bool ply, bool obj);
/* The frame's files only (several ranks writing frames: one indexes them). */
int mf_mesh_write_frame_files(const char *dir, const char *prefix, int index, const mf_mesh *m,
                              bool ply, bool obj);

/* Rebuild <dir>/<prefix>.xdmf from the <prefix>_NNNNNN.h5 files in dir,
 * in time order (a frame whose time repeats an earlier one of a higher index
 * replaces it); frames without triangles are left out. */
int mf_mesh_write_xdmf_index(const char *dir, const char *prefix);

/* Highest NNNNNN of the <prefix>_NNNNNN.h5 files in dir, -1 if none. */
int mf_mesh_last_index(const char *dir, const char *prefix);

#endif
