/* halo.c: the copies of mf_halo.h.
 *
 * The plan of one build is kept until the next: which owned particle goes
 * to which rank with which periodic shift. Local images (periodic copies
 * on this rank) come first after n_owned, then the copies received, in the
 * order Zoltan_Comm delivers them (by sending rank); an update sends the
 * same particles again in the same order, so each copy gets its owner's
 * value without any lookup.
 *
 * Which rank needs a particle: rank q reads particles within the radius of
 * its owned ones, all of which lie in the bounding box of its owned
 * particles; so a particle (or an image of it) inside that box grown by the
 * radius is sent to q. The boxes are exchanged at each build (6 numbers a
 * rank), and only the ranks whose grown box meets this rank's box (or its
 * periodic shift) are tested particle by particle.
 */
#include "mf_halo.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <zoltan.h>
#include <zoltan_comm.h>

#include "mf_error.h"
#include "parallel_internal.h"

typedef struct candidate {
    int rank;
    int shift; /* -1, 0, +1 periods along the axis */
} candidate;

struct mf_halo {
    mf_halo_spec spec;
    bool active;
    /* Local images: [n_owned, n_owned + nlocal). */
    size_t nlocal, cap_local;
    size_t *local_src;
    signed char *local_shift;
    /* Sent copies, and the plan that delivers them. */
    size_t nsend, cap_send;
    size_t *send_src;
    signed char *send_shift;
    int *send_rank;
    size_t nrecv;
    ZOLTAN_COMM_OBJ *plan;
    /* Buffers, grown as needed. */
    char *sbuf, *rbuf;
    size_t cap_sbuf, cap_rbuf;
    candidate *cand;
    size_t cap_cand;
    size_t elem_cap; /* the buffers hold this many bytes a copy (the same on every rank) */
    double *boxes;   /* 6 a rank: the owned particles' bounding boxes */
};

/* Updates of values up to this size (9 doubles: any particle field) find
 * their buffers ready, so they need no agreement between the ranks. */
#define UPDATE_BYTES (9 * sizeof(double))

int mf_halo_create(mf_halo **out)
{
    *out = calloc(1, sizeof **out);
    if (!*out)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for a halo");
    return 0;
}

void mf_halo_destroy(mf_halo *h)
{
    if (!h)
        return;
    if (h->plan)
        Zoltan_Comm_Destroy(&h->plan);
    free(h->local_src);
    free(h->local_shift);
    free(h->send_src);
    free(h->send_shift);
    free(h->send_rank);
    free(h->sbuf);
    free(h->rbuf);
    free(h->cand);
    free(h->boxes);
    free(h);
}

void mf_halo_drop(mf_halo *h, mf_particles *p)
{
    p->n = p->n_owned;
    if (h)
        h->active = false;
}

bool mf_halo_active(const mf_halo *h)
{
    return h && h->active;
}

size_t mf_halo_local_owner(const mf_halo *h, const mf_particles *p, size_t j)
{
    if (j < p->n_owned)
        return j;
    if (!h || j - p->n_owned >= h->nlocal)
        return SIZE_MAX;
    return h->local_src[j - p->n_owned];
}

/* ---- growing arrays ---------------------------------------------------------- */

static int grow(void **ptr, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t n = need + need / 2 + 64;
    void *g = realloc(*ptr, n * elem);
    if (!g)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for a halo of %zu particles", need);
    *ptr = g;
    *cap = n;
    return 0;
}

static int push_local(mf_halo *h, size_t i, int shift)
{
    size_t cap = h->cap_local;
    MF_CALL(grow((void **)&h->local_src, &cap, h->nlocal + 1, sizeof *h->local_src));
    cap = h->cap_local;
    MF_CALL(grow((void **)&h->local_shift, &cap, h->nlocal + 1, sizeof *h->local_shift));
    h->cap_local = cap;
    h->local_src[h->nlocal] = i;
    h->local_shift[h->nlocal++] = (signed char)shift;
    return 0;
}

static int push_send(mf_halo *h, size_t i, int shift, int rank)
{
    size_t cap = h->cap_send;
    MF_CALL(grow((void **)&h->send_src, &cap, h->nsend + 1, sizeof *h->send_src));
    cap = h->cap_send;
    MF_CALL(grow((void **)&h->send_shift, &cap, h->nsend + 1, sizeof *h->send_shift));
    cap = h->cap_send;
    MF_CALL(grow((void **)&h->send_rank, &cap, h->nsend + 1, sizeof *h->send_rank));
    h->cap_send = cap;
    h->send_src[h->nsend] = i;
    h->send_shift[h->nsend] = (signed char)shift;
    h->send_rank[h->nsend++] = rank;
    return 0;
}

/* ---- the periodic axis --------------------------------------------------------- */

static bool periodic(const mf_halo_spec *s)
{
    return s->periodic_length > 0;
}

/* Shifts of the images particle x needs: +1 within the radius of the lower
 * face, -1 within the radius of the upper face (never both: the length
 * exceeds twice the radius). */
static int image_shift(const mf_halo_spec *s, const double *x)
{
    if (!periodic(s))
        return 0;
    const double v = x[s->periodic_axis];
    if (v < s->periodic_origin + s->radius)
        return 1;
    if (v >= s->periodic_origin + s->periodic_length - s->radius)
        return -1;
    return 0;
}

static void shifted(const mf_halo_spec *s, const double *x, int shift, double y[3])
{
    y[0] = x[0];
    y[1] = x[1];
    y[2] = x[2];
    if (shift)
        y[s->periodic_axis] += shift * s->periodic_length;
}

void mf_halo_wrap(const mf_halo_spec *s, mf_particles *p)
{
    if (!periodic(s))
        return;
    const double x0 = s->periodic_origin, x1 = x0 + s->periodic_length;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        double *x = &p->pos[3 * i + s->periodic_axis];
        while (*x < x0)
            *x += s->periodic_length;
        while (*x >= x1)
            *x -= s->periodic_length;
    }
}

/* ---- building ---------------------------------------------------------------- */

static void owned_box(const mf_particles *p, double box[6])
{
    for (int c = 0; c < 3; c++) {
        box[c] = INFINITY;
        box[3 + c] = -INFINITY;
    }
    /* Comparisons, not fmin/fmax: the same box (a NaN is passed over either
     * way; a -0 against a +0 decides no box test), without a libm call per
     * coordinate (two a particle and axis, at every halo build). */
    for (size_t i = 0; i < p->n_owned; i++)
        for (int c = 0; c < 3; c++) {
            const double v = p->pos[3 * i + c];
            box[c] = v < box[c] ? v : box[c];
            box[3 + c] = v > box[3 + c] ? v : box[3 + c];
        }
}

/* x within r of box b (a box test: the ball of radius r is inside the grown box). */
static bool near_box(const double *b, const double *x, double r, int dim)
{
    for (int c = 0; c < dim; c++)
        if (x[c] < b[c] - r || x[c] > b[3 + c] + r)
            return false;
    return true;
}

/* Box a, shifted, meets box b grown by r. */
static bool boxes_meet(const mf_halo_spec *s, const double *a, int shift, const double *b,
                       double r, int dim)
{
    for (int c = 0; c < dim; c++) {
        double lo = a[c], hi = a[3 + c];
        if (shift && c == s->periodic_axis) {
            lo += shift * s->periodic_length;
            hi += shift * s->periodic_length;
        }
        if (hi < b[c] - r || lo > b[3 + c] + r)
            return false;
    }
    return true;
}

/* Who gets which copy. */
static int plan_copies(mf_halo *h, const mf_parallel *par, const mf_particles *p,
                       const double *boxes)
{
    const mf_halo_spec *s = &h->spec;
    const int me = par ? par->rank : 0, nranks = par ? par->size : 1, dim = p->dim;
    const double r = s->radius;
    const double *mine = boxes + 6 * me;
    /* Ranks (and shifts) that may need something of ours. */
    size_t ncand = 0;
    for (int shift = -1; shift <= 1; shift++) {
        if (shift && !periodic(s))
            continue;
        for (int q = 0; q < nranks; q++) {
            if (q == me && shift == 0)
                continue;
            if (!boxes_meet(s, mine, shift, boxes + 6 * q, r, dim))
                continue;
            MF_CALL(grow((void **)&h->cand, &h->cap_cand, ncand + 1, sizeof *h->cand));
            h->cand[ncand++] = (candidate){q, shift};
        }
    }
    for (size_t i = 0; i < p->n_owned; i++) {
        const double *x = &p->pos[3 * i];
        const int img = image_shift(s, x);
        for (size_t k = 0; k < ncand; k++) {
            const candidate *c = &h->cand[k];
            if (c->shift != 0 && c->shift != img)
                continue;
            double y[3];
            shifted(s, x, c->shift, y);
            if (c->rank == me) {
                /* An image on this rank: always (the loops of a serial
                 * periodic run read every particle within the radius of a
                 * face across it). */
                MF_CALL(push_local(h, i, c->shift));
            } else if (near_box(boxes + 6 * c->rank, y, r, dim)) {
                MF_CALL(push_send(h, i, c->shift, c->rank));
            }
        }
    }
    return 0;
}

/* Bytes of one copy: position, velocity, kind, id and the named fields. */
static size_t copy_bytes(const mf_halo *h, const mf_particles *p)
{
    size_t b = (h->spec.velocities ? 6 : 3) * sizeof(double) + sizeof(uint8_t) + sizeof(int64_t);
    for (int k = 0; k < h->spec.nfields; k++)
        b += mf_particles_field_bytes(&p->field[h->spec.field[k]]);
    return b;
}

static void pack_copy(const mf_halo *h, const mf_particles *p, size_t i, int shift, char *out)
{
    double y[3];
    shifted(&h->spec, &p->pos[3 * i], shift, y);
    memcpy(out, y, sizeof y);
    out += sizeof y;
    if (h->spec.velocities) {
        memcpy(out, &p->vel[3 * i], 3 * sizeof(double));
        out += 3 * sizeof(double);
    }
    memcpy(out, &p->kind[i], 1);
    out += 1;
    memcpy(out, &p->id[i], sizeof(int64_t));
    out += sizeof(int64_t);
    for (int k = 0; k < h->spec.nfields; k++) {
        const mf_field *f = &p->field[h->spec.field[k]];
        const size_t es = mf_particles_field_bytes(f);
        memcpy(out, (const char *)f->data + i * es, es);
        out += es;
    }
}

static void unpack_copy(const mf_halo *h, mf_particles *p, size_t j, const char *in)
{
    memcpy(&p->pos[3 * j], in, 3 * sizeof(double));
    in += 3 * sizeof(double);
    if (h->spec.velocities) {
        memcpy(&p->vel[3 * j], in, 3 * sizeof(double));
        in += 3 * sizeof(double);
    } else {
        memset(&p->vel[3 * j], 0, 3 * sizeof(double));
    }
    memcpy(&p->kind[j], in, 1);
    in += 1;
    memcpy(&p->id[j], in, sizeof(int64_t));
    in += sizeof(int64_t);
    for (int k = 0; k < h->spec.nfields; k++) {
        const mf_field *f = &p->field[h->spec.field[k]];
        const size_t es = mf_particles_field_bytes(f);
        memcpy((char *)f->data + j * es, in, es);
        in += es;
    }
}

static int check_spec(const mf_halo_spec *s, const mf_particles *p)
{
    if (!(s->radius > 0))
        return MF_ERROR(MF_ERR_INTERNAL, "halo radius %g", s->radius);
    if (periodic(s) && (s->periodic_axis < 0 || s->periodic_axis >= p->dim ||
                        !(s->periodic_length > 2 * s->radius)))
        return MF_ERROR(MF_ERR_INPUT,
                        "periodic axis %d of length %g: the length must exceed twice the "
                        "largest radius %g",
                        s->periodic_axis, s->periodic_length, s->radius);
    if (s->nfields < 0 || s->nfields > p->nfields)
        return MF_ERROR(MF_ERR_INTERNAL, "halo of %d fields (the particles have %d)",
                        s->nfields, p->nfields);
    for (int k = 0; k < s->nfields; k++)
        if (s->field[k] < 0 || s->field[k] >= p->nfields)
            return MF_ERROR(MF_ERR_INTERNAL, "halo field %d does not exist", s->field[k]);
    return 0;
}

int mf_halo_build(mf_halo *h, mf_parallel *par, mf_particles *p, const mf_halo_spec *spec)
{
    p->n = p->n_owned;
    h->active = false;
    h->nlocal = h->nsend = h->nrecv = 0;
    if (!par && !periodic(spec))
        return 0; /* serial, no period: nothing to copy */
    const double t0 = par ? MPI_Wtime() : 0;
    h->spec = *spec;
    int rc = check_spec(spec, p);
    const int nranks = par ? par->size : 1;
    MF_CALL(rc); /* the same spec on every rank: the same answer */
    /* One agreement, after the plan: a rank that failed before it still
     * takes part (sending nothing) and reports then. */
    if (!h->boxes && !(h->boxes = malloc(6 * (size_t)nranks * sizeof *h->boxes))) {
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for %d subdomain boxes", nranks);
        mf_parallel_abort(par, rc); /* 48 bytes a rank: cannot even take part */
        return rc;
    }
    double *boxes = h->boxes, mine[6];
    owned_box(p, mine);
    const double t_wait = par ? MPI_Wtime() : 0;
    mf_parallel_allgather(par, mine, sizeof mine, boxes);
    if (par)
        par->stats.t_halo_wait += MPI_Wtime() - t_wait;
    if (rc == 0)
        rc = plan_copies(h, par, p, boxes);
    if (rc != 0)
        h->nsend = h->nlocal = 0;

    const size_t row = copy_bytes(h, p);
    int nrecv = 0;
    if (h->plan)
        Zoltan_Comm_Destroy(&h->plan);
    if (par) {
        if (Zoltan_Comm_Create(&h->plan, (int)h->nsend, h->send_rank, par->comm, MF_TAG_HALO,
                               &nrecv) != ZOLTAN_OK &&
            rc == 0)
            rc = MF_ERROR(MF_ERR_LIBRARY, "Zoltan_Comm_Create failed (halo of %zu copies)",
                          h->nsend);
    }
    h->elem_cap = row > UPDATE_BYTES ? row : UPDATE_BYTES;
    if (rc == 0)
        rc = grow((void **)&h->sbuf, &h->cap_sbuf, h->nsend * h->elem_cap + 1, 1);
    if (rc == 0)
        rc = grow((void **)&h->rbuf, &h->cap_rbuf, ((size_t)nrecv + 1) * h->elem_cap, 1);
    if (rc == 0)
        rc = mf_particles_reserve(p, p->n_owned + h->nlocal + (size_t)nrecv);
    MF_CALL_GOTO(rc, mf_parallel_agree(par, rc), done);
    h->nrecv = (size_t)nrecv;
    for (size_t k = 0; k < h->nsend; k++)
        pack_copy(h, p, h->send_src[k], h->send_shift[k], h->sbuf + k * row);
    /* (A failed exchange fails on the ranks that took part: no agreement.) */
    if (par && Zoltan_Comm_Do(h->plan, MF_TAG_HALO + 1, h->sbuf, (int)row, h->rbuf) != ZOLTAN_OK)
        rc = MF_ERROR(MF_ERR_LIBRARY, "Zoltan_Comm_Do failed (halo)");
    MF_CALL_GOTO(rc, rc, done);
    /* Local images straight from their owners, then the received copies. */
    for (size_t k = 0; k < h->nlocal; k++) {
        pack_copy(h, p, h->local_src[k], h->local_shift[k], h->rbuf + h->nrecv * row);
        unpack_copy(h, p, p->n_owned + k, h->rbuf + h->nrecv * row);
    }
    for (size_t k = 0; k < h->nrecv; k++)
        unpack_copy(h, p, p->n_owned + h->nlocal + k, h->rbuf + k * row);
    p->n = p->n_owned + h->nlocal + h->nrecv;
    h->active = h->nlocal + h->nrecv > 0 || par != NULL;
    if (par) {
        par->stats.halo_builds++;
        par->stats.halo_particles += h->nrecv;
        par->stats.owned_at_builds += p->n_owned;
        par->stats.halo_sent_bytes += h->nsend * row;
        par->stats.t_halo += MPI_Wtime() - t0;
    }
done:
    return rc;
}

/* ---- updates ----------------------------------------------------------------- */

/* values[n_owned + ...] of the copies from the owners' values; `get` packs
 * one owner's value (with its shift) and `put` stores one copy's. */
typedef void (*pack_fn)(const void *ctx, size_t i, int shift, char *out);
typedef void (*unpack_fn)(void *ctx, size_t j, const char *in);

static int update(mf_halo *h, mf_parallel *par, const mf_particles *p, size_t size,
                  pack_fn get, unpack_fn put, void *ctx)
{
    if (!h || !h->active)
        return 0;
    const double t0 = par ? MPI_Wtime() : 0;
    if (size > (size_t)INT32_MAX)
        return MF_ERROR(MF_ERR_INTERNAL, "halo update of %zu-byte values", size);
    int rc = 0;
    if (size > h->elem_cap) { /* every rank: elem_cap and size are the same on all */
        rc = grow((void **)&h->sbuf, &h->cap_sbuf, h->nsend * size + 1, 1);
        if (rc == 0)
            rc = grow((void **)&h->rbuf, &h->cap_rbuf, (h->nrecv + 1) * size + 1, 1);
        MF_CALL(mf_parallel_agree(par, rc));
        h->elem_cap = size;
    }
    for (size_t k = 0; k < h->nsend; k++)
        get(ctx, h->send_src[k], h->send_shift[k], h->sbuf + k * size);
    if (par && Zoltan_Comm_Do(h->plan, MF_TAG_HALO_UPDATE, h->sbuf, (int)size, h->rbuf) !=
                   ZOLTAN_OK)
        rc = MF_ERROR(MF_ERR_LIBRARY, "Zoltan_Comm_Do failed (halo update)");
    MF_CALL(rc);
    char *tmp = h->rbuf + h->nrecv * size;
    for (size_t k = 0; k < h->nlocal; k++) {
        get(ctx, h->local_src[k], h->local_shift[k], tmp);
        put(ctx, p->n_owned + k, tmp);
    }
    for (size_t k = 0; k < h->nrecv; k++)
        put(ctx, p->n_owned + h->nlocal + k, h->rbuf + k * size);
    if (par) {
        par->stats.halo_updates++;
        par->stats.halo_sent_bytes += h->nsend * size;
        par->stats.t_halo += MPI_Wtime() - t0;
    }
    return 0;
}

typedef struct array_ctx {
    char *values;
    size_t size;
} array_ctx;

static void array_get(const void *ctx, size_t i, int shift, char *out)
{
    const array_ctx *a = ctx;
    (void)shift;
    memcpy(out, a->values + i * a->size, a->size);
}

static void array_put(void *ctx, size_t j, const char *in)
{
    array_ctx *a = ctx;
    memcpy(a->values + j * a->size, in, a->size);
}

int mf_halo_update(mf_halo *h, mf_parallel *par, const mf_particles *p, void *values,
                   size_t size)
{
    array_ctx a = {values, size};
    MF_CALL(update(h, par, p, size, array_get, array_put, &a));
    return 0;
}

int mf_halo_update_field(mf_halo *h, mf_parallel *par, mf_particles *p, int field)
{
    if (field < 0 || field >= p->nfields)
        return MF_ERROR(MF_ERR_INTERNAL, "halo update of field %d (of %d)", field, p->nfields);
    MF_CALL(mf_halo_update(h, par, p, p->field[field].data,
                           mf_particles_field_bytes(&p->field[field])));
    return 0;
}

typedef struct motion_ctx {
    const mf_halo *h;
    mf_particles *p;
} motion_ctx;

static void motion_get(const void *ctx, size_t i, int shift, char *out)
{
    const motion_ctx *m = ctx;
    double y[3];
    shifted(&m->h->spec, &m->p->pos[3 * i], shift, y);
    memcpy(out, y, sizeof y);
    memcpy(out + sizeof y, &m->p->vel[3 * i], 3 * sizeof(double));
}

static void motion_put(void *ctx, size_t j, const char *in)
{
    motion_ctx *m = ctx;
    memcpy(&m->p->pos[3 * j], in, 3 * sizeof(double));
    memcpy(&m->p->vel[3 * j], in + 3 * sizeof(double), 3 * sizeof(double));
}

int mf_halo_update_motion(mf_halo *h, mf_parallel *par, mf_particles *p)
{
    motion_ctx m = {h, p};
    MF_CALL(update(h, par, p, 6 * sizeof(double), motion_get, motion_put, &m));
    return 0;
}
