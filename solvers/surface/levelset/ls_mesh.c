/* ls_mesh.c: the zero level of a brick field as a triangle mesh, by marching
 * tetrahedra on the 6-tetrahedra (Kuhn) split of every grid cube.
 *
 * Why tetrahedra and not the 256-case marching cubes table: every cube is
 * split the same way (the six tetrahedra around its main diagonal), so the
 * split of a shared face is the same seen from both cubes, and the
 * piecewise-linear zero level of a tetrahedral mesh is a 2-manifold without
 * any ambiguity to resolve: a closed level gives a closed, manifold mesh by
 * construction. Marching cubes needs an ambiguity rule kept consistent
 * across faces (and a 256-entry table) to promise the same. The price is
 * about twice as many triangles. Debian's libraries for this (VTK, CGAL,
 * OpenVDB) are large C++ frameworks; this is 300 lines of C.
 *
 * Vertices sit on grid edges (the 3 axes, 3 face diagonals and the cube
 * diagonal of the split), at the linear interpolation of the zero; each is
 * made once, by the brick that holds the edge's lower end, and numbered by
 * counting (two passes, so the output does not depend on the thread count).
 * Normals are -grad phi (central differences, interpolated along the edge):
 * phi > 0 inside, so they point out of the fluid. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "levelset.h"

typedef struct src {
    const ls_bricks *b;
    const int32_t *nb;
    const float *v32;
    const double *v64;
    const uint8_t *known;
    /* the current brick's values with a halo, local -1 .. 9 (NaN: unknown) */
    const double *pad;
    int32_t pad_brick;
} src;

#define Q 11
#define QI(i, j, k) ((i) + 1 + Q * ((j) + 1 + Q * ((k) + 1)))

/* Brick and local offset of a point given relative to brick b, coordinates
 * in [-8, 15]. */
static inline bool locate(const src *s, int32_t b, int i, int j, int k, size_t *o)
{
    int dx = i < 0 ? -1 : (i >= LS_B ? 1 : 0), dy = j < 0 ? -1 : (j >= LS_B ? 1 : 0),
        dz = k < 0 ? -1 : (k >= LS_B ? 1 : 0);
    int32_t nbk = s->nb[27 * b + (dx + 1) + 3 * (dy + 1) + 9 * (dz + 1)];
    if (nbk == LS_NONE)
        return false;
    *o = (size_t)nbk * LS_B3 + ls_local_index(i & 7, j & 7, k & 7);
    return !s->known || (s->known[*o] & LS_HAS_PHI);
}

static inline bool value(const src *s, int32_t b, int i, int j, int k, double *v)
{
    if (s->pad && b == s->pad_brick && i >= -1 && i <= 9 && j >= -1 && j <= 9 && k >= -1 &&
        k <= 9) {
        *v = s->pad[QI(i, j, k)];
        return !isnan(*v);
    }
    size_t o;
    if (!locate(s, b, i, j, k, &o))
        return false;
    *v = s->v32 ? (double)s->v32[o] : s->v64[o];
    return true;
}

static inline int popcount8(unsigned m)
{
    m = m - ((m >> 1) & 0x55);
    m = (m & 0x33) + ((m >> 2) & 0x33);
    return (int)((m + (m >> 4)) & 0x0f);
}

static inline int dir_x(int d) { return d & 1; }
static inline int dir_y(int d) { return (d >> 1) & 1; }
static inline int dir_z(int d) { return (d >> 2) & 1; }

/* Where the zero lies on an edge, as a fraction from the lower end. Kept
 * away from the ends so that no two vertices coincide. */
static inline double crossing(double v0, double v1)
{
    double t = v0 / (v0 - v1);
    return fmin(1 - 1e-4, fmax(1e-4, t));
}

static void gradient(const src *s, int32_t b, int i, int j, int k, double g[3])
{
    double c = 0;
    bool has_c = value(s, b, i, j, k, &c);
    for (int a = 0; a < 3; a++) {
        double m = 0, p = 0;
        int di = a == 0, dj = a == 1, dk = a == 2;
        bool hm = value(s, b, i - di, j - dj, k - dk, &m);
        bool hp = value(s, b, i + di, j + dj, k + dk, &p);
        if (hm && hp)
            g[a] = 0.5 * (p - m);
        else if (hp && has_c)
            g[a] = p - c;
        else if (hm && has_c)
            g[a] = c - m;
        else
            g[a] = 0;
    }
}

/* A per-thread view of the source with brick b's padded block filled. */
static void with_pad(const src *s, int32_t b, double *pad, src *out)
{
    *out = *s;
    out->pad = NULL;
    for (int k = -1; k <= 9; k++)
        for (int j = -1; j <= 9; j++)
            for (int i = -1; i <= 9; i++) {
                double v;
                pad[QI(i, j, k)] = value(out, b, i, j, k, &v) ? v : NAN;
            }
    out->pad = pad;
    out->pad_brick = b;
}

/* Kuhn split: tetrahedra {0, a, a | b, 7} for the 6 orders of the axes
 * (corner codes: bit 0 x, bit 1 y, bit 2 z). */
static const int tets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                               {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};

typedef struct counts {
    uint8_t *mask;   /* per point: bit d set if the edge along direction d crosses */
    uint16_t *cum;   /* per point: crossing edges of the brick's earlier points */
    size_t *voff;    /* per brick: first vertex */
    size_t *toff;    /* per brick: first triangle */
} counts;

static inline int32_t vertex_of(const src *s, const counts *c, int32_t b, int i, int j, int k,
                                int d)
{
    size_t o;
    if (!locate(s, b, i, j, k, &o))
        return -1;
    size_t brick = o / LS_B3;
    unsigned m = c->mask[o];
    if (!(m & (1u << d)))
        return -1;
    return (int32_t)(c->voff[brick] + c->cum[o] +
                     (size_t)popcount8(m & ((1u << d) - 1)));
}

/* The triangles of one tetrahedron (corner values v, positions on the
 * corner codes); returns the count (0..2) and writes vertex indices. */
static int tet_triangles(const src *s, const counts *c, int32_t b, int i, int j, int k,
                         const int *tet, const double *v, int32_t tri[6])
{
    int in = 0;
    for (int q = 0; q < 4; q++)
        if (v[tet[q]] > 0)
            in |= 1 << q;
    if (in == 0 || in == 15)
        return 0;
    /* the grid edges of the tetrahedron that cross, as (lower, upper) corner codes */
    int ins[4], outs[4], ni = 0, no = 0;
    for (int q = 0; q < 4; q++) {
        if (in & (1 << q))
            ins[ni++] = tet[q];
        else
            outs[no++] = tet[q];
    }
#define EDGE(u, w)                                                                         \
    vertex_of(s, c, b, i + dir_x((u) < (w) ? (u) : (w)), j + dir_y((u) < (w) ? (u) : (w)), \
              k + dir_z((u) < (w) ? (u) : (w)), (u) ^ (w))
    int nt;
    int32_t e[4];
    if (ni == 1 || no == 1) {
        int odd = ni == 1 ? ins[0] : outs[0];
        const int *rest = ni == 1 ? outs : ins;
        for (int q = 0; q < 3; q++)
            e[q] = EDGE(odd, rest[q]);
        tri[0] = e[0];
        tri[1] = e[1];
        tri[2] = e[2];
        nt = 1;
    } else {
        e[0] = EDGE(ins[0], outs[0]);
        e[1] = EDGE(ins[0], outs[1]);
        e[2] = EDGE(ins[1], outs[1]);
        e[3] = EDGE(ins[1], outs[0]);
        tri[0] = e[0];
        tri[1] = e[1];
        tri[2] = e[2];
        tri[3] = e[0];
        tri[4] = e[2];
        tri[5] = e[3];
        nt = 2;
    }
#undef EDGE
    for (int q = 0; q < 3 * nt; q++)
        if (tri[q] < 0)
            return -1; /* an inconsistency: a bug, reported by the caller */
    /* Orientation: the normal must point from the inside corners to the
     * outside ones. Positions from the corner values, as the vertices were
     * placed. */
    double cin[3] = {0, 0, 0}, cout[3] = {0, 0, 0};
    for (int q = 0; q < ni; q++) {
        cin[0] += dir_x(ins[q]) / (double)ni;
        cin[1] += dir_y(ins[q]) / (double)ni;
        cin[2] += dir_z(ins[q]) / (double)ni;
    }
    for (int q = 0; q < no; q++) {
        cout[0] += dir_x(outs[q]) / (double)no;
        cout[1] += dir_y(outs[q]) / (double)no;
        cout[2] += dir_z(outs[q]) / (double)no;
    }
    const double out_dir[3] = {cout[0] - cin[0], cout[1] - cin[1], cout[2] - cin[2]};
    /* crossing positions of the edges, in the cube's frame */
    double pos[4][3];
    int pairs[4][2];
    if (ni == 1 || no == 1) {
        int odd = ni == 1 ? ins[0] : outs[0];
        const int *rest = ni == 1 ? outs : ins;
        for (int q = 0; q < 3; q++) {
            pairs[q][0] = odd;
            pairs[q][1] = rest[q];
        }
    } else {
        int p4[4][2] = {{ins[0], outs[0]}, {ins[0], outs[1]}, {ins[1], outs[1]}, {ins[1], outs[0]}};
        memcpy(pairs, p4, sizeof p4);
    }
    for (int q = 0; q < (nt == 1 ? 3 : 4); q++) {
        int u = pairs[q][0], w = pairs[q][1];
        int lo = u < w ? u : w, hi = u < w ? w : u;
        double t = crossing(v[lo], v[hi]);
        pos[q][0] = dir_x(lo) + t * (dir_x(hi) - dir_x(lo));
        pos[q][1] = dir_y(lo) + t * (dir_y(hi) - dir_y(lo));
        pos[q][2] = dir_z(lo) + t * (dir_z(hi) - dir_z(lo));
    }
    static const int corner_of[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (int q = 0; q < nt; q++) {
        const double *A = pos[corner_of[q][0]];
        const double *B = pos[corner_of[q][1]];
        const double *C = pos[corner_of[q][2]];
        double u1[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
        double u2[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
        double n[3] = {u1[1] * u2[2] - u1[2] * u2[1], u1[2] * u2[0] - u1[0] * u2[2],
                       u1[0] * u2[1] - u1[1] * u2[0]};
        if (n[0] * out_dir[0] + n[1] * out_dir[1] + n[2] * out_dir[2] < 0) {
            int32_t t = tri[3 * q + 1];
            tri[3 * q + 1] = tri[3 * q + 2];
            tri[3 * q + 2] = t;
        }
    }
    return nt;
}

/* Corner values of the cube at local (i, j, k) of brick b; bit q of the
 * result says corner q is known. A tetrahedron is used when its four corners
 * are known: every corner of a tetrahedron the zero level crosses is the end
 * of a crossing edge, and those are known (ls_detect, the band's rim), while
 * the cube's other corners may lie in bricks that were never stored. */
static inline unsigned cube_values(const src *s, int32_t b, int i, int j, int k, double v[8])
{
    unsigned known = 0;
    for (int q = 0; q < 8; q++)
        if (value(s, b, i + dir_x(q), j + dir_y(q), k + dir_z(q), &v[q]))
            known |= 1u << q;
        else
            v[q] = NAN;
    return known;
}

static size_t brick_triangles(const src *s, const counts *c, int32_t b, int32_t *out,
                              int *bad)
{
    size_t nt = 0;
    for (int k = 0; k < LS_B; k++)
        for (int j = 0; j < LS_B; j++)
            for (int i = 0; i < LS_B; i++) {
                double v[8];
                unsigned known = cube_values(s, b, i, j, k, v);
                bool pos = false, neg = false;
                for (int q = 0; q < 8; q++) {
                    if (!(known & (1u << q)))
                        continue;
                    if (v[q] > 0)
                        pos = true;
                    else
                        neg = true;
                }
                if (!pos || !neg)
                    continue;
                for (int t = 0; t < 6; t++) {
                    const int *tt = tets[t];
                    if (!(known & (1u << tt[0])) || !(known & (1u << tt[1])) ||
                        !(known & (1u << tt[2])) || !(known & (1u << tt[3])))
                        continue;
                    int32_t tri[6];
                    int n = tet_triangles(s, c, b, i, j, k, tets[t], v, tri);
                    if (n < 0) {
                        *bad = 1;
                        continue;
                    }
                    if (out)
                        memcpy(out + 3 * nt, tri, 3 * (size_t)n * sizeof *tri);
                    nt += (size_t)n;
                }
            }
    return nt;
}

int ls_mesh_extract(const ls_bricks *bricks, const int32_t *nb, const float *values32,
                    const double *values64, const uint8_t *known, double h, mf_mesh *out)
{
    src s = {bricks, nb, values32, values64, known, NULL, LS_NONE};
    const size_t nbk = bricks->n;
    counts c = {0};
    c.mask = malloc((nbk ? nbk : 1) * LS_B3);
    c.cum = malloc((nbk ? nbk : 1) * LS_B3 * sizeof *c.cum);
    c.voff = malloc((nbk + 1) * sizeof *c.voff);
    c.toff = malloc((nbk + 1) * sizeof *c.toff);
    int rc = 0;
    if (!c.mask || !c.cum || !c.voff || !c.toff) {
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory extracting a mesh from %zu bricks", nbk);
        goto done;
    }
    /* 1. crossing edges per point, vertex numbering */
#pragma omp parallel for schedule(dynamic, 8)
    for (size_t b = 0; b < nbk; b++) {
        double pad[Q * Q * Q];
        src ps;
        with_pad(&s, (int32_t)b, pad, &ps);
        size_t total = 0;
        for (int l = 0; l < LS_B3; l++) {
            const int i = l & 7, j = (l >> 3) & 7, k = l >> 6;
            const size_t o = b * LS_B3 + (size_t)l;
            unsigned m = 0;
            double v0 = 0, v1 = 0;
            if (value(&ps, (int32_t)b, i, j, k, &v0)) {
                for (int d = 1; d < 8; d++)
                    if (value(&ps, (int32_t)b, i + dir_x(d), j + dir_y(d), k + dir_z(d), &v1) &&
                        (v0 > 0) != (v1 > 0))
                        m |= 1u << d;
            }
            c.mask[o] = (uint8_t)m;
            c.cum[o] = (uint16_t)total;
            total += (size_t)popcount8(m);
        }
        c.voff[b + 1] = total;
    }
    c.voff[0] = 0;
    for (size_t b = 0; b < nbk; b++)
        c.voff[b + 1] += c.voff[b];
    /* 2. triangles per brick */
    int bad = 0;
#pragma omp parallel for schedule(dynamic, 8) reduction(| : bad)
    for (size_t b = 0; b < nbk; b++) {
        double pad[Q * Q * Q];
        src ps;
        with_pad(&s, (int32_t)b, pad, &ps);
        c.toff[b + 1] = brick_triangles(&ps, &c, (int32_t)b, NULL, &bad);
    }
    c.toff[0] = 0;
    for (size_t b = 0; b < nbk; b++)
        c.toff[b + 1] += c.toff[b];
    if (bad) {
        rc = MF_ERROR(MF_ERR_INTERNAL, "marching tetrahedra: a crossing edge without a vertex");
        goto done;
    }
    rc = mf_mesh_reserve(out, c.voff[nbk], c.toff[nbk]);
    if (rc != 0)
        goto done;
    out->nverts = c.voff[nbk];
    out->ntris = c.toff[nbk];
    /* 3. vertices with normals, and the triangles */
#pragma omp parallel for schedule(dynamic, 8) reduction(| : bad)
    for (size_t b = 0; b < nbk; b++) {
        const int32_t *bc = &bricks->coord[3 * b];
        double pad[Q * Q * Q];
        src ps;
        with_pad(&s, (int32_t)b, pad, &ps);
        for (int l = 0; l < LS_B3; l++) {
            const size_t o = b * LS_B3 + (size_t)l;
            unsigned m = c.mask[o];
            if (!m)
                continue;
            const int i = l & 7, j = (l >> 3) & 7, k = l >> 6;
            double v0 = 0, v1 = 0, g0[3], g1[3];
            value(&ps, (int32_t)b, i, j, k, &v0);
            gradient(&ps, (int32_t)b, i, j, k, g0);
            size_t vi = c.voff[b] + c.cum[o];
            for (int d = 1; d < 8; d++) {
                if (!(m & (1u << d)))
                    continue;
                const int i1 = i + dir_x(d), j1 = j + dir_y(d), k1 = k + dir_z(d);
                value(&ps, (int32_t)b, i1, j1, k1, &v1);
                gradient(&ps, (int32_t)b, i1, j1, k1, g1);
                const double t = crossing(v0, v1);
                float *x = &out->xyz[3 * vi], *n = &out->normal[3 * vi];
                x[0] = (float)(h * (LS_B * bc[0] + i + t * dir_x(d)));
                x[1] = (float)(h * (LS_B * bc[1] + j + t * dir_y(d)));
                x[2] = (float)(h * (LS_B * bc[2] + k + t * dir_z(d)));
                double g[3], gn = 0;
                for (int a = 0; a < 3; a++) {
                    g[a] = -((1 - t) * g0[a] + t * g1[a]);
                    gn += g[a] * g[a];
                }
                gn = sqrt(gn);
                if (gn > 0) {
                    for (int a = 0; a < 3; a++)
                        n[a] = (float)(g[a] / gn);
                } else {
                    /* flat field: the edge direction, from inside to outside */
                    double e[3] = {dir_x(d), dir_y(d), dir_z(d)}, en = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
                    double sgn = v0 > 0 ? 1 : -1;
                    for (int a = 0; a < 3; a++)
                        n[a] = (float)(sgn * e[a] / en);
                }
                vi++;
            }
        }
        brick_triangles(&ps, &c, (int32_t)b, out->tri + 3 * c.toff[b], &bad);
    }
    if (bad)
        rc = MF_ERROR(MF_ERR_INTERNAL, "marching tetrahedra: a crossing edge without a vertex");
done:
    free(c.mask);
    free(c.cum);
    free(c.voff);
    free(c.toff);
    return rc;
}
