/* trimesh_internal.h: what core/scene/trimesh.c shares with core/scene/scene_mesh.c
 * (not installed, not for modules). */
#ifndef MF_TRIMESH_INTERNAL_H
#define MF_TRIMESH_INTERNAL_H

#include <math.h>

#include "mf_trimesh.h"

/* Feature of a triangle nearest to a point: its face, a vertex or an edge. */
enum {
    MF_FEAT_FACE = 0,
    MF_FEAT_VERT0 = 1, /* + k: vertex k */
    MF_FEAT_EDGE0 = 4  /* + k: edge from vertex k to vertex (k + 1) % 3 */
};

/* Angle-weighted pseudo-normals (Baerentzen & Aanaes 2005) of a mesh: one
 * per face (its unit normal), per triangle edge (the sum of the unit normals
 * of the faces that share the edge; one face on an open edge) and per vertex
 * (the incident unit face normals weighted by the face angle at it).
 * (x - c) . n of the feature nearest to x, whose nearest point is c, has the
 * sign of the side x is on. */
typedef struct mf_pseudonormals {
    double *face;   /* 3 * ntris */
    double *edge;   /* 9 * ntris: edge k of triangle t at 3 * (3 t + k) */
    double *vert;   /* 3 * nverts */
} mf_pseudonormals;

int mf_pseudonormals_build(const mf_trimesh *m, mf_pseudonormals *pn);
void mf_pseudonormals_free(mf_pseudonormals *pn);

static inline const double *mf_pseudonormal_of(const mf_pseudonormals *pn, const mf_trimesh *m,
                                               size_t t, int feature)
{
    if (feature == MF_FEAT_FACE)
        return &pn->face[3 * t];
    if (feature < MF_FEAT_EDGE0)
        return &pn->vert[3 * (size_t)m->tri[3 * t + (feature - MF_FEAT_VERT0)]];
    return &pn->edge[3 * (3 * t + (size_t)(feature - MF_FEAT_EDGE0))];
}

/* The point of triangle (a, b, c) nearest to p, and which feature it lies
 * on (Ericson, Real-Time Collision Detection, 2005, section 5.1.5). */
static inline int mf_closest_on_triangle(const double p[3], const double a[3], const double b[3],
                                         const double c[3], double q[3])
{
    double ab[3], ac[3], ap[3];
    for (int k = 0; k < 3; k++) {
        ab[k] = b[k] - a[k];
        ac[k] = c[k] - a[k];
        ap[k] = p[k] - a[k];
    }
#define DOT3(u, v) ((u)[0] * (v)[0] + (u)[1] * (v)[1] + (u)[2] * (v)[2])
    double d1 = DOT3(ab, ap), d2 = DOT3(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        for (int k = 0; k < 3; k++) q[k] = a[k];
        return MF_FEAT_VERT0;
    }
    double bp[3];
    for (int k = 0; k < 3; k++) bp[k] = p[k] - b[k];
    double d3 = DOT3(ab, bp), d4 = DOT3(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
        for (int k = 0; k < 3; k++) q[k] = b[k];
        return MF_FEAT_VERT0 + 1;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++) q[k] = a[k] + v * ab[k];
        return MF_FEAT_EDGE0; /* a-b */
    }
    double cp[3];
    for (int k = 0; k < 3; k++) cp[k] = p[k] - c[k];
    double d5 = DOT3(ab, cp), d6 = DOT3(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
        for (int k = 0; k < 3; k++) q[k] = c[k];
        return MF_FEAT_VERT0 + 2;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++) q[k] = a[k] + w * ac[k];
        return MF_FEAT_EDGE0 + 2; /* c-a */
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++) q[k] = b[k] + w * (c[k] - b[k]);
        return MF_FEAT_EDGE0 + 1; /* b-c */
    }
    double denom = 1.0 / (va + vb + vc);
    double v = vb * denom, w = vc * denom;
    for (int k = 0; k < 3; k++) q[k] = a[k] + ab[k] * v + ac[k] * w;
#undef DOT3
    return MF_FEAT_FACE;
}

#endif
