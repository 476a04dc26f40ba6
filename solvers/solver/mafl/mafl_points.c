/* mafl_points.c: where the number of points changes (section 3.3, eq. 22).
 *
 * After the Eulerian phase, at r^{n+1}:
 *  - merge: of two fluid points closer than removeDistance l0 the newer
 *    (higher id) is removed;
 *  - holes: a site of the scene's lattice near a fluid point with a number
 *    density deficit, with no point within holeDistance l0 and at least
 *    holeDensity of the neighbours a full lattice site has within the
 *    number-density radius (so inside the fluid, not beyond its surface),
 *    gets a new fluid point. Its values are those of the closest
 *    old point after the Eulerian phase, f^L(r_cl - u^a dt) (eq. 22).
 * New points get fresh ids (mf_particles_add); ids are never reused.
 *
 * On several ranks each rank decides for its own points, with copies of
 * the other ranks' points within reach: a pair across ranks is merged by
 * the owner of the newer point, and a hole is filled by the owner of its
 * closest point (the nearest, lowest id first, which both ranks find
 * alike), so no point is added twice. A chain of three points within
 * removeDistance across a rank boundary may lose one point more than the
 * serial run, which decides in index order. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mafl.h"
#include "mf_error.h"

static inline bool carries_values(int kind)
{
    return kind == MF_FLUID || kind == MF_INLET || kind == MF_OUTLET;
}

/* Lattice site keys: integer coordinates relative to d->lattice, 21 bits each. */
#define SITE_BIAS ((int64_t)1 << 20)

static bool site_key(const mafl_data *d, int dim, const double x[3], const long off[3], double l0,
                     uint64_t *key)
{
    uint64_t k = 0;
    for (int a = 0; a < dim; a++) {
        double m = floor((x[a] - d->lattice[a]) / l0 + 0.5) + (double)off[a];
        if (!(fabs(m) < (double)(SITE_BIAS - 1)))
            return false;
        k |= (uint64_t)((int64_t)m + SITE_BIAS) << (21 * a);
    }
    *key = k;
    return true;
}

static void site_position(const mafl_data *d, int dim, uint64_t key, double l0, double x[3])
{
    x[0] = x[1] = x[2] = 0;
    for (int a = 0; a < dim; a++) {
        int64_t m = (int64_t)((key >> (21 * a)) & ((1u << 21) - 1)) - SITE_BIAS;
        x[a] = d->lattice[a] + (double)m * l0;
    }
}

static int by_key(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

typedef struct merge_ctx {
    mafl_data *d;
    const mf_particles *p;
    size_t i;
    double dmin;
} merge_ctx;

/* i goes if an older fluid point (not itself going) is closer than dmin. */
static inline bool merge_point(void *acc, const void *ctx, size_t j, const double r[3], double d2)
{
    (void)r;
    const merge_ctx *c = ctx;
    const mf_particles *p = c->p;
    if (j == c->i || p->kind[j] != MF_FLUID || c->d->remove[j] || p->id[j] > p->id[c->i])
        return true;
    if (d2 < c->dmin * c->dmin) {
        *(bool *)acc = true;
        return false;
    }
    return true;
}

/* Mark the newer of each pair of fluid points closer than dmin (in index
 * order: a point marked earlier no longer removes another). */
static size_t mark_merges(mafl_data *d, const mf_particles *p, double dmin)
{
    size_t count = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const merge_ctx c = {d, p, i, dmin};
        bool close = false;
        mf_grid_near(d->grid, &p->pos[3 * i], merge_point, &c, &close);
        if (close) {
            d->remove[i] = 1;
            count++;
        }
    }
    return count;
}

typedef struct hole {
    double x[3];
    size_t closest;
} hole;

/* Neighbours a site of a full lattice has within re. */
static double full_count(int dim, double re, double l0)
{
    const long m = (long)ceil(re / l0);
    double count = 0;
    for (long k = dim == 3 ? -m : 0; k <= (dim == 3 ? m : 0); k++)
        for (long j = -m; j <= m; j++)
            for (long i = -m; i <= m; i++) {
                double r = l0 * sqrt((double)(i * i + j * j + k * k));
                if (r > 0 && r < re)
                    count++;
            }
    return count;
}

typedef struct hole_ctx {
    const mafl_data *d;
    const mf_particles *p;
    double dmin, re;
    bool by_id; /* equal distances: the lowest id is the closest */
} hole_ctx;

typedef struct hole_acc {
    double count, walls, best, best_any; /* walls: neighbours that carry no values */
    size_t closest, nearest;
    bool occupied; /* a point closer than dmin */
} hole_acc;

static inline bool hole_point(void *acc, const void *ctx, size_t j, const double r[3], double d2)
{
    (void)r;
    const hole_ctx *c = ctx;
    hole_acc *a = acc;
    if (c->d->remove[j])
        return true;
    double dist = sqrt(d2);
    if (dist < c->dmin) {
        a->occupied = true;
        return false;
    }
    if (dist < c->re) {
        a->count++;
        a->walls += !carries_values(c->p->kind[j]);
    }
    if (dist < a->best_any) {
        a->best_any = dist;
        a->nearest = j;
    }
    if (carries_values(c->p->kind[j]) &&
        (dist < a->best ||
         (c->by_id && dist == a->best && c->p->id[j] < c->p->id[a->closest]))) {
        a->best = dist;
        a->closest = j;
    }
    return true;
}

/* Is the site x a hole? No point closer than holeDistance, and at least
 * holeDensity of a full lattice's neighbours within re (a count, not the
 * singular weight: one close point must not make an empty site look full),
 * counted on the fluid's side: the fluid points among the sites that are
 * not wall, fluid >= holeDensity (full - walls). Counted with the walls, a
 * site above a free surface beside a wall has the wall above the surface
 * to make it look full: on a resting box with moving points the contact
 * lines grew a column of new points up each side wall (+5.5% in 2 s).
 * Then *closest is the nearest point carrying values and *nearest the
 * nearest point of any kind. */
static bool is_hole(const mafl_data *d, const mf_particles *p, const double x[3], double l0,
                    double full, size_t *closest, size_t *nearest)
{
    /* On several ranks ties are broken alike on every rank (lowest id). */
    const hole_ctx c = {d, p, d->s.hole_distance * l0, d->mps->k_nd.re, d->halo != NULL};
    hole_acc a = {0, 0, INFINITY, INFINITY, *closest, *nearest, false};
    mf_grid_near(d->grid, x, hole_point, &c, &a);
    *closest = a.closest;
    *nearest = a.nearest;
    if (a.occupied)
        return false;
    return isfinite(a.best) && a.count - a.walls >= d->s.hole_density * (full - a.walls);
}

/* A hole is found the first step its nearest point is more than
 * holeDistance l0 away, so a site filled at once would be between
 * holeDistance and holeDistance + |u^c| dt from it: where points stream
 * away from an inlet that packed the new columns about 0.95 l0 apart and
 * the count grew. The new point goes to l0 from its nearest point instead,
 * along the line from that point through the site (a shift of at most
 * (1 - holeDistance) l0). */
static void space_from_nearest(const mf_particles *p, size_t nearest, double l0, double x[3])
{
    const double *xn = &p->pos[3 * nearest];
    double r[3] = {x[0] - xn[0], x[1] - xn[1], x[2] - xn[2]};
    double len = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (!(len > 0) || len >= l0)
        return;
    for (int a = 0; a < 3; a++)
        x[a] = xn[a] + r[a] * (l0 / len);
}

/* Candidate sites: around fluid points whose number density (at r*, from
 * the MPS phase) falls short of n0, the only places a hole can be. */
static int find_holes(mafl_data *d, const mf_sim *sim, hole **out, size_t *nout)
{
    const mf_particles *p = sim->p;
    const double l0 = sim->l0, n0 = d->mps->k_nd.n0;
    const double *nd = mf_particles_fd(p, d->mps->f_number_density);
    const int dim = sim->dim;
    const int per = dim == 3 ? 27 : 9;
    size_t ncand = 0, cap = 0;
    uint64_t *keys = NULL;
    int rc = 0;
    for (size_t i = 0; i < p->n_owned && rc == 0; i++) {
        if (p->kind[i] != MF_FLUID || d->remove[i] || !(nd[i] < 0.99 * n0))
            continue;
        if (ncand + (size_t)per > cap) {
            cap = 2 * cap + 1024;
            if (mf_resize(&keys, cap, sizeof *keys)) {
                rc = MF_ERROR(MF_ERR_MEMORY, "out of memory looking for holes");
                break;
            }
        }
        for (long oz = dim == 3 ? -1 : 0; oz <= (dim == 3 ? 1 : 0); oz++)
            for (long oy = -1; oy <= 1; oy++)
                for (long ox = -1; ox <= 1; ox++) {
                    long off[3] = {ox, oy, oz};
                    if (site_key(d, dim, &p->pos[3 * i], off, l0, &keys[ncand]))
                        ncand++;
                }
    }
    *out = NULL;
    *nout = 0;
    if (rc != 0 || ncand == 0) {
        free(keys);
        return rc;
    }
    qsort(keys, ncand, sizeof *keys, by_key);
    const double full = full_count(dim, d->mps->k_nd.re, l0);
    hole *holes = NULL;
    size_t nholes = 0, hcap = 0;
    for (size_t k = 0; k < ncand; k++) {
        if (k > 0 && keys[k] == keys[k - 1])
            continue;
        double x[3];
        site_position(d, dim, keys[k], l0, x);
        size_t closest = 0, nearest = 0;
        if (!is_hole(d, p, x, l0, full, &closest, &nearest) || closest >= p->n_owned)
            continue; /* (closest beyond n_owned: the other rank's hole) */
        if (d->s.hole_spacing)
            space_from_nearest(p, nearest, l0, x);
        if (nholes == hcap) {
            hcap = 2 * hcap + 64;
            if (mf_resize(&holes, hcap, sizeof *holes)) {
                free(holes);
                free(keys);
                return MF_ERROR(MF_ERR_MEMORY, "out of memory for new points");
            }
        }
        memcpy(holes[nholes].x, x, sizeof x);
        holes[nholes++].closest = closest;
    }
    free(keys);
    *out = holes;
    *nout = nholes;
    return 0;
}

/* eq. 22: a new point takes every value of the closest old point. */
static int add_point(mafl_data *d, mf_sim *sim, const hole *h)
{
    mf_particles *p = sim->p;
    size_t cl = h->closest, idx = p->n;
    double v[3];
    memcpy(v, &p->vel[3 * cl], sizeof v);
    MF_CALL(mf_particles_add(p, MF_FLUID, h->x, v, NULL));
    for (int f = 0; f < p->nfields; f++) {
        mf_field *fd = &p->field[f];
        if (f == d->f_point_vel || f == d->f_conv_vel || f == d->f_kind)
            continue;
        size_t es = (size_t)fd->ncomp * (fd->type == MF_FIELD_INT32 ? sizeof(int32_t)
                                                                      : sizeof(double));
        memcpy((char *)fd->data + idx * es, (const char *)fd->data + cl * es, es);
    }
    mf_particles_fi(p, d->f_kind)[idx] = MF_FLUID;
    mf_particles_fi(p, d->mps->f_flags)[idx] = 0;
    return 0;
}

int mafl_update_points(mafl_data *d, mf_sim *sim)
{
    mf_particles *p = sim->p;
    const double l0 = sim->l0;
    d->last_added = d->last_removed = 0;
    const double dmerge = d->s.remove_distance * l0;
    if (dmerge <= 0 && !d->s.add_points)
        return 0;
    double cell = d->mps->k_nd.re;
    if (d->s.hole_distance * l0 > cell)
        cell = d->s.hole_distance * l0;
    /* Copies reach a site's neighbours: sites lie within sqrt(3) l0 of a
     * point, their neighbours within the number-density radius. */
    MF_CALL(mafl_copies(d, sim, cell + 2 * l0, false));
    MF_CALL(mf_neighbours_grid(sim->neighbours, p, cell, &d->grid));
    const size_t n_old = p->n_owned;
    memset(d->remove, 0, p->n);
    size_t merged = dmerge > 0 ? mark_merges(d, p, dmerge) : 0;
    hole *holes = NULL;
    size_t nholes = 0;
    int rc = d->s.add_points ? find_holes(d, sim, &holes, &nholes) : 0;
    if (d->halo)
        mf_halo_drop(d->halo, p); /* before any point is added */
    MF_CALL(mf_parallel_agree(sim->par, rc));
    for (size_t k = 0; k < nholes && rc == 0; k++)
        rc = add_point(d, sim, &holes[k]);
    free(holes);
    MF_CALL(rc);
    if (merged) {
        uint8_t *flag = calloc(p->n, 1);
        if (!flag)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory removing points");
        memcpy(flag, d->remove, n_old);
        size_t removed = 0;
        rc = mf_particles_remove(p, flag, &removed);
        free(flag);
        MF_CALL(rc);
        d->last_removed = removed;
    }
    d->last_added = nholes;
    d->total_added += d->last_added;
    d->total_removed += d->last_removed;
    return 0;
}
