/* ls_detect.c: find the bricks that the zero level of a field crosses.
 *
 * The field is only non-trivial in the bricks a particle's support reaches
 * (ls_field's binning); elsewhere it is the constant offset (< 0, outside).
 * Those bricks are scanned once:
 *   - coarse pass (when the grid is finer than 0.6 l0): the field on a
 *     lattice of stride s cells with s h <= 0.6 l0; a brick is kept when one
 *     of its coarse cubes changes sign or has a corner with |F| below a
 *     margin. A feature of the zero level smaller than about one particle
 *     spacing that falls between coarse nodes can be missed: the price of not
 *     evaluating the whole volume at the fine spacing;
 *   - fine pass: the field at the brick's 8^3 points and one more layer on
 *     the + sides; every grid edge of the 6-tetrahedra split (3 axes, 3 face
 *     diagonals, the cube diagonal) with a sign change marks the bricks of
 *     both its ends. Marked bricks keep their 512 values; a brick marked from
 *     a neighbour but not yet evaluated is evaluated in a further round.
 * The scan streams through the bricks in chunks: only crossing bricks are
 * stored, so memory follows the surface. Time of the coarse pass follows the
 * volume at the coarse spacing (the fine work follows the surface). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "levelset.h"

#define CHUNK 256
#define N9 9
#define N9_3 (N9 * N9 * N9)

void ls_crossing_init(ls_crossing *c)
{
    memset(c, 0, sizeof *c);
    ls_bricks_init(&c->b);
}

void ls_crossing_free(ls_crossing *c)
{
    ls_bricks_free(&c->b);
    free(c->F);
    ls_crossing_init(c);
}

static int crossing_add(ls_crossing *c, const int32_t *bc, const float *v9, size_t mem_limit,
                        int32_t *index, bool *added)
{
    MF_CALL(ls_bricks_insert(&c->b, bc[0], bc[1], bc[2], index, added));
    if (c->b.n > c->cap) {
        size_t cap = c->cap ? 2 * c->cap : 1024;
        if ((double)cap * LS_B3 * sizeof(float) + ls_bricks_memory(&c->b) > (double)mem_limit)
            return MF_ERROR(MF_ERR_MEMORY,
                            "the surface crosses %zu bricks of 8^3 cells: more than the memory "
                            "limit of %.3g GB allows (maxMemory); use a coarser gridSpacing",
                            c->b.n, mem_limit / 1073741824.0);
        if (mf_resize(&c->F, cap * LS_B3, sizeof *c->F))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu crossing bricks", cap);
        c->cap = cap;
    }
    if (*added) {
        float *dst = c->F + (size_t)*index * LS_B3;
        for (int k = 0; k < LS_B; k++)
            for (int j = 0; j < LS_B; j++)
                memcpy(dst + LS_B * (j + LS_B * k), v9 + N9 * (j + N9 * k), LS_B * sizeof *dst);
    }
    return 0;
}

/* Sign-change edges with a lower end in the brick; returns whether any, and
 * sets via[d] for the 7 neighbours (+x, +y, ... combinations, d = dx + 2 dy +
 * 4 dz) that hold an upper end. */
static bool find_crossings(const float *v, bool via[8])
{
    bool any = false;
    for (int d = 0; d < 8; d++)
        via[d] = false;
    for (int k = 0; k < LS_B; k++)
        for (int j = 0; j < LS_B; j++)
            for (int i = 0; i < LS_B; i++) {
                const bool in = v[i + N9 * (j + N9 * k)] > 0;
                for (int d = 1; d < 8; d++) {
                    int di = d & 1, dj = (d >> 1) & 1, dk = (d >> 2) & 1;
                    int ii = i + di, jj = j + dj, kk = k + dk;
                    if ((v[ii + N9 * (jj + N9 * kk)] > 0) != in) {
                        any = true;
                        via[(ii >> 3) | (jj >> 3) << 1 | (kk >> 3) << 2] = true;
                    }
                }
            }
    return any;
}

/* Coarse pass: is the brick worth a fine look? */
static bool coarse_suspicious(const ls_field *f, const int32_t *bc, int s, double margin,
                              float *buf)
{
    ls_field_brick_coarse(f, bc[0], bc[1], bc[2], s, buf);
    const int n = LS_B / s + 1;
    for (int q = 0; q < n * n * n; q++)
        if (fabsf(buf[q]) < margin)
            return true;
    for (int k = 0; k + 1 < n; k++)
        for (int j = 0; j + 1 < n; j++)
            for (int i = 0; i + 1 < n; i++) {
                bool in = buf[i + n * (j + n * k)] > 0;
                for (int d = 1; d < 8; d++) {
                    int ii = i + (d & 1), jj = j + ((d >> 1) & 1), kk = k + ((d >> 2) & 1);
                    if ((buf[ii + n * (jj + n * kk)] > 0) != in)
                        return true;
                }
            }
    return false;
}

typedef struct work_list {
    int32_t *c; /* 3 per brick */
    size_t n, cap;
} work_list;

static int work_push(work_list *w, int32_t x, int32_t y, int32_t z)
{
    if (w->n == w->cap) {
        size_t cap = w->cap ? 2 * w->cap : 1024;
        if (mf_resize(&w->c, 3 * cap, sizeof *w->c))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for a list of %zu bricks", cap);
        w->cap = cap;
    }
    w->c[3 * w->n] = x;
    w->c[3 * w->n + 1] = y;
    w->c[3 * w->n + 2] = z;
    w->n++;
    return 0;
}

/* The fine pass over a work list: crossing bricks go into out (with their
 * values); bricks marked from a neighbour and not in out yet go to next.
 * `force` stores every brick of the list (they were marked by a neighbour). */
static int fine_pass(const ls_field *f, const work_list *w, bool force, size_t mem_limit,
                     ls_crossing *out, work_list *next)
{
    float *vals = malloc((size_t)CHUNK * N9_3 * sizeof *vals);
    uint8_t *flags = malloc(CHUNK);
    if (!vals || !flags) {
        free(vals);
        free(flags);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the zero-level search");
    }
    int rc = 0;
    for (size_t c0 = 0; c0 < w->n && rc == 0; c0 += CHUNK) {
        size_t nc = w->n - c0 < CHUNK ? w->n - c0 : CHUNK;
#pragma omp parallel for schedule(dynamic, 4)
        for (size_t q = 0; q < nc; q++) {
            const int32_t *bc = &w->c[3 * (c0 + q)];
            float *v = vals + q * N9_3;
            ls_field_brick(f, bc[0], bc[1], bc[2], N9, v);
            bool via[8];
            bool any = find_crossings(v, via);
            uint8_t fl = any ? 1 : 0;
            for (int d = 1; d < 8; d++)
                if (via[d])
                    fl |= (uint8_t)(1u << d);
            flags[q] = fl;
        }
        for (size_t q = 0; q < nc && rc == 0; q++) {
            const int32_t *bc = &w->c[3 * (c0 + q)];
            int32_t idx;
            bool added;
            if ((flags[q] & 1) || force)
                rc = crossing_add(out, bc, vals + q * N9_3, mem_limit, &idx, &added);
            for (int d = 1; d < 8 && rc == 0; d++) {
                if (!(flags[q] & (1u << d)))
                    continue;
                int32_t nx = bc[0] + (d & 1), ny = bc[1] + ((d >> 1) & 1),
                        nz = bc[2] + ((d >> 2) & 1);
                if (ls_bricks_find(&out->b, nx, ny, nz) == LS_NONE)
                    rc = work_push(next, nx, ny, nz);
            }
        }
    }
    free(vals);
    free(flags);
    return rc;
}

int ls_detect(const ls_field *f, double l0, size_t mem_limit, ls_crossing *out)
{
    ls_bricks_clear(&out->b);
    int s = 1;
    while (s < LS_B && 2 * s * f->h <= 0.6 * l0)
        s *= 2;
    work_list w = {0}, next = {0};
    int rc = 0;
    const size_t nt = f->touched.n;
    if (s == 1) {
        for (size_t k = 0; k < nt && rc == 0; k++) {
            const int32_t *c = &f->touched.coord[3 * k];
            rc = work_push(&w, c[0], c[1], c[2]);
        }
    } else {
        const int n = LS_B / s + 1;
        const double margin = 0.25 * fabs(f->offset);
        uint8_t *keep = malloc(nt ? nt : 1);
        if (!keep)
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for the zero-level search");
        if (rc == 0) {
#pragma omp parallel
            {
                float *buf = malloc((size_t)n * n * n * sizeof *buf);
#pragma omp for schedule(dynamic, 16)
                for (size_t k = 0; k < nt; k++)
                    keep[k] = buf ? coarse_suspicious(f, &f->touched.coord[3 * k], s, margin, buf)
                                  : 1;
                free(buf);
            }
            for (size_t k = 0; k < nt && rc == 0; k++)
                if (keep[k]) {
                    const int32_t *c = &f->touched.coord[3 * k];
                    rc = work_push(&w, c[0], c[1], c[2]);
                }
        }
        free(keep);
    }
    bool force = false;
    while (rc == 0 && w.n > 0) {
        next.n = 0;
        rc = fine_pass(f, &w, force, mem_limit, out, &next);
        /* next may hold duplicates and bricks added meanwhile: dedupe */
        work_list tmp = w;
        w = next;
        next = tmp;
        size_t m = 0;
        ls_bricks seen;
        ls_bricks_init(&seen);
        for (size_t k = 0; k < w.n && rc == 0; k++) {
            int32_t *c = &w.c[3 * k], idx;
            bool added;
            if (ls_bricks_find(&out->b, c[0], c[1], c[2]) != LS_NONE)
                continue;
            rc = ls_bricks_insert(&seen, c[0], c[1], c[2], &idx, &added);
            if (rc == 0 && added) {
                memmove(&w.c[3 * m], c, 3 * sizeof *c);
                m++;
            }
        }
        ls_bricks_free(&seen);
        w.n = m;
        force = true;
    }
    free(w.c);
    free(next.c);
    return rc;
}
