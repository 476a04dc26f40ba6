/* mf_mesh_import.h: polygon files (OBJ, STL and PLY, through Debian's
 * assimp; other formats are refused: some of assimp's readers crash on
 * broken files) into the plain triangle mesh of core/scene/mf_trimesh.h.
 *
 * Polygons are split into triangles; points and lines are counted in
 * mesh->dropped and left out; node transforms of formats that have them
 * are applied; corners at the same place are merged (STL repeats them for
 * every triangle). A missing, empty or unreadable file, a file with no
 * triangle, or one with a non-finite coordinate is MF_ERR_INPUT or
 * MF_ERR_IO with a message naming the file. */
#ifndef MF_MESH_IMPORT_H
#define MF_MESH_IMPORT_H

#include "mf_trimesh.h"

/* Polygon files larger than this are refused before they are read: 4 GiB
 * is tens of millions of triangles, beyond what a scene's lattice can use. */
#define MF_MESH_MAX_FILE_BYTES ((size_t)4 << 30)

/* Read the file at path into *out (initialised by the caller); only a
 * regular file, of at most MF_MESH_MAX_FILE_BYTES. */
int mf_mesh_import(const char *path, mf_trimesh *out);

/* A PLY file's header checked against the format's grammar and its element
 * counts against the file's size (ply_header.c), before assimp reads it:
 * assimp's PLY reader runs for minutes on some broken headers. */
int mf_ply_check_header(const char *path, size_t file_bytes);

/* The reader the scene builder takes: `file` as written in a case, tried
 * as it is when absolute, else in the folder of the dictionary that names
 * it (constant/), then in its triSurface/ subfolder (OpenFOAM's place). */
mf_trimesh_reader mf_mesh_import_reader(void);

#endif
