/* mf_mesh.h: a triangle mesh, what a surface reconstructor (kind surface,
 * mf_modules.h) hands back: vertices with unit normals, and triangles whose
 * vertex order is counter-clockwise seen from outside (the normal of
 * (b - a) x (c - a) points out of the fluid), the convention of PLY, OBJ
 * and every renderer.
 *
 * Single precision for positions and normals: what PLY files for renderers
 * hold, and half the memory of a surface of millions of triangles. Writers
 * live in io/ (mf_mesh_writer.h); core only holds the data.
 *
 * The functions are static inline so that core needs no new object file. */
#ifndef MF_MESH_H
#define MF_MESH_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"

typedef struct mf_mesh {
    size_t nverts;
    size_t ntris;
    float *xyz;     /* 3 * nverts: positions, m */
    float *normal;  /* 3 * nverts: unit outward normals */
    int32_t *tri;   /* 3 * ntris: vertex indices */
    size_t cap_verts, cap_tris;
    double time;    /* the time of the particles it was built from */
} mf_mesh;

static inline void mf_mesh_init(mf_mesh *m)
{
    memset(m, 0, sizeof *m);
}

static inline void mf_mesh_free(mf_mesh *m)
{
    if (!m)
        return;
    free(m->xyz);
    free(m->normal);
    free(m->tri);
    mf_mesh_init(m);
}

/* Make room for nverts vertices and ntris triangles (contents kept). */
static inline int mf_mesh_reserve(mf_mesh *m, size_t nverts, size_t ntris)
{
    if (nverts > (size_t)INT32_MAX || ntris > SIZE_MAX / (3 * sizeof(int32_t)))
        return MF_ERROR(MF_ERR_MEMORY, "a mesh of %zu vertices and %zu triangles is too large",
                        nverts, ntris);
    if (nverts > m->cap_verts) {
        if (mf_resize(&m->xyz, 3 * nverts, sizeof *m->xyz))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu mesh vertices", nverts);
        if (mf_resize(&m->normal, 3 * nverts, sizeof *m->normal))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu mesh normals", nverts);
        m->cap_verts = nverts;
    }
    if (ntris > m->cap_tris) {
        if (mf_resize(&m->tri, 3 * ntris, sizeof *m->tri))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu mesh triangles", ntris);
        m->cap_tris = ntris;
    }
    return 0;
}

static inline size_t mf_mesh_memory(const mf_mesh *m)
{
    return m->cap_verts * 6 * sizeof(float) + m->cap_tris * 3 * sizeof(int32_t);
}

#pragma GCC visibility pop
#endif
