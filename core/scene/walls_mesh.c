/* walls_mesh.c: a polygon solid kept for the run (walls_internal.h): its
 * signed distance and its wall weight terms, from the triangles near the
 * point (a cell index built once in the body frame).
 *
 * Terms: the triangles within reach are gathered into planes (same normal
 * within 15 degrees, same offset within 2% of the reach). One plane: the
 * half-space behind it (a tank's face). Two or three planes at about right
 * angles (70 to 110 degrees): the union of their half-spaces where each lies
 * on the others' fluid side (a concave edge or corner, as a tank's), their
 * intersection where it lies on their solid side (a convex one, as an
 * obstacle's), the edge and corner tables of mf_wall_weight.h in a frame
 * made orthogonal. Anything else (a curved surface: many planes at small
 * angles; faces meeting at other angles): the tangent plane at the nearest
 * point, as curved analytic shapes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "trimesh_internal.h"
#include "walls_internal.h"

#define KEY_BITS 21
#define KEY_OFF (1L << (KEY_BITS - 1))

struct mf_wall_mesh {
    mf_trimesh m;
    mf_pseudonormals pn;
    int side, out_sign, dim;
    double half, cell;
    size_t nkeys;
    uint64_t *keys;   /* sorted cell keys */
    uint32_t *start;  /* nkeys + 1 offsets into tris */
    int32_t *tris;
};

static inline long cell_of(double x, double cell) { return (long)floor(x / cell); }

static inline uint64_t key_of(const long c[3])
{
    return (uint64_t)(c[0] + KEY_OFF) | (uint64_t)(c[1] + KEY_OFF) << KEY_BITS |
           (uint64_t)(c[2] + KEY_OFF) << (2 * KEY_BITS);
}

typedef struct pair {
    uint64_t key;
    int32_t tri;
} pair;

static int cmp_pair(const void *a, const void *b)
{
    const pair *p = a, *q = b;
    if (p->key != q->key)
        return p->key < q->key ? -1 : 1;
    return (p->tri > q->tri) - (p->tri < q->tri);
}

static const double *vert(const mf_trimesh *m, size_t t, int k)
{
    return &m->xyz[3 * (size_t)m->tri[3 * t + k]];
}

static double tri_distance(const mf_trimesh *m, size_t t, const double x[3], double q[3],
                           int *feature)
{
    *feature = mf_closest_on_triangle(x, vert(m, t, 0), vert(m, t, 1), vert(m, t, 2), q);
    double d2 = 0;
    for (int a = 0; a < 3; a++)
        d2 += (x[a] - q[a]) * (x[a] - q[a]);
    return sqrt(d2);
}

static int copy_mesh(const mf_trimesh *src, mf_trimesh *dst)
{
    mf_trimesh_init(dst);
    MF_CALL(mf_trimesh_reserve(dst, src->nverts, src->ntris));
    memcpy(dst->xyz, src->xyz, 3 * src->nverts * sizeof *dst->xyz);
    memcpy(dst->tri, src->tri, 3 * src->ntris * sizeof *dst->tri);
    dst->nverts = src->nverts;
    dst->ntris = src->ntris;
    snprintf(dst->name, sizeof dst->name, "%s", src->name);
    return 0;
}

/* Each triangle into every cell whose points may lie within `cell` of it:
 * the cell's centre within cell (1 + sqrt(3)/2) of the triangle. */
int mf_wall_mesh_index(struct mf_wall_mesh *wm, double cell)
{
    free(wm->keys);
    free(wm->start);
    free(wm->tris);
    wm->keys = NULL;
    wm->start = NULL;
    wm->tris = NULL;
    wm->nkeys = 0;
    wm->cell = cell;
    pair *pairs = NULL;
    size_t np = 0, cap = 0;
    int rc = 0;
    const double margin = cell * (1 + 0.5 * sqrt(3.0));
    for (size_t t = 0; rc == 0 && t < wm->m.ntris; t++) {
        long lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            double mn = INFINITY, mx = -INFINITY;
            for (int k = 0; k < 3; k++) {
                mn = fmin(mn, vert(&wm->m, t, k)[a]);
                mx = fmax(mx, vert(&wm->m, t, k)[a]);
            }
            if (wm->dim == 2 && a == 2) { /* the lattice lies in z = 0 */
                if (mn > cell || mx < -cell) {
                    lo[0] = 1; hi[0] = 0; /* no cell */
                }
                lo[2] = hi[2] = cell_of(0, cell);
                continue;
            }
            lo[a] = cell_of(mn - cell, cell);
            hi[a] = cell_of(mx + cell, cell);
            if (hi[a] - lo[a] > (1L << (KEY_BITS - 2)) || lo[a] < -KEY_OFF + 2 ||
                hi[a] > KEY_OFF - 2)
                rc = MF_ERROR(MF_ERR_INPUT, "%s: the mesh spans too many cells of %g m",
                              wm->m.name, cell);
        }
        for (long k = lo[2]; rc == 0 && k <= hi[2]; k++)
            for (long j = lo[1]; rc == 0 && j <= hi[1]; j++)
                for (long i = lo[0]; rc == 0 && i <= hi[0]; i++) {
                    const double c[3] = {(i + 0.5) * cell, (j + 0.5) * cell,
                                         wm->dim == 2 ? 0.0 : (k + 0.5) * cell};
                    double q[3];
                    int f;
                    if (tri_distance(&wm->m, t, c, q, &f) > margin)
                        continue;
                    if (np == cap) {
                        size_t nc = cap ? 2 * cap : 1024;
                        pair *g = realloc(pairs, nc * sizeof *g);
                        if (!g) {
                            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for a mesh's cell index");
                            break;
                        }
                        pairs = g;
                        cap = nc;
                    }
                    const long cc[3] = {i, j, k};
                    pairs[np++] = (pair){key_of(cc), (int32_t)t};
                }
    }
    if (rc == 0 && np > 1)
        qsort(pairs, np, sizeof *pairs, cmp_pair);
    if (rc == 0) {
        wm->tris = malloc((np ? np : 1) * sizeof *wm->tris);
        wm->keys = malloc((np ? np : 1) * sizeof *wm->keys);
        wm->start = malloc((np + 1) * sizeof *wm->start);
        if (!wm->tris || !wm->keys || !wm->start)
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for a mesh's cell index");
    }
    for (size_t k = 0; rc == 0 && k < np; k++) {
        if (k == 0 || pairs[k].key != pairs[k - 1].key) {
            wm->keys[wm->nkeys] = pairs[k].key;
            wm->start[wm->nkeys++] = (uint32_t)k;
        }
        wm->tris[k] = pairs[k].tri;
    }
    if (rc == 0)
        wm->start[wm->nkeys] = (uint32_t)np;
    free(pairs);
    return rc;
}

double mf_wall_mesh_cell(const struct mf_wall_mesh *wm) { return wm->cell; }

int mf_wall_mesh_create(const mf_trimesh *src, int side, int out_sign, double half, double cell,
                        int dim, struct mf_wall_mesh **out)
{
    *out = NULL;
    struct mf_wall_mesh *wm = calloc(1, sizeof *wm);
    if (!wm)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    wm->side = side;
    wm->out_sign = out_sign;
    wm->half = half;
    wm->dim = dim;
    int rc = copy_mesh(src, &wm->m);
    if (rc == 0)
        rc = mf_pseudonormals_build(&wm->m, &wm->pn);
    if (rc == 0)
        rc = mf_wall_mesh_index(wm, cell);
    if (rc != 0) {
        mf_wall_mesh_destroy(wm);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    *out = wm;
    return 0;
}

void mf_wall_mesh_destroy(struct mf_wall_mesh *wm)
{
    if (!wm)
        return;
    mf_trimesh_free(&wm->m);
    mf_pseudonormals_free(&wm->pn);
    free(wm->keys);
    free(wm->start);
    free(wm->tris);
    free(wm);
}

size_t mf_wall_mesh_memory(const struct mf_wall_mesh *wm)
{
    if (!wm)
        return 0;
    return sizeof *wm + wm->m.nverts * 3 * sizeof(double) + wm->m.ntris * 3 * sizeof(int32_t) +
           (wm->m.ntris * 12 + wm->m.nverts * 3) * sizeof(double) +
           wm->nkeys * (sizeof(uint64_t) + sizeof(uint32_t)) +
           (wm->nkeys ? wm->start[wm->nkeys] : 0) * sizeof(int32_t);
}

/* The triangles listed for the cell of xb. */
static const int32_t *cell_tris(const struct mf_wall_mesh *wm, const double xb[3], size_t *n)
{
    const long c[3] = {cell_of(xb[0], wm->cell), cell_of(xb[1], wm->cell),
                       cell_of(xb[2], wm->cell)};
    const uint64_t key = key_of(c);
    size_t lo = 0, hi = wm->nkeys;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (wm->keys[mid] < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    *n = 0;
    if (!wm->keys || lo == wm->nkeys || wm->keys[lo] != key)
        return NULL;
    *n = wm->start[lo + 1] - wm->start[lo];
    return &wm->tris[wm->start[lo]];
}

/* The side of the fluid: +1 where (x - c).pn > 0 puts x on the fluid side. */
static double side_sign(const struct mf_wall_mesh *wm, double dot)
{
    const double s = dot >= 0 ? 1 : -1;
    switch (wm->side) {
    case MF_SIDE_INSIDE: return -wm->out_sign * s;
    case MF_SIDE_OUTSIDE: return wm->out_sign * s;
    default: return s;
    }
}

/* Signed distance, with the nearest triangle and point. */
static double nearest(const struct mf_wall_mesh *wm, const double xb[3], double n[3],
                      size_t *tri_out)
{
    size_t nt;
    const int32_t *list = cell_tris(wm, xb, &nt);
    double best = INFINITY, q[3], bq[3] = {0, 0, 0};
    int f, bf = 0;
    size_t bt = 0;
    for (size_t k = 0; k < nt; k++) {
        const double d = tri_distance(&wm->m, (size_t)list[k], xb, q, &f);
        if (d < best) {
            best = d;
            bt = (size_t)list[k];
            bf = f;
            memcpy(bq, q, sizeof q);
        }
    }
    n[0] = n[1] = n[2] = 0;
    if (tri_out)
        *tri_out = bt;
    if (!isfinite(best))
        return INFINITY;
    const double *pn = mf_pseudonormal_of(&wm->pn, &wm->m, bt, bf);
    const double dot = (xb[0] - bq[0]) * pn[0] + (xb[1] - bq[1]) * pn[1] + (xb[2] - bq[2]) * pn[2];
    /* direction to the point, else the pseudonormal (on the surface) */
    double dir[3], len = 0;
    for (int a = 0; a < 3; a++) {
        dir[a] = xb[a] - bq[a];
        len += dir[a] * dir[a];
    }
    len = sqrt(len);
    const double *face = &wm->pn.face[3 * bt];
    if (wm->side == MF_SIDE_BOTH) {
        const double s = dot >= 0 ? 1 : -1;
        for (int a = 0; a < 3; a++)
            n[a] = len > 1e-12 * wm->cell ? dir[a] / len : s * face[a];
        return best - wm->half;
    }
    const double s = side_sign(wm, dot);
    double sign_face = side_sign(wm, 1.0); /* the face normal's side */
    for (int a = 0; a < 3; a++)
        n[a] = len > 1e-12 * wm->cell ? s * dir[a] / len : sign_face * face[a];
    return s * best;
}

double mf_wall_mesh_distance(const struct mf_wall_mesh *wm, const double xb[3], double n[3])
{
    return nearest(wm, xb, n, NULL);
}

/* ---- terms ------------------------------------------------------------------- */

typedef struct plane {
    double n[3];     /* into the fluid */
    double delta;    /* the point's signed distance to the plane */
    double dist;     /* to its nearest triangle */
    double cent[3];  /* centroid of that triangle */
} plane;

#define MAX_PLANES 8

int mf_wall_mesh_terms(const struct mf_wall_mesh *wm, const mf_wall_tables *t,
                       const double xb[3], mf_wall_term *terms, int max)
{
    const double reach = mf_wall_tables_reach(t), freed = mf_wall_tables_free_beyond(t);
    double n_near[3];
    const double d_near = nearest(wm, xb, n_near, NULL);
    if (!(d_near < reach))
        return 0;
    size_t nt;
    const int32_t *list = cell_tris(wm, xb, &nt);
    plane pl[MAX_PLANES];
    int np = 0;
    bool curved = false;
    const double cos15 = cos(15 * M_PI / 180), tol = 0.02 * reach;
    for (size_t k = 0; k < nt && !curved; k++) {
        const size_t tr = (size_t)list[k];
        double q[3];
        int f;
        const double dist = tri_distance(&wm->m, tr, xb, q, &f);
        if (!(dist < reach + wm->half))
            continue;
        const double *fn = &wm->pn.face[3 * tr];
        const double *a0 = vert(&wm->m, tr, 0);
        double n[3], s;
        if (wm->side == MF_SIDE_BOTH) {
            const double dot = (xb[0] - a0[0]) * fn[0] + (xb[1] - a0[1]) * fn[1] +
                               (xb[2] - a0[2]) * fn[2];
            s = dot >= 0 ? 1 : -1;
        } else {
            s = side_sign(wm, 1.0);
        }
        for (int a = 0; a < 3; a++)
            n[a] = s * fn[a];
        if (wm->dim == 2) { /* a profile extruded across z = 0 */
            n[2] = 0;
            double len = hypot(n[0], n[1]);
            if (!(len > 0.5))
                continue; /* a face parallel to the plane of the lattice */
            n[0] /= len;
            n[1] /= len;
        }
        const double delta = (xb[0] - a0[0]) * n[0] + (xb[1] - a0[1]) * n[1] +
                             (xb[2] - a0[2]) * n[2] - wm->half;
        int c = 0;
        while (c < np && !(pl[c].n[0] * n[0] + pl[c].n[1] * n[1] + pl[c].n[2] * n[2] > cos15 &&
                           fabs(pl[c].delta - delta) < tol))
            c++;
        if (c == np) {
            if (np == MAX_PLANES) {
                curved = true;
                break;
            }
            np++;
            pl[c].dist = INFINITY;
            memcpy(pl[c].n, n, sizeof n);
            pl[c].delta = delta;
        }
        if (dist < pl[c].dist) {
            pl[c].dist = dist;
            for (int a = 0; a < 3; a++)
                pl[c].cent[a] = (vert(&wm->m, tr, 0)[a] + vert(&wm->m, tr, 1)[a] +
                                 vert(&wm->m, tr, 2)[a]) / 3;
        }
    }
    /* Orthogonal enough, two or three planes, all within reach of their own */
    bool ortho = !curved && np >= 2 && np <= (wm->dim == 2 ? 2 : 3);
    for (int a = 0; ortho && a < np; a++)
        for (int b = a + 1; b < np; b++)
            if (fabs(pl[a].n[0] * pl[b].n[0] + pl[a].n[1] * pl[b].n[1] +
                     pl[a].n[2] * pl[b].n[2]) > 0.34)
                ortho = false;
    if (np == 1 || ortho) {
        if (np == 1 && pl[0].delta >= reach)
            return 0;
        /* concave or convex: where the others' nearest faces lie */
        int concave = 0, convex = 0;
        for (int a = 0; a < np; a++)
            for (int b = 0; b < np; b++) {
                if (a == b)
                    continue;
                double s = 0;
                for (int k = 0; k < 3; k++)
                    s += (pl[b].cent[k] - xb[k]) * pl[a].n[k];
                s += pl[a].delta + wm->half; /* (cent_b - p_a).n_a */
                if (s > 0) concave++;
                else convex++;
            }
        const bool uni = concave >= convex;
        /* The frame: into the solid, made orthogonal in order. */
        double e[3][3];
        for (int a = 0; a < np; a++) {
            for (int k = 0; k < 3; k++)
                e[a][k] = -pl[a].n[k];
            for (int b = 0; b < a; b++) {
                double dot = e[a][0] * e[b][0] + e[a][1] * e[b][1] + e[a][2] * e[b][2];
                for (int k = 0; k < 3; k++)
                    e[a][k] -= dot * e[b][k];
            }
            double len = sqrt(e[a][0] * e[a][0] + e[a][1] * e[a][1] + e[a][2] * e[a][2]);
            for (int k = 0; k < 3; k++)
                e[a][k] /= len;
        }
        for (int a = 0; a < np; a++)
            if (pl[a].delta <= -freed && uni) {
                terms[0] = (mf_wall_term){.c = 0, .sign = 1};
                return 1;
            }
        int ntm = 0;
        if (uni) {
            for (int mask = 1; mask < (1 << np) && ntm < max; mask++) {
                mf_wall_term tm = {.c = 0};
                for (int a = 0; a < np; a++)
                    if (mask >> a & 1) {
                        memcpy(tm.e[tm.c], e[a], sizeof e[a]);
                        tm.delta[tm.c++] = pl[a].delta;
                    }
                tm.sign = tm.c % 2 ? 1 : -1;
                terms[ntm++] = tm;
            }
        } else {
            mf_wall_term tm = {.c = 0, .sign = 1};
            for (int a = 0; a < np; a++) {
                if (pl[a].delta <= -freed)
                    continue; /* that face's slab covers the reach: a free axis */
                memcpy(tm.e[tm.c], e[a], sizeof e[a]);
                tm.delta[tm.c++] = pl[a].delta;
            }
            terms[ntm++] = tm;
        }
        return ntm;
    }
    /* The tangent plane at the nearest point. */
    if (d_near <= -freed) {
        terms[0] = (mf_wall_term){.c = 0, .sign = 1};
        return 1;
    }
    mf_wall_term tm = {.c = 1, .sign = 1, .delta = {d_near, 0, 0}};
    double len = 0;
    for (int a = 0; a < 3; a++) {
        tm.e[0][a] = wm->dim == 2 && a == 2 ? 0 : -n_near[a];
        len += tm.e[0][a] * tm.e[0][a];
    }
    if (!(len > 0))
        return 0;
    len = sqrt(len);
    for (int a = 0; a < 3; a++)
        tm.e[0][a] /= len;
    terms[0] = tm;
    return 1;
}

const mf_trimesh *mf_wall_mesh_surface(const struct mf_wall_mesh *wm)
{
    return &wm->m;
}

int mf_wall_mesh_report(const struct mf_wall_mesh *wm, mf_trimesh_report *r)
{
    mf_trimesh copy; /* mf_trimesh_check may turn triangles: not the kept mesh's */
    int rc = copy_mesh(&wm->m, &copy);
    if (rc == 0)
        rc = mf_trimesh_check(&copy, r);
    mf_trimesh_free(&copy);
    return rc;
}
