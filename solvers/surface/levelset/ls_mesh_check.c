/* ls_mesh_check.c: the topology of a triangle mesh, to state (in the log and
 * in tests) that a reconstructed surface is closed and manifold:
 *   - every edge is used by exactly two triangles (closed; more than two is
 *     a non-manifold edge);
 *   - the triangles around every vertex form one fan (a single cycle of
 *     link edges), so no two surfaces touch at a vertex;
 *   - the Euler characteristic V - E + F (2 for each sphere-like component)
 *     and the number of connected components. */
#include <stdlib.h>
#include <string.h>

#include "levelset.h"

/* LSD radix sort of 64-bit keys, 16 bits per pass. */
static int sort_keys(uint64_t *a, size_t n)
{
    uint64_t *tmp = malloc((n ? n : 1) * sizeof *tmp);
    size_t *count = malloc(65536 * sizeof *count);
    if (!tmp || !count) {
        free(tmp);
        free(count);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory sorting %zu mesh edges", n);
    }
    for (int pass = 0; pass < 4; pass++) {
        const int shift = 16 * pass;
        memset(count, 0, 65536 * sizeof *count);
        for (size_t i = 0; i < n; i++)
            count[(a[i] >> shift) & 0xffff]++;
        size_t sum = 0;
        for (size_t d = 0; d < 65536; d++) {
            size_t c = count[d];
            count[d] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++)
            tmp[count[(a[i] >> shift) & 0xffff]++] = a[i];
        memcpy(a, tmp, n * sizeof *a);
    }
    free(tmp);
    free(count);
    return 0;
}

static size_t find_root(size_t *parent, size_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

/* Is the link of a vertex (pairs (a[k], b[k]), k < n) one cycle? */
static bool single_cycle(const int32_t *la, const int32_t *lb, size_t n, bool *used)
{
    if (n < 3)
        return false;
    for (size_t k = 0; k < n; k++)
        used[k] = false;
    /* every link vertex must appear exactly twice */
    for (size_t k = 0; k < n; k++) {
        int ca = 0, cb = 0;
        for (size_t q = 0; q < n; q++) {
            ca += (la[q] == la[k]) + (lb[q] == la[k]);
            cb += (la[q] == lb[k]) + (lb[q] == lb[k]);
        }
        if (ca != 2 || cb != 2)
            return false;
    }
    /* walk the cycle from the first edge */
    size_t walked = 1;
    used[0] = true;
    int32_t start = la[0], cur = lb[0];
    while (cur != start) {
        bool step = false;
        for (size_t q = 0; q < n && !step; q++) {
            if (used[q])
                continue;
            if (la[q] == cur) {
                cur = lb[q];
                step = true;
            } else if (lb[q] == cur) {
                cur = la[q];
                step = true;
            }
            if (step) {
                used[q] = true;
                walked++;
            }
        }
        if (!step)
            return false;
    }
    return walked == n;
}

int ls_mesh_topology(const mf_mesh *m, ls_topology *t)
{
    memset(t, 0, sizeof *t);
    const size_t nt = m->ntris, nv = m->nverts;
    t->faces = nt;
    uint64_t *edges = malloc((nt ? 3 * nt : 1) * sizeof *edges);
    size_t *parent = malloc((nv ? nv : 1) * sizeof *parent);
    size_t *vstart = calloc(nv + 1, sizeof *vstart);
    int32_t *vtri = malloc((nt ? 3 * nt : 1) * sizeof *vtri);
    if (!edges || !parent || !vstart || !vtri) {
        free(edges);
        free(parent);
        free(vstart);
        free(vtri);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory checking a mesh of %zu triangles", nt);
    }
    for (size_t v = 0; v < nv; v++)
        parent[v] = v;
    for (size_t f = 0; f < nt; f++)
        for (int e = 0; e < 3; e++) {
            uint64_t a = (uint64_t)m->tri[3 * f + e], b = (uint64_t)m->tri[3 * f + (e + 1) % 3];
            edges[3 * f + e] = a < b ? a << 32 | b : b << 32 | a;
            size_t ra = find_root(parent, a), rb = find_root(parent, b);
            if (ra != rb)
                parent[ra] = rb;
            vstart[a + 1]++;
        }
    int rc = sort_keys(edges, 3 * nt);
    if (rc == 0) {
        for (size_t i = 0; i < 3 * nt;) {
            size_t j = i;
            while (j < 3 * nt && edges[j] == edges[i])
                j++;
            t->edges++;
            if (j - i == 1)
                t->boundary_edges++;
            else if (j - i > 2)
                t->nonmanifold_edges++;
            i = j;
        }
        /* vertices in use, components */
        for (size_t v = 0; v < nv; v++) {
            if (vstart[v + 1] == 0)
                continue;
            t->vertices++;
            if (find_root(parent, v) == v)
                t->components++;
        }
        /* triangles around each vertex */
        for (size_t v = 0; v < nv; v++)
            vstart[v + 1] += vstart[v];
        size_t *fill = malloc((nv ? nv : 1) * sizeof *fill);
        if (!fill) {
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory checking a mesh");
        } else {
            memcpy(fill, vstart, nv * sizeof *fill);
            for (size_t f = 0; f < nt; f++)
                for (int e = 0; e < 3; e++)
                    vtri[fill[m->tri[3 * f + e]]++] = (int32_t)f;
            free(fill);
            size_t maxdeg = 0;
            for (size_t v = 0; v < nv; v++)
                if (vstart[v + 1] - vstart[v] > maxdeg)
                    maxdeg = vstart[v + 1] - vstart[v];
            int32_t *la = malloc((maxdeg ? maxdeg : 1) * sizeof *la);
            int32_t *lb = malloc((maxdeg ? maxdeg : 1) * sizeof *lb);
            bool *used = malloc(maxdeg ? maxdeg : 1);
            if (!la || !lb || !used)
                rc = MF_ERROR(MF_ERR_MEMORY, "out of memory checking a mesh");
            for (size_t v = 0; v < nv && rc == 0; v++) {
                size_t n = vstart[v + 1] - vstart[v];
                if (n == 0)
                    continue;
                for (size_t q = 0; q < n; q++) {
                    const int32_t *tr = &m->tri[3 * (size_t)vtri[vstart[v] + q]];
                    int at = tr[0] == (int32_t)v ? 0 : (tr[1] == (int32_t)v ? 1 : 2);
                    la[q] = tr[(at + 1) % 3];
                    lb[q] = tr[(at + 2) % 3];
                }
                if (!single_cycle(la, lb, n, used))
                    t->nonmanifold_vertices++;
            }
            free(la);
            free(lb);
            free(used);
        }
    }
    t->euler = (long)t->vertices - (long)t->edges + (long)t->faces;
    t->closed = t->boundary_edges == 0 && t->nonmanifold_edges == 0;
    t->manifold = t->nonmanifold_edges == 0 && t->nonmanifold_vertices == 0;
    free(edges);
    free(parent);
    free(vstart);
    free(vtri);
    return rc;
}
