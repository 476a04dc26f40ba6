/* trimesh.c: triangle meshes from polygon files: storage, welding, the
 * checks of a surface (degenerate triangles, open and non-manifold edges,
 * winding), pseudo-normals and winding numbers. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_trimesh.h"
#include "trimesh_internal.h"

void mf_trimesh_init(mf_trimesh *m)
{
    memset(m, 0, sizeof *m);
}

void mf_trimesh_free(mf_trimesh *m)
{
    if (!m)
        return;
    free(m->xyz);
    free(m->tri);
    char name[sizeof m->name];
    memcpy(name, m->name, sizeof name);
    mf_trimesh_init(m);
    memcpy(m->name, name, sizeof name); /* messages may still name it */
}

int mf_trimesh_reserve(mf_trimesh *m, size_t nverts, size_t ntris)
{
    if (nverts > (size_t)INT32_MAX || ntris > SIZE_MAX / (3 * sizeof(int32_t)))
        return MF_ERROR(MF_ERR_MEMORY, "%s: a mesh of %zu vertices and %zu triangles is too large",
                        m->name, nverts, ntris);
    if (nverts > m->cap_verts) {
        size_t cap = nverts > 2 * m->cap_verts ? nverts : 2 * m->cap_verts;
        if (mf_resize(&m->xyz, 3 * cap, sizeof *m->xyz))
            return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for %zu vertices", m->name, cap);
        m->cap_verts = cap;
    }
    if (ntris > m->cap_tris) {
        size_t cap = ntris > 2 * m->cap_tris ? ntris : 2 * m->cap_tris;
        if (mf_resize(&m->tri, 3 * cap, sizeof *m->tri))
            return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for %zu triangles", m->name, cap);
        m->cap_tris = cap;
    }
    return 0;
}

int mf_trimesh_add_vertex(mf_trimesh *m, const double x[3])
{
    MF_CALL(mf_trimesh_reserve(m, m->nverts + 1, m->ntris));
    memcpy(&m->xyz[3 * m->nverts], x, 3 * sizeof(double));
    m->nverts++;
    return 0;
}

int mf_trimesh_add_triangle(mf_trimesh *m, int32_t a, int32_t b, int32_t c)
{
    int32_t v[3] = {a, b, c};
    for (int k = 0; k < 3; k++)
        if (v[k] < 0 || (size_t)v[k] >= m->nverts)
            return MF_ERROR(MF_ERR_INPUT, "%s: triangle %zu names vertex %d of %zu", m->name,
                            m->ntris, (int)v[k], m->nverts);
    MF_CALL(mf_trimesh_reserve(m, m->nverts, m->ntris + 1));
    memcpy(&m->tri[3 * m->ntris], v, sizeof v);
    m->ntris++;
    return 0;
}

void mf_trimesh_scale(mf_trimesh *m, double s)
{
    for (size_t k = 0; k < 3 * m->nverts; k++)
        m->xyz[k] *= s;
}

void mf_trimesh_bounds(const mf_trimesh *m, double min[3], double max[3])
{
    for (int a = 0; a < 3; a++) {
        min[a] = m->nverts ? INFINITY : 0;
        max[a] = m->nverts ? -INFINITY : 0;
    }
    for (size_t v = 0; v < m->nverts; v++)
        for (int a = 0; a < 3; a++) {
            double x = m->xyz[3 * v + a];
            if (x < min[a]) min[a] = x;
            if (x > max[a]) max[a] = x;
        }
}

/* ---- welding ---------------------------------------------------------------- */

typedef struct weld_item {
    long long q[3]; /* quantised coordinates */
    int32_t v;
} weld_item;

static int cmp_weld(const void *pa, const void *pb)
{
    const weld_item *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->q[k] != b->q[k])
            return a->q[k] < b->q[k] ? -1 : 1;
    return a->v < b->v ? -1 : a->v > b->v;
}

int mf_trimesh_weld(mf_trimesh *m, double tol)
{
    if (m->nverts == 0)
        return 0;
    if (!(tol > 0))
        tol = 1e-300;
    weld_item *items = malloc(m->nverts * sizeof *items);
    int32_t *map = malloc(m->nverts * sizeof *map);
    char *used = calloc(m->nverts, 1);
    double *xyz = malloc(3 * m->nverts * sizeof *xyz);
    if (!items || !map || !used || !xyz) {
        free(items); free(map); free(used); free(xyz);
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory welding %zu vertices", m->name,
                        m->nverts);
    }
    for (size_t t = 0; t < 3 * m->ntris; t++)
        used[m->tri[t]] = 1;
    size_t n = 0;
    for (size_t v = 0; v < m->nverts; v++) {
        if (!used[v])
            continue;
        for (int k = 0; k < 3; k++)
            items[n].q[k] = llround(m->xyz[3 * v + k] / tol);
        items[n++].v = (int32_t)v;
    }
    qsort(items, n, sizeof *items, cmp_weld);
    size_t nv = 0;
    for (size_t k = 0; k < n; k++) {
        bool same = k > 0 && memcmp(items[k].q, items[k - 1].q, sizeof items[k].q) == 0;
        if (!same) {
            /* The first of a run (the lowest original index) keeps its place. */
            memcpy(&xyz[3 * nv], &m->xyz[3 * (size_t)items[k].v], 3 * sizeof(double));
            nv++;
        }
        map[items[k].v] = (int32_t)(nv - 1);
    }
    for (size_t t = 0; t < 3 * m->ntris; t++)
        m->tri[t] = map[m->tri[t]];
    free(m->xyz);
    m->xyz = xyz;
    m->nverts = nv;
    m->cap_verts = m->nverts;
    free(items);
    free(map);
    free(used);
    return 0;
}

/* ---- edges ------------------------------------------------------------------ */

/* One triangle side: vertices lo < hi, and whether the triangle walks it
 * from lo to hi. */
typedef struct half_edge {
    int32_t lo, hi;
    uint32_t tri;
    uint8_t k;       /* side k of the triangle: vertex k to vertex k + 1 */
    uint8_t forward; /* walked lo -> hi */
} half_edge;

static int cmp_half_edge(const void *pa, const void *pb)
{
    const half_edge *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    if (a->tri != b->tri) return a->tri < b->tri ? -1 : 1;
    return a->k < b->k ? -1 : a->k > b->k;
}

/* Every triangle side, sorted so that the sides of one edge are adjacent. */
static int half_edges(const mf_trimesh *m, half_edge **out)
{
    if (m->ntris > UINT32_MAX)
        return MF_ERROR(MF_ERR_MEMORY, "%s: too many triangles (%zu)", m->name, m->ntris);
    half_edge *h = malloc(3 * m->ntris * sizeof *h + 1);
    if (!h)
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for the edges of %zu triangles",
                        m->name, m->ntris);
    for (size_t t = 0; t < m->ntris; t++)
        for (int k = 0; k < 3; k++) {
            int32_t a = m->tri[3 * t + k], b = m->tri[3 * t + (k + 1) % 3];
            h[3 * t + k] = (half_edge){a < b ? a : b, a < b ? b : a, (uint32_t)t, (uint8_t)k,
                                       (uint8_t)(a < b)};
        }
    qsort(h, 3 * m->ntris, sizeof *h, cmp_half_edge);
    *out = h;
    return 0;
}

static void edge_midpoint(const mf_trimesh *m, const half_edge *e, double at[3])
{
    for (int a = 0; a < 3; a++)
        at[a] = 0.5 * (m->xyz[3 * (size_t)e->lo + a] + m->xyz[3 * (size_t)e->hi + a]);
}

/* ---- the checks -------------------------------------------------------------- */

static double tri_area2(const mf_trimesh *m, size_t t, double n[3], double *longest2)
{
    const double *a = &m->xyz[3 * (size_t)m->tri[3 * t]];
    const double *b = &m->xyz[3 * (size_t)m->tri[3 * t + 1]];
    const double *c = &m->xyz[3 * (size_t)m->tri[3 * t + 2]];
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = c[k] - b[k];
    }
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    if (longest2) {
        double lu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
        double lv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        double lw = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
        *longest2 = fmax(lu, fmax(lv, lw));
    }
    return sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

static size_t remove_degenerate(mf_trimesh *m, mf_trimesh_report *r)
{
    size_t kept = 0, removed = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        const int32_t *v = &m->tri[3 * t];
        double n[3], longest2;
        bool degenerate = v[0] == v[1] || v[1] == v[2] || v[2] == v[0];
        if (!degenerate) {
            double area2 = tri_area2(m, t, n, &longest2);
            degenerate = !(area2 > 1e-10 * longest2);
        }
        if (degenerate) {
            if (removed++ == 0)
                for (int a = 0; a < 3; a++)
                    r->at_degenerate[a] = (m->xyz[3 * (size_t)v[0] + a] +
                                           m->xyz[3 * (size_t)v[1] + a] +
                                           m->xyz[3 * (size_t)v[2] + a]) / 3;
            continue;
        }
        memmove(&m->tri[3 * kept], v, 3 * sizeof *v);
        kept++;
    }
    m->ntris = kept;
    return removed;
}

/* Turn triangles so that the two triangles of every manifold edge walk it in
 * opposite directions. Breadth-first over each connected piece; in each
 * piece the winding of the majority of its triangles is kept. */
static int orient(mf_trimesh *m, const half_edge *h, mf_trimesh_report *r)
{
    size_t nt = m->ntris, nh = 3 * nt;
    /* For each triangle side, the other side of the same (manifold) edge. */
    size_t *mate = malloc(nh * sizeof *mate + 1);
    int8_t *flip = malloc(nt + 1);          /* -1 unvisited, 0 keep, 1 turn */
    uint32_t *queue = malloc(nt * sizeof *queue + 1);
    uint32_t *comp = malloc(nt * sizeof *comp + 1);
    if (!mate || !flip || !queue || !comp) {
        free(mate); free(flip); free(queue); free(comp);
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory orienting %zu triangles", m->name, nt);
    }
    for (size_t k = 0; k < nh; k++)
        mate[k] = SIZE_MAX;
    for (size_t k = 0; k < nh;) {
        size_t e = k + 1;
        while (e < nh && h[e].lo == h[k].lo && h[e].hi == h[k].hi)
            e++;
        if (e - k == 2) {
            mate[3 * (size_t)h[k].tri + h[k].k] = k + 1;
            mate[3 * (size_t)h[k + 1].tri + h[k + 1].k] = k;
        }
        k = e;
    }
    /* forward flag of each triangle side, by (tri, k). */
    memset(flip, -1, nt);
    r->orientable = true;
    r->ncomponents = 0;
    for (size_t seed = 0; seed < nt; seed++) {
        if (flip[seed] >= 0)
            continue;
        size_t head = 0, tail = 0, nturned = 0;
        flip[seed] = 0;
        queue[tail++] = (uint32_t)seed;
        while (head < tail) {
            uint32_t t = queue[head++];
            for (int k = 0; k < 3; k++) {
                size_t o = mate[3 * (size_t)t + k];
                if (o == SIZE_MAX)
                    continue;
                /* This side's direction as the triangle now stands; the
                 * neighbour must walk the edge the other way. */
                int32_t a = m->tri[3 * (size_t)t + k], b = m->tri[3 * (size_t)t + (k + 1) % 3];
                int dir_self = (a < b) ^ flip[t];
                const half_edge *other = &h[o];
                uint32_t u = other->tri;
                int turn = other->forward == dir_self;
                if (flip[u] < 0) {
                    flip[u] = (int8_t)turn;
                    nturned += (size_t)turn;
                    queue[tail++] = u;
                } else if (flip[u] != turn) {
                    r->orientable = false;
                }
            }
        }
        /* Keep the majority's winding. */
        bool invert = 2 * nturned > tail;
        for (size_t q = 0; q < tail; q++) {
            if (invert)
                flip[queue[q]] = (int8_t)!flip[queue[q]];
            comp[queue[q]] = (uint32_t)r->ncomponents;
        }
        r->ncomponents++;
    }
    size_t nflipped = 0;
    if (r->orientable)
        for (size_t t = 0; t < nt; t++)
            if (flip[t] == 1) {
                int32_t tmp = m->tri[3 * t + 1];
                m->tri[3 * t + 1] = m->tri[3 * t + 2];
                m->tri[3 * t + 2] = tmp;
                nflipped++;
            }
    r->nflipped = nflipped;
    free(mate);
    free(flip);
    free(queue);
    free(comp);
    return 0;
}

int mf_trimesh_check(mf_trimesh *m, mf_trimesh_report *r)
{
    memset(r, 0, sizeof *r);
    r->ndegenerate = remove_degenerate(m, r);
    if (m->ntris == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: no triangle is left once the %zu degenerate (zero-area) "
                        "ones are removed", m->name, r->ndegenerate);
    half_edge *h;
    MF_CALL(half_edges(m, &h));
    size_t nh = 3 * m->ntris;
    for (size_t k = 0; k < nh;) {
        size_t e = k + 1;
        while (e < nh && h[e].lo == h[k].lo && h[e].hi == h[k].hi)
            e++;
        if (e - k == 1 && r->nboundary++ == 0)
            edge_midpoint(m, &h[k], r->at_boundary);
        if (e - k > 2 && r->nnonmanifold++ == 0)
            edge_midpoint(m, &h[k], r->at_nonmanifold);
        k = e;
    }
    int rc = orient(m, h, r);
    free(h);
    MF_CALL(rc);
    r->closed = r->nboundary == 0 && r->nnonmanifold == 0;
    mf_trimesh_bounds(m, r->min, r->max);
    double area = 0, volume = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        double n[3];
        area += 0.5 * tri_area2(m, t, n, NULL);
        const double *a = &m->xyz[3 * (size_t)m->tri[3 * t]];
        volume += (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) / 6; /* a . ((b-a) x (c-a)) / 6 */
    }
    r->area = area;
    r->volume = volume;
    return 0;
}

/* ---- pseudo-normals ---------------------------------------------------------- */

static void normalize(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0)
        for (int k = 0; k < 3; k++)
            v[k] /= l;
}

int mf_pseudonormals_build(const mf_trimesh *m, mf_pseudonormals *pn)
{
    size_t nt = m->ntris;
    pn->face = malloc(3 * nt * sizeof(double) + 1);
    pn->edge = calloc(9 * nt + 1, sizeof(double));
    pn->vert = calloc(3 * m->nverts + 1, sizeof(double));
    half_edge *h = NULL;
    if (!pn->face || !pn->edge || !pn->vert) {
        mf_pseudonormals_free(pn);
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for normals", m->name);
    }
    for (size_t t = 0; t < nt; t++) {
        double *n = &pn->face[3 * t];
        tri_area2(m, t, n, NULL);
        normalize(n);
        /* Angle of the face at each corner, for the vertex normals. */
        for (int k = 0; k < 3; k++) {
            const double *p = &m->xyz[3 * (size_t)m->tri[3 * t + k]];
            const double *q = &m->xyz[3 * (size_t)m->tri[3 * t + (k + 1) % 3]];
            const double *s = &m->xyz[3 * (size_t)m->tri[3 * t + (k + 2) % 3]];
            double u[3], v[3];
            for (int a = 0; a < 3; a++) {
                u[a] = q[a] - p[a];
                v[a] = s[a] - p[a];
            }
            normalize(u);
            normalize(v);
            double c = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
            double angle = acos(fmax(-1.0, fmin(1.0, c)));
            double *vn = &pn->vert[3 * (size_t)m->tri[3 * t + k]];
            for (int a = 0; a < 3; a++)
                vn[a] += angle * n[a];
        }
    }
    int rc = half_edges(m, &h);
    if (rc != 0) {
        mf_pseudonormals_free(pn);
        MF_CALL(rc);
    }
    size_t nh = 3 * nt;
    for (size_t k = 0; k < nh;) {
        size_t e = k + 1;
        while (e < nh && h[e].lo == h[k].lo && h[e].hi == h[k].hi)
            e++;
        double sum[3] = {0, 0, 0};
        for (size_t q = k; q < e; q++)
            for (int a = 0; a < 3; a++)
                sum[a] += pn->face[3 * (size_t)h[q].tri + a];
        for (size_t q = k; q < e; q++)
            memcpy(&pn->edge[3 * (3 * (size_t)h[q].tri + h[q].k)], sum, sizeof sum);
        k = e;
    }
    free(h);
    return 0;
}

void mf_pseudonormals_free(mf_pseudonormals *pn)
{
    free(pn->face);
    free(pn->edge);
    free(pn->vert);
    pn->face = pn->edge = pn->vert = NULL;
}

/* ---- winding number -------------------------------------------------------- */

double mf_trimesh_winding(const mf_trimesh *m, const double x[3])
{
    double sum = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        double a[3], b[3], c[3];
        for (int k = 0; k < 3; k++) {
            a[k] = m->xyz[3 * (size_t)m->tri[3 * t] + k] - x[k];
            b[k] = m->xyz[3 * (size_t)m->tri[3 * t + 1] + k] - x[k];
            c[k] = m->xyz[3 * (size_t)m->tri[3 * t + 2] + k] - x[k];
        }
        double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                     a[2] * (b[0] * c[1] - b[1] * c[0]);
        double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        double bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
        double ca = c[0] * a[0] + c[1] * a[1] + c[2] * a[2];
        /* van Oosterom & Strackee (IEEE Trans. Biomed. Eng. 30, 1983): tan(Omega/2). */
        sum += 2 * atan2(det, la * lb * lc + ab * lc + bc * la + ca * lb);
    }
    return sum / (4 * M_PI);
}
