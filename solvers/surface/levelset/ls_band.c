/* ls_band.c: the narrow band around the zero level.
 *
 * phi is stored in 8^3 bricks (ls_bricks) that hold band points only. The
 * band is built from seeds, points next to the zero level whose values are
 * kept as they are (so the zero level does not move when the band is
 * rebuilt), by fast marching (Sethian 1996) outward to a rim of
 * width + 2 cells: the first-order upwind solution of |grad phi| = 1, with
 * the sign of the upwind neighbour. The queue is a bucket queue of width
 * 1/16 cell (Yatziv et al. 2006, "O(N) implementation of the fast marching
 * algorithm"): linear time, ordering errors below the bucket width.
 *
 * Points with |phi| <= width are evolved (the state vector of ARKODE);
 * the rim beyond them is frozen and serves as the boundary of the stencils.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "levelset.h"

#define BUCKET 0.0625

void ls_band_init(ls_band *band, double width, size_t mem_limit)
{
    memset(band, 0, sizeof *band);
    ls_bricks_init(&band->b);
    band->width = width;
    band->rim = width + 2;
    band->mem_limit = mem_limit;
}

void ls_band_free(ls_band *band)
{
    ls_bricks_free(&band->b);
    free(band->phi);
    free(band->F);
    free(band->flag);
    free(band->idx);
    free(band->nb);
    free(band->act);
    double width = band->width;
    size_t limit = band->mem_limit;
    ls_band_init(band, width, limit);
}

void ls_band_clear(ls_band *band)
{
    ls_bricks_clear(&band->b);
    band->nact = 0;
    free(band->nb);
    band->nb = NULL;
}

size_t ls_band_memory(const ls_band *band)
{
    return ls_bricks_memory(&band->b) +
           band->cap * LS_B3 * (sizeof(double) + sizeof(float) + 1 + sizeof(int32_t)) +
           (band->nb ? band->b.n * 27 * sizeof(int32_t) : 0) + band->cap_act * sizeof(uint32_t);
}

int ls_band_brick(ls_band *band, int32_t bx, int32_t by, int32_t bz, int32_t *index)
{
    bool added;
    MF_CALL(ls_bricks_insert(&band->b, bx, by, bz, index, &added));
    if (!added)
        return 0;
    if (band->b.n > band->cap) {
        size_t cap = band->cap ? 2 * band->cap : 1024;
        const size_t per = LS_B3 * (sizeof(double) + sizeof(float) + 1 + sizeof(int32_t));
        if ((double)cap * per + ls_bricks_memory(&band->b) > (double)band->mem_limit) {
            cap = band->b.n + band->b.n / 4;
            if ((double)cap * per + ls_bricks_memory(&band->b) > (double)band->mem_limit)
                return MF_ERROR(MF_ERR_MEMORY,
                                "the narrow band needs more than %zu bricks of 8^3 cells (%.3g "
                                "GB): more than the memory limit of %.3g GB (maxMemory); use a "
                                "coarser gridSpacing",
                                band->b.n, (double)band->b.n * per / 1073741824.0,
                                band->mem_limit / 1073741824.0);
        }
        if (mf_resize(&band->phi, cap * LS_B3, sizeof *band->phi) ||
            mf_resize(&band->F, cap * LS_B3, sizeof *band->F) ||
            mf_resize(&band->flag, cap * LS_B3, 1) ||
            mf_resize(&band->idx, cap * LS_B3, sizeof *band->idx))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for a band of %zu bricks", cap);
        band->cap = cap;
    }
    const size_t o = (size_t)*index * LS_B3;
    memset(band->flag + o, 0, LS_B3);
    for (int q = 0; q < LS_B3; q++) {
        band->phi[o + q] = 0;
        band->F[o + q] = 0;
        band->idx[o + q] = LS_NONE;
    }
    return 0;
}

int ls_band_link(ls_band *band)
{
    free(band->nb);
    band->nb = NULL;
    MF_CALL(ls_bricks_neighbours(&band->b, &band->nb));
    return 0;
}

bool ls_band_lookup(const ls_band *band, int32_t x, int32_t y, int32_t z, double *phi, float *F)
{
    int32_t b = ls_bricks_find(&band->b, ls_brick_of(x), ls_brick_of(y), ls_brick_of(z));
    if (b == LS_NONE)
        return false;
    size_t o = (size_t)b * LS_B3 + ls_local_index(ls_local_of(x), ls_local_of(y), ls_local_of(z));
    if (!(band->flag[o] & LS_HAS_PHI))
        return false;
    if (phi)
        *phi = band->phi[o];
    if (F)
        *F = band->F[o];
    return true;
}

/* ---- fast marching ------------------------------------------------------- */

typedef struct bucket_queue {
    uint32_t **items;
    size_t *n, *cap;
    size_t nb;
} bucket_queue;

static int queue_push(bucket_queue *q, size_t bucket, uint32_t item)
{
    if (q->n[bucket] == q->cap[bucket]) {
        size_t cap = q->cap[bucket] ? 2 * q->cap[bucket] : 256;
        if (mf_resize(&q->items[bucket], cap, sizeof *q->items[bucket]))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory in fast marching");
        q->cap[bucket] = cap;
    }
    q->items[bucket][q->n[bucket]++] = item;
    return 0;
}

static void queue_free(bucket_queue *q)
{
    for (size_t k = 0; k < q->nb; k++)
        free(q->items[k]);
    free(q->items);
    free(q->n);
    free(q->cap);
}

/* Point handle: brick * 512 + local. */
static inline uint32_t handle(int32_t brick, int local) { return (uint32_t)brick * LS_B3 + (uint32_t)local; }

typedef struct fmm {
    ls_band *band;
    bucket_queue q;
} fmm;

/* Neighbour of handle h by one step along axis a (0..2), direction s (+-1):
 * within the brick directly, else through the hash (adding the brick when
 * `create`). Returns false when absent. */
static int neighbour(ls_band *band, uint32_t h, int a, int s, bool create, uint32_t *out,
                     bool *found)
{
    int32_t brick = (int32_t)(h / LS_B3);
    int l = (int)(h % LS_B3);
    int loc[3] = {l & 7, (l >> 3) & 7, l >> 6};
    loc[a] += s;
    if (loc[a] >= 0 && loc[a] < LS_B) {
        *out = handle(brick, ls_local_index(loc[0], loc[1], loc[2]));
        *found = true;
        return 0;
    }
    int32_t bc[3] = {band->b.coord[3 * brick], band->b.coord[3 * brick + 1],
                     band->b.coord[3 * brick + 2]};
    bc[a] += s;
    loc[a] &= 7;
    int32_t nbk = ls_bricks_find(&band->b, bc[0], bc[1], bc[2]);
    if (nbk == LS_NONE) {
        if (!create) {
            *found = false;
            return 0;
        }
        MF_CALL(ls_band_brick(band, bc[0], bc[1], bc[2], &nbk));
    }
    *out = handle(nbk, ls_local_index(loc[0], loc[1], loc[2]));
    *found = true;
    return 0;
}

/* Upwind update of point h from its accepted face neighbours. */
static int fmm_update(fmm *m, uint32_t h)
{
    ls_band *band = m->band;
    double mins[3];
    double best = INFINITY, sign = 1;
    for (int a = 0; a < 3; a++) {
        mins[a] = INFINITY;
        for (int s = -1; s <= 1; s += 2) {
            uint32_t nh;
            bool found;
            MF_CALL(neighbour(band, h, a, s, false, &nh, &found));
            if (!found || !(band->flag[nh] & LS_DONE))
                continue;
            double v = fabs(band->phi[nh]);
            if (v < mins[a])
                mins[a] = v;
            if (v < best) {
                best = v;
                sign = band->phi[nh] > 0 ? 1 : -1;
            }
        }
    }
    /* sort ascending */
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2 - i; j++)
            if (mins[j] > mins[j + 1]) {
                double t = mins[j];
                mins[j] = mins[j + 1];
                mins[j + 1] = t;
            }
    if (!isfinite(mins[0]))
        return 0;
    double u = mins[0] + 1;
    if (u > mins[1]) {
        double a = mins[0], b = mins[1];
        u = 0.5 * (a + b + sqrt(fmax(0.0, 2 - (a - b) * (a - b))));
        if (u > mins[2]) {
            double c = mins[2], s1 = a + b + c, s2 = a * a + b * b + c * c;
            double disc = s1 * s1 - 3 * (s2 - 1);
            u = (s1 + sqrt(fmax(0.0, disc))) / 3;
        }
    }
    if (u > band->rim)
        return 0;
    uint8_t *fl = &band->flag[h];
    if ((*fl & LS_HAS_PHI) && fabs(band->phi[h]) <= u)
        return 0;
    band->phi[h] = sign * u;
    *fl |= LS_HAS_PHI;
    size_t bucket = (size_t)(u / BUCKET);
    if (bucket >= m->q.nb)
        bucket = m->q.nb - 1;
    MF_CALL(queue_push(&m->q, bucket, h));
    return 0;
}

static int fmm_accept(fmm *m, uint32_t h)
{
    ls_band *band = m->band;
    band->flag[h] |= LS_DONE;
    for (int a = 0; a < 3; a++)
        for (int s = -1; s <= 1; s += 2) {
            uint32_t nh;
            bool found;
            /* A point whose neighbour is within the rim may need a brick that
             * does not exist yet: create it (the handle of h stays valid, as
             * handles are indices, not pointers). */
            MF_CALL(neighbour(band, h, a, s, fabs(band->phi[h]) + 1 <= band->rim, &nh, &found));
            if (found && !(band->flag[nh] & LS_DONE))
                MF_CALL(fmm_update(m, nh));
        }
    return 0;
}

/* Sort n handles by brick (counting sort on handle / 512, nbricks bricks);
 * count and tmp are scratch arrays grown as needed. */
static int sort_by_brick(uint32_t *h, size_t n, size_t nbricks, size_t **count, size_t *ncount,
                         uint32_t **tmp, size_t *ntmp)
{
    if (n < 2)
        return 0;
    if (*ncount < nbricks + 1) {
        if (mf_resize(count, nbricks + 1, sizeof **count))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory in fast marching");
        *ncount = nbricks + 1;
    }
    if (*ntmp < n) {
        if (mf_resize(tmp, n, sizeof **tmp))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory in fast marching");
        *ntmp = n;
    }
    size_t *c = *count;
    memset(c, 0, (nbricks + 1) * sizeof *c);
    for (size_t i = 0; i < n; i++)
        c[h[i] / LS_B3 + 1]++;
    for (size_t b = 0; b < nbricks; b++)
        c[b + 1] += c[b];
    for (size_t i = 0; i < n; i++)
        (*tmp)[c[h[i] / LS_B3]++] = h[i];
    memcpy(h, *tmp, n * sizeof *h);
    return 0;
}

int ls_band_from_seeds(ls_band *band, const ls_seed *seeds, size_t nseeds)
{
    ls_band_clear(band);
    fmm m = {.band = band};
    m.q.nb = (size_t)(band->rim / BUCKET) + 2;
    m.q.items = calloc(m.q.nb, sizeof *m.q.items);
    m.q.n = calloc(m.q.nb, sizeof *m.q.n);
    m.q.cap = calloc(m.q.nb, sizeof *m.q.cap);
    int rc = 0;
    if (!m.q.items || !m.q.n || !m.q.cap)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory in fast marching");
    uint32_t *hs = rc == 0 ? malloc((nseeds ? nseeds : 1) * sizeof *hs) : NULL;
    if (rc == 0 && !hs)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu seeds", nseeds);
    for (size_t k = 0; k < nseeds && rc == 0; k++) {
        const ls_seed *s = &seeds[k];
        int32_t b;
        rc = ls_band_brick(band, ls_brick_of(s->x), ls_brick_of(s->y), ls_brick_of(s->z), &b);
        if (rc != 0)
            break;
        uint32_t h = handle(b, ls_local_index(ls_local_of(s->x), ls_local_of(s->y),
                                              ls_local_of(s->z)));
        hs[k] = h;
        band->phi[h] = s->phi;
        band->flag[h] |= LS_HAS_PHI | LS_DONE | LS_SEED;
    }
    if (band->b.n > (size_t)UINT32_MAX / LS_B3 - 1 && rc == 0)
        rc = MF_ERROR(MF_ERR_MEMORY, "too many bricks in the band (%zu)", band->b.n);
    for (size_t k = 0; k < nseeds && rc == 0; k++)
        rc = fmm_accept(&m, hs[k]);
    size_t *count = NULL, ncount = 0;
    uint32_t *sorted = NULL;
    size_t nsorted = 0;
    for (size_t bk = 0; bk < m.q.nb && rc == 0; bk++) {
        /* A bucket holds points from all over the surface: processed in the
         * order they came, each access would miss the cache. Sorted by brick
         * first (a counting sort; the order within a bucket is free, its
         * points are within the bucket width of each other), the accesses
         * stay within a few bricks at a time. */
        rc = sort_by_brick(m.q.items[bk], m.q.n[bk], band->b.n, &count, &ncount, &sorted,
                           &nsorted);
        /* items may be appended to this very bucket while it is processed */
        for (size_t i = 0; i < m.q.n[bk] && rc == 0; i++) {
            uint32_t h = m.q.items[bk][i];
            if (band->flag[h] & LS_DONE)
                continue;
            rc = fmm_accept(&m, h);
        }
        free(m.q.items[bk]);
        m.q.items[bk] = NULL;
        m.q.n[bk] = m.q.cap[bk] = 0;
    }
    free(hs);
    free(count);
    free(sorted);
    queue_free(&m.q);
    if (rc == 0) {
        for (size_t q = 0; q < band->b.n * LS_B3; q++)
            band->flag[q] &= (uint8_t)~LS_DONE;
        rc = ls_band_link(band);
    }
    return rc;
}

/* ---- seeds --------------------------------------------------------------- */

typedef struct seed_list {
    ls_seed *s;
    size_t n, cap;
} seed_list;

static int seed_push(seed_list *l, int32_t x, int32_t y, int32_t z, double phi)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 4096;
        if (mf_resize(&l->s, cap, sizeof *l->s))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu seeds", cap);
        l->cap = cap;
    }
    l->s[l->n++] = (ls_seed){x, y, z, phi};
    return 0;
}

/* Value at the face neighbour of (brick, local) in a brick set with a value
 * array and an optional known-flag array; NAN when absent. */
static double face_value(const ls_bricks *b, const int32_t *nb, const float *v32,
                         const double *v64, const uint8_t *flag, int32_t brick, int i, int j,
                         int k)
{
    int bx = i < 0 ? -1 : (i >= LS_B ? 1 : 0), by = j < 0 ? -1 : (j >= LS_B ? 1 : 0),
        bz = k < 0 ? -1 : (k >= LS_B ? 1 : 0);
    int32_t nbk = brick;
    if (bx || by || bz) {
        if (nb) {
            nbk = nb[27 * brick + (bx + 1) + 3 * (by + 1) + 9 * (bz + 1)];
        } else {
            const int32_t *c = &b->coord[3 * brick];
            nbk = ls_bricks_find(b, c[0] + bx, c[1] + by, c[2] + bz);
        }
        if (nbk == LS_NONE)
            return NAN;
    }
    size_t o = (size_t)nbk * LS_B3 + ls_local_index(i & 7, j & 7, k & 7);
    if (flag && !(flag[o] & LS_HAS_PHI))
        return NAN;
    return v32 ? (double)v32[o] : v64[o];
}

int ls_crossing_seeds(const ls_crossing *c, ls_seed **seeds, size_t *n)
{
    seed_list l = {0};
    int rc = 0;
    for (size_t b = 0; b < c->b.n && rc == 0; b++) {
        const int32_t *bc = &c->b.coord[3 * b];
        const float *F = c->F + b * LS_B3;
        for (int k = 0; k < LS_B && rc == 0; k++)
            for (int j = 0; j < LS_B && rc == 0; j++)
                for (int i = 0; i < LS_B && rc == 0; i++) {
                    const double f0 = F[ls_local_index(i, j, k)];
                    const bool in = f0 > 0;
                    double inv2 = 0;
                    for (int a = 0; a < 3; a++) {
                        double tmin = INFINITY;
                        for (int s = -1; s <= 1; s += 2) {
                            int ii = i + (a == 0) * s, jj = j + (a == 1) * s, kk = k + (a == 2) * s;
                            double f1 = face_value(&c->b, NULL, c->F, NULL, NULL, (int32_t)b, ii,
                                                   jj, kk);
                            if (isnan(f1) || (f1 > 0) == in)
                                continue;
                            double t = f0 / (f0 - f1); /* where F crosses 0 on the edge */
                            if (t < tmin)
                                tmin = t;
                        }
                        if (isfinite(tmin)) {
                            tmin = fmax(tmin, 1e-3);
                            inv2 += 1 / (tmin * tmin);
                        }
                    }
                    if (inv2 > 0) {
                        double d = 1 / sqrt(inv2);
                        rc = seed_push(&l, LS_B * bc[0] + i, LS_B * bc[1] + j, LS_B * bc[2] + k,
                                       in ? d : -d);
                    }
                }
    }
    if (rc != 0) {
        free(l.s);
        return rc;
    }
    *seeds = l.s;
    *n = l.n;
    return 0;
}

int ls_band_interface(const ls_band *band, ls_seed **seeds, size_t *n)
{
    seed_list l = {0};
    int rc = 0;
    for (size_t b = 0; b < band->b.n && rc == 0; b++) {
        const int32_t *bc = &band->b.coord[3 * b];
        for (int k = 0; k < LS_B && rc == 0; k++)
            for (int j = 0; j < LS_B && rc == 0; j++)
                for (int i = 0; i < LS_B && rc == 0; i++) {
                    size_t o = b * LS_B3 + ls_local_index(i, j, k);
                    if (!(band->flag[o] & LS_HAS_PHI) || fabs(band->phi[o]) > 2)
                        continue;
                    const bool in = band->phi[o] > 0;
                    bool cross = false;
                    for (int a = 0; a < 3 && !cross; a++)
                        for (int s = -1; s <= 1 && !cross; s += 2) {
                            double v = face_value(&band->b, band->nb, NULL, band->phi, band->flag,
                                                  (int32_t)b, i + (a == 0) * s, j + (a == 1) * s,
                                                  k + (a == 2) * s);
                            cross = !isnan(v) && (v > 0) != in;
                        }
                    if (cross)
                        rc = seed_push(&l, LS_B * bc[0] + i, LS_B * bc[1] + j, LS_B * bc[2] + k,
                                       band->phi[o]);
                }
    }
    if (rc != 0) {
        free(l.s);
        return rc;
    }
    *seeds = l.s;
    *n = l.n;
    return 0;
}

int ls_band_within(const ls_band *band, double dist, ls_seed **seeds, size_t *n)
{
    seed_list l = {0};
    int rc = 0;
    for (size_t b = 0; b < band->b.n && rc == 0; b++) {
        const int32_t *bc = &band->b.coord[3 * b];
        for (int q = 0; q < LS_B3 && rc == 0; q++) {
            size_t o = b * LS_B3 + (size_t)q;
            if ((band->flag[o] & LS_HAS_PHI) && fabs(band->phi[o]) <= dist)
                rc = seed_push(&l, LS_B * bc[0] + (q & 7), LS_B * bc[1] + ((q >> 3) & 7),
                               LS_B * bc[2] + (q >> 6), band->phi[o]);
        }
    }
    if (rc != 0) {
        free(l.s);
        return rc;
    }
    *seeds = l.s;
    *n = l.n;
    return 0;
}

/* ---- F on the band ------------------------------------------------------- */

int ls_band_fill_F(ls_band *band, const ls_field *f, const ls_bricks *from_b,
                   const float *from_F)
{
    const size_t nb = band->b.n;
    int failed = 0;
#pragma omp parallel
    {
        float *buf = malloc(LS_B3 * sizeof *buf);
        if (!buf) {
#pragma omp atomic write
            failed = 1;
        }
#pragma omp for schedule(dynamic, 8)
        for (size_t b = 0; b < nb; b++) {
            if (!buf)
                continue;
            const size_t o = b * LS_B3;
            bool need = false;
            for (int q = 0; q < LS_B3 && !need; q++)
                need = !(band->flag[o + q] & LS_HAS_F);
            if (!need)
                continue;
            const int32_t *c = &band->b.coord[3 * b];
            int32_t src = from_b ? ls_bricks_find(from_b, c[0], c[1], c[2]) : LS_NONE;
            const float *vals;
            if (src != LS_NONE) {
                vals = from_F + (size_t)src * LS_B3;
            } else {
                ls_field_brick(f, c[0], c[1], c[2], LS_B, buf);
                vals = buf;
            }
            for (int q = 0; q < LS_B3; q++)
                if (!(band->flag[o + q] & LS_HAS_F)) {
                    band->F[o + q] = vals[q];
                    band->flag[o + q] |= LS_HAS_F;
                }
        }
        free(buf);
    }
    if (failed)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory evaluating F on the band");
    return 0;
}

/* ---- the active set ------------------------------------------------------ */

int ls_band_activate(ls_band *band)
{
    size_t n = 0;
    const size_t np = band->b.n * LS_B3;
    for (size_t q = 0; q < np; q++) {
        band->flag[q] &= (uint8_t)~LS_ACTIVE;
        band->idx[q] = LS_NONE;
        if ((band->flag[q] & LS_HAS_PHI) && fabs(band->phi[q]) <= band->width)
            n++;
    }
    if (n > (size_t)INT32_MAX)
        return MF_ERROR(MF_ERR_MEMORY, "%zu active band points: too many", n);
    if (n > band->cap_act) {
        if (mf_resize(&band->act, n, sizeof *band->act))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu active band points", n);
        band->cap_act = n;
    }
    size_t k = 0;
    for (size_t q = 0; q < np; q++)
        if ((band->flag[q] & LS_HAS_PHI) && fabs(band->phi[q]) <= band->width) {
            band->flag[q] |= LS_ACTIVE;
            band->idx[q] = (int32_t)k;
            band->act[k++] = (uint32_t)q;
        }
    band->nact = n;
    return 0;
}
