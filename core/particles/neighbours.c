/* neighbours.c: the neighbour service of mf_neighbours.h.
 *
 * Requests are grouped by the cell size that fixes their order (a class):
 * one grid and one list per class, at the largest radius of its requests
 * plus a skin. A list is kept while it still holds every pair a request
 * needs: with d the largest displacement of any particle since the build,
 * a pair closer than r now was closer than r + 2d then, so the list of
 * radius R serves radius r while r + 2d <= R (the particles and their ids
 * must also be the same, in the same slots). At an order point its j's are
 * re-sorted into the order of the current positions (mf_nlist_sort), which
 * is the order a fresh build would give: sums come out bit for bit the same
 * whether a list was kept or built.
 *
 * The skin adapts to the displacement a list meets at the first order point
 * after its build, times SKIN_FACTOR, between the set bounds (a list that
 * fails there takes the displacement it failed at). The MPS step builds at
 * r* (after the explicit phase moved the fluid by u* dt) and meets the next
 * order point at r^n of the next step, after the correction moved it by
 * u' dt only: the skin settles at a few times that small displacement, one
 * build a step instead of two, the list only slightly longer. A slow flow
 * keeps a list for many steps. A skin sized to survive several steps of a
 * fast flow costs more than it saves: every loop pays for the longer list,
 * and a build at radius R > cell size looks at more cells.
 */
#include "mf_neighbours.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_clock.h"
#include "mf_error.h"
#include "mf_pairs.h"

#define SKIN_FACTOR 2.5
/* The largest request of radius at most this share of its class's gets a
 * list of its own, made in the same pass (mf_nlist_build_pair): the
 * gradient at 2.1 l0 beside a Laplacian at 3.1 l0 visits half the pairs.
 * Smaller requests of the class use it too while it holds their pairs. A
 * build makes it when the last list's life had a use for it (the collision
 * model's radius in a 3-D case, where every operator has the same radius,
 * asks for pairs only where the sub-list no longer holds them: none is
 * made, and its memory is not spent). */
#define SUB_SHARE 0.8
/* A list serves radius r while r + 2d <= R (1 - MARGIN): rounding of the
 * distances cannot matter at that margin. */
#define MARGIN 1e-9

typedef struct nb_class {
    double cell;        /* the order's cell size */
    double radius;      /* largest radius of its requests */
    double skin;        /* of the next build */
    double list_radius; /* of the current list; 0: none */
    double d_first;     /* displacement at the first order point after the build; -1: none yet */
    double need;        /* the skin last asked for */
    unsigned long epoch; /* order point the list is in the order of */
    const mf_particles *store;
    mf_grid grid;
    mf_nlist list;
    int64_t *id0;       /* ids at the build, in the grid's (cell) order */
    size_t cap_id;
    mf_nlist sub;       /* the sub-list (see SUB_SHARE) */
    double sub_radius;  /* the request it serves; 0: none at the last build */
    double sub_list_radius; /* sub_radius + the skin of the build */
    bool sub_wanted;    /* a request the sub-list would have served came during this life */
    bool built_once;
    /* The cells the lists are in the order of (for re-sorting only the lists
     * that hold a particle that changed cell): */
    int cells_known;    /* CELLS_OF_BUILD, CELLS_KEPT (in cell0) or CELLS_UNKNOWN */
    uint32_t *cell0;    /* CELLS_KEPT: each particle's cell, the high half of its packed key */
    size_t cap_cell0;
} nb_class;

enum { CELLS_OF_BUILD = 0, CELLS_KEPT = 1, CELLS_UNKNOWN = 2 };

typedef struct nb_handle {
    double radius, cell; /* cell 0: shared, resolved at the first use */
    int cls;             /* -1 until resolved */
} nb_handle;

struct mf_neighbours {
    nb_handle *handle;
    int nhandles, cap_handles;
    nb_class *cls;
    int nclasses, cap_classes;
    unsigned long epoch;
    double skin_min, skin_max, skin_start; /* fractions of the cell */
    mf_grid points;     /* mf_neighbours_grid */
    mf_neighbours_stats stats;
};

int mf_neighbours_create(mf_neighbours **out)
{
    mf_neighbours *nb = calloc(1, sizeof *nb);
    if (!nb)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the neighbour service");
    nb->skin_min = 0.01;
    nb->skin_max = 0.25;
    nb->skin_start = 0.05;
    nb->epoch = 1;
    mf_grid_init(&nb->points);
    *out = nb;
    return 0;
}

double mf_neighbours_max_radius(const mf_neighbours *nb)
{
    double r = 0;
    for (int k = 0; nb && k < nb->nhandles; k++)
        r = fmax(r, nb->handle[k].radius);
    return r;
}

void mf_neighbours_destroy(mf_neighbours *nb)
{
    if (!nb)
        return;
    for (int c = 0; c < nb->nclasses; c++) {
        mf_grid_free(&nb->cls[c].grid);
        mf_nlist_free(&nb->cls[c].list);
        mf_nlist_free(&nb->cls[c].sub);
        free(nb->cls[c].id0);
        free(nb->cls[c].cell0);
    }
    mf_grid_free(&nb->points);
    free(nb->cls);
    free(nb->handle);
    free(nb);
}

int mf_neighbours_set_skin(mf_neighbours *nb, double min, double max, double start)
{
    if (!(min > 0) || !(max >= min) || !(max <= 0.5) || !(start >= min && start <= max))
        return MF_ERROR(MF_ERR_INPUT,
                        "neighbour skin: need 0 < min %g <= start %g <= max %g <= 0.5 (fractions "
                        "of the cell size)",
                        min, start, max);
    nb->skin_min = min;
    nb->skin_max = max;
    nb->skin_start = start;
    return 0;
}

/* The class of a cell size, created if new. */
static int class_of(mf_neighbours *nb, double cell, int *out)
{
    for (int c = 0; c < nb->nclasses; c++)
        if (nb->cls[c].cell == cell) {
            *out = c;
            return 0;
        }
    if (nb->nclasses == nb->cap_classes) {
        int cap = 2 * nb->cap_classes + 4;
        if (mf_resize(&nb->cls, (size_t)cap, sizeof *nb->cls))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for neighbour lists");
        nb->cap_classes = cap;
    }
    nb_class *c = &nb->cls[nb->nclasses];
    memset(c, 0, sizeof *c);
    c->cell = cell;
    c->skin = nb->skin_start * cell;
    mf_grid_init(&c->grid);
    mf_nlist_init(&c->list);
    mf_nlist_init(&c->sub);
    *out = nb->nclasses++;
    return 0;
}

/* h joins the class of this cell. */
static int join_class(mf_neighbours *nb, nb_handle *h, double cell)
{
    MF_CALL(class_of(nb, cell, &h->cls));
    nb_class *c = &nb->cls[h->cls];
    if (h->radius > c->radius)
        c->radius = h->radius;
    return 0;
}

int mf_neighbours_request(mf_neighbours *nb, double radius, double cell, int *handle)
{
    if (!nb)
        return MF_ERROR(MF_ERR_INPUT, "no neighbour service (mf_neighbours_create)");
    if (!(radius > 0) || !isfinite(radius) || !(cell >= 0) || !isfinite(cell) ||
        (cell > 0 && radius > cell))
        return MF_ERROR(MF_ERR_INPUT,
                        "neighbour request: radius %g must be positive and at most the cell "
                        "size %g (0: shared)",
                        radius, cell);
    if (nb->nhandles == nb->cap_handles) {
        int cap = 2 * nb->cap_handles + 8;
        if (mf_resize(&nb->handle, (size_t)cap, sizeof *nb->handle))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for neighbour requests");
        nb->cap_handles = cap;
    }
    nb_handle *h = &nb->handle[nb->nhandles];
    h->radius = radius;
    h->cell = cell;
    h->cls = -1;
    if (cell > 0)
        MF_CALL(join_class(nb, h, cell));
    *handle = nb->nhandles++;
    return 0;
}

/* A shared request takes the smallest cell already asked for that reaches. */
static int resolve(mf_neighbours *nb, nb_handle *h)
{
    if (h->cls >= 0)
        return 0;
    double best = INFINITY;
    for (int c = 0; c < nb->nclasses; c++)
        if (nb->cls[c].cell >= h->radius && nb->cls[c].cell < best)
            best = nb->cls[c].cell;
    MF_CALL(join_class(nb, h, isfinite(best) ? best : h->radius));
    return 0;
}

void mf_neighbours_moved(mf_neighbours *nb)
{
    if (nb)
        nb->epoch++;
}

/* Same particles in the same slots as at the build, and the largest
 * displacement since (NAN if not the same). */
static double displacement(const nb_class *c, const mf_particles *p)
{
    if (c->list_radius <= 0 || c->store != p || c->grid.np != p->n || c->grid.dim != p->dim ||
        c->list.n != p->n)
        return NAN;
    const size_t np = p->n;
    const uint32_t *order = c->grid.order;
    const double *sx = c->grid.spos, *sy = sx + np, *sz = sx + 2 * np;
    const double *pos = p->pos;
    const int64_t *id = p->id, *id0 = c->id0;
    size_t moved_slots = 0;
    double d2max = 0;
    if (p->dim == 3) {
#pragma omp parallel for schedule(dynamic, MF_STREAM_CHUNK) \
    reduction(+ : moved_slots) reduction(max : d2max)
        for (size_t k = 0; k < np; k++) {
            const size_t i = order[k];
            moved_slots += id[i] != id0[k];
            const double dx = pos[3 * i] - sx[k], dy = pos[3 * i + 1] - sy[k];
            const double dz = pos[3 * i + 2] - sz[k];
            const double d2 = dx * dx + dy * dy + dz * dz;
            if (!(d2 <= d2max)) /* NaN: the build that follows reports it */
                d2max = isnan(d2) ? INFINITY : d2;
        }
    } else { /* 2-D: no z (a loop of its own, not a test a particle) */
#pragma omp parallel for schedule(dynamic, MF_STREAM_CHUNK) \
    reduction(+ : moved_slots) reduction(max : d2max)
        for (size_t k = 0; k < np; k++) {
            const size_t i = order[k];
            moved_slots += id[i] != id0[k];
            const double dx = pos[3 * i] - sx[k], dy = pos[3 * i + 1] - sy[k];
            const double d2 = dx * dx + dy * dy;
            if (!(d2 <= d2max))
                d2max = isnan(d2) ? INFINITY : d2;
        }
    }
    return moved_slots ? NAN : sqrt(d2max);
}

static int build(mf_neighbours *nb, nb_class *c, const mf_particles *p)
{
    const double R = c->radius + c->skin;
    c->list_radius = 0;
    MF_CALL(mf_grid_build_reach(&c->grid, p, c->cell, R > c->cell ? 2 : 1));
    /* The radix sort's buffers (24 bytes a particle) are dead once the grid
     * is built: given back before the list build, whose scratch would
     * otherwise stack on them (the step's peak, issue 12). */
    mf_grid_release_scratch(&c->grid);
    const int self = (int)(c - nb->cls);
    c->sub_radius = 0;
    for (int k = 0; k < nb->nhandles; k++) {
        const double r = nb->handle[k].radius;
        if (nb->handle[k].cls == self && r <= SUB_SHARE * c->radius && r > c->sub_radius)
            c->sub_radius = r;
    }
    if (c->built_once && !c->sub_wanted)
        c->sub_radius = 0;
    c->sub_wanted = false;
    c->built_once = true;
    c->sub_list_radius = c->sub_radius > 0 ? c->sub_radius + c->skin : 0;
    if (c->sub_radius > 0)
        MF_CALL(mf_nlist_build_pair(&c->list, &c->sub, &c->grid, p, R, c->sub_list_radius));
    else
        MF_CALL(mf_nlist_build(&c->list, &c->grid, p, R));
    /* The builds' scratch is a fifth of the lists' memory; a run holds the
     * lists while the pressure solve's memory peaks, the scratch need not. */
    mf_nlist_release_scratch(&c->list);
    const size_t np = p->n;
    if (np > c->cap_id) {
        size_t cap = np + np / 8 + 16;
        if (mf_resize(&c->id0, cap, sizeof *c->id0))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particle ids", np);
        c->cap_id = cap;
    }
    for (size_t k = 0; k < np; k++)
        c->id0[k] = p->id[c->grid.order[k]];
    c->store = p;
    c->cells_known = CELLS_OF_BUILD;
    c->list_radius = R;
    c->d_first = -1;
    c->epoch = nb->epoch;
    nb->stats.builds++;
    /* Per owned particle: the copies' rows are empty (nlist.c). */
    nb->stats.entries = p->n_owned ? (double)c->list.start[np] / (double)p->n_owned : 0.0;
    return 0;
}

/* The lists of class c into the order of keys (mf_grid_keys at the current
 * positions). With packed keys and the cells of the lists' order known,
 * only the lists that hold a particle that changed cell since are sorted
 * (mf_nlist_mark_moved; the others are in that order already), else all:
 * the same lists either way. */
static int order_lists(nb_class *c, const uint64_t *keys, bool packed)
{
    const size_t n = c->list.n;
    if (!packed) {
        mf_nlist_sort(&c->list, keys, false);
        if (c->sub_radius > 0)
            mf_nlist_sort(&c->sub, keys, false);
        c->cells_known = CELLS_UNKNOWN;
        return 0;
    }
    if (n > c->cap_cell0) {
        size_t cap = n + n / 8 + 16;
        c->cells_known = c->cells_known == CELLS_KEPT ? CELLS_UNKNOWN : c->cells_known;
        if (mf_resize(&c->cell0, cap, sizeof *c->cell0))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particles' cells", n);
        c->cap_cell0 = cap;
    }
    if (c->cells_known == CELLS_OF_BUILD)
        c->cells_known = mf_grid_cells(&c->grid, c->cell0) ? CELLS_KEPT : CELLS_UNKNOWN;
    uint8_t *dirty = c->cells_known == CELLS_KEPT ? malloc(n ? n : 1) : NULL;
    if (c->cells_known == CELLS_KEPT && !dirty)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu list marks", n);
    if (dirty) {
        mf_nlist_mark_moved(&c->list, keys, c->cell0, c->store ? c->store->n_owned : n, dirty);
        mf_nlist_sort_marked(&c->list, keys, true, dirty);
        if (c->sub_radius > 0)
            mf_nlist_sort_marked(&c->sub, keys, true, dirty);
        free(dirty);
    } else {
        mf_nlist_sort(&c->list, keys, true);
        if (c->sub_radius > 0)
            mf_nlist_sort(&c->sub, keys, true);
    }
    for (size_t i = 0; i < n; i++)
        c->cell0[i] = (uint32_t)(keys[i] >> 32);
    c->cells_known = CELLS_KEPT;
    return 0;
}

/* The lists of class c at the current positions, good for radius r; *dmax:
 * the largest displacement since their build. */
static int refresh(mf_neighbours *nb, nb_class *c, const mf_particles *p, double r,
                   double *dmax)
{
    const double t0 = mf_wall_seconds();
    int rc = 0;
    nb->stats.checks++;
    const double d = displacement(c, p);
    const bool same = !isnan(d);
    const bool kept = same && r + 2 * d <= c->list_radius * (1 - MARGIN) &&
                      c->list_radius >= c->radius;
    if (kept) {
        if (c->epoch != nb->epoch) { /* an order point since: the order of now */
            if (c->d_first < 0)
                c->d_first = d;
            bool packed = false;
            uint64_t *keys = malloc((p->n ? p->n : 1) * sizeof *keys);
            rc = keys ? mf_grid_keys(p, c->cell, keys, &packed)
                      : MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu sort keys", p->n);
            if (rc == 0)
                rc = order_lists(c, keys, packed);
            if (rc == 0) {
                c->epoch = nb->epoch;
                nb->stats.sorts++;
            }
            free(keys);
        }
    } else {
        if (same) { /* moved too far for the skin: fit it to what is needed */
            const double d1 = c->d_first >= 0 ? c->d_first : d;
            /* Shrink slowly: one small step must not undo a larger need. */
            c->need = fmax(SKIN_FACTOR * d1, 0.5 * c->need);
            const double lo = nb->skin_min * c->cell, hi = nb->skin_max * c->cell;
            c->skin = c->need < lo ? lo : c->need > hi ? hi : c->need;
        }
        rc = build(nb, c, p);
    }
    *dmax = kept ? d : 0.0; /* a fresh build: nothing has moved */
    nb->stats.seconds += mf_wall_seconds() - t0;
    return rc == 0 ? 0 : mf_error_trace(rc, __FILE__, __LINE__, __func__);
}

static int handle_class(mf_neighbours *nb, int handle, nb_handle **h, nb_class **c)
{
    if (!nb)
        return MF_ERROR(MF_ERR_INPUT, "the run has no neighbour service (mf_neighbours_create)");
    if (handle < 0 || handle >= nb->nhandles)
        return MF_ERROR(MF_ERR_INPUT, "neighbour handle %d was not requested", handle);
    *h = &nb->handle[handle];
    MF_CALL(resolve(nb, *h));
    *c = &nb->cls[(*h)->cls];
    return 0;
}

int mf_neighbours_pairs(mf_neighbours *nb, const mf_particles *p, int handle, mf_pairs *out)
{
    nb_handle *h = NULL;
    nb_class *c = NULL;
    MF_CALL(handle_class(nb, handle, &h, &c));
    double d = 0;
    MF_CALL(refresh(nb, c, p, h->radius, &d));
    /* The sub-list while it holds the pairs, else the class's: same order. */
    if (h->radius <= SUB_SHARE * c->radius && 2 * d <= c->skin)
        c->sub_wanted = true;
    if (h->radius <= c->sub_radius &&
        h->radius + 2 * d <= c->sub_list_radius * (1 - MARGIN))
        *out = mf_pairs_of_list(p, &c->sub, h->radius);
    else
        *out = mf_pairs_of_list(p, &c->list, h->radius);
    return 0;
}

int mf_neighbours_update(mf_neighbours *nb, const mf_particles *p, int handle)
{
    mf_neighbours_moved(nb);
    mf_pairs v;
    MF_CALL(mf_neighbours_pairs(nb, p, handle, &v));
    return 0;
}

int mf_neighbours_grid(mf_neighbours *nb, const mf_particles *p, double cell,
                       const mf_grid **out)
{
    if (!nb)
        return MF_ERROR(MF_ERR_INPUT, "the run has no neighbour service (mf_neighbours_create)");
    const double t0 = mf_wall_seconds();
    int rc = mf_grid_build(&nb->points, p, cell);
    mf_grid_release_scratch(&nb->points);
    nb->stats.seconds += mf_wall_seconds() - t0;
    MF_CALL(rc);
    *out = &nb->points;
    return 0;
}

int mf_neighbours_locality_order(mf_neighbours *nb, const mf_particles *p, int handle,
                                 size_t *perm)
{
    nb_handle *h = NULL;
    nb_class *c = NULL;
    MF_CALL(handle_class(nb, handle, &h, &c));
    const double t0 = mf_wall_seconds();
    c->list_radius = 0; /* the particles are about to move to other slots */
    int rc = mf_grid_build(&c->grid, p, c->cell);
    if (rc == 0)
        rc = mf_grid_locality_order(&c->grid, perm);
    mf_grid_release_scratch(&c->grid);
    nb->stats.seconds += mf_wall_seconds() - t0;
    MF_CALL(rc);
    return 0;
}

size_t mf_neighbours_memory(const mf_neighbours *nb)
{
    if (!nb)
        return 0;
    size_t bytes = mf_grid_memory(&nb->points);
    for (int c = 0; c < nb->nclasses; c++)
        bytes += mf_grid_memory(&nb->cls[c].grid) + mf_nlist_memory(&nb->cls[c].list) +
                 mf_nlist_memory(&nb->cls[c].sub) + nb->cls[c].cap_id * sizeof(int64_t);
    return bytes;
}

void mf_neighbours_get_stats(const mf_neighbours *nb, mf_neighbours_stats *out)
{
    memset(out, 0, sizeof *out);
    if (nb)
        *out = nb->stats;
}
