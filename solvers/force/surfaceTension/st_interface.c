/* st_interface.c: the counts of eqs. 34-37 and the interface particles with
 * their normal and count curvature (eqs. 36-39). */
#include <math.h>

#include "surface_tension.h"

/* eqs. 34-35: n^st1 (own fluid, walls included) and the count of every
 * particle within r_st. */
typedef struct count_acc {
    int x;
    int32_t own_count, all;
} count_acc;

static inline bool count_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    count_acc *a = acc;
    if (pr->len >= c->d->r)
        return true;
    a->all++;
    a->own_count += own(c->p, c->fid, pr->j, a->x);
    return true;
}

static void count_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    count_acc a = {0, 0, 0};
    if (c->p->kind[i] == MF_FLUID) {
        a.x = fluid_of(c->fid, i);
        mf_pairs_row(c->v, i, NULL, count_pair, c, &a);
    }
    c->d->n1[i] = a.own_count;
    c->d->nall[i] = a.all;
}

void st_count_neighbours(const st_ctx *c)
{
    mf_pairs_each(c->v, NULL, count_row, c);
}

/* A neighbour within r_st that misses neighbours (ends the row). */
static inline bool deep_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    bool *deep = acc;
    *deep = !(c->p->kind[pr->j] == MF_FLUID && c->d->nall[pr->j] < c->thr && pr->len < c->d->r);
    return *deep;
}

/* The full count of the current packing: the mean count of the fluid
 * particles deeper than r_st inside (no particle within r_st that misses
 * neighbours); the lattice's N_full until there are such particles.
 * Disorder changes the count by a particle or two out of 30, which the
 * curvature of eqs. 38-39 would read as 0.05 / l0; a count-based choice of
 * the particles (count above a threshold) would be biased the same way. */
double st_measured_full_count(st_ctx *c)
{
    const st_data *d = c->d;
    const mf_particles *p = c->p;
    c->thr = d->s.beta * d->n_full;
    double sum = 0;
    size_t count = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID || d->nall[i] < c->thr)
            continue;
        bool deep = true;
        mf_pairs_row(c->v, i, NULL, deep_pair, c, &deep);
        if (deep) {
            sum += d->nall[i];
            count++;
        }
    }
    return count ? sum / (double)count : d->n_full;
}

/* Interface particles and their curvature (eqs. 36-39); kappa = NAN off the
 * interface. fdir[3i] = 1 marks a free surface. */
typedef struct iface_acc {
    int x;
    double n2, g[3];
    bool other;
} iface_acc;

static inline bool iface_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    iface_acc *a = acc;
    const st_data *d = c->d;
    const size_t i = pr->i, j = pr->j;
    const double len = pr->len, rst = d->r;
    if (len >= rst || len <= 0)
        return true;
    /* colour gradient of the own fluid: toward own, away from others */
    const bool mine = own(c->p, c->fid, j, a->x);
    double s = (mine ? 1.0 : -1.0) * colour_weight(len, rst) / len;
    for (int q = 0; q < 3; q++)
        a->g[q] += s * pr->r[q];
    if (mine) {
        if (c->p->kind[j] != MF_FLUID || d->n1[j] > d->n1[i])
            a->n2 += 1; /* eq. 37: deeper inside than i */
        else if (d->n1[j] == d->n1[i])
            a->n2 += 0.5;
    } else if (d->sigma[a->x][fluid_of(c->fid, j)] > 0) {
        a->other = true;
    }
    return true;
}

static void iface_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    st_data *d = c->d;
    d->kappa[i] = NAN;
    d->nrm[3 * i] = d->nrm[3 * i + 1] = d->nrm[3 * i + 2] = 0;
    if (c->p->kind[i] != MF_FLUID)
        return;
    iface_acc a = {fluid_of(c->fid, i), 0, {0, 0, 0}, false};
    mf_pairs_row(c->v, i, NULL, iface_pair, c, &a);
    const int x = a.x;
    const double *g = a.g;
    bool free_surface = d->nall[i] < d->s.beta * c->n_full && d->sigma[x][x] > 0;
    d->fdir[3 * i] = free_surface;
    double gm = d->g_coef * sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    bool interface = a.other || free_surface;
    for (int q = 0; q < 3; q++) /* outward: against the colour gradient */
        d->nrm[3 * i + q] = interface && gm >= 0.1 * d->g_ref ? -d->g_coef * g[q] / gm : 0.0;
    if (!interface)
        return;
    /* eq. 39: n^st2 against its flat-interface value n0^st, half the full
     * count. Where the probe is full (an interface between fluids), the
     * particle's own count of every particle is that full count. */
    double full = free_surface ? c->n_full : (double)d->nall[i];
    d->kappa[i] = d->normal ? 0.0 : st_curvature(d, a.n2 / full);
}


void st_find_interface(const st_ctx *c)
{
    mf_pairs_each(c->v, NULL, iface_row, c);
}
