/* st_smooth.c: curvature smoothing over the free-surface particles. */
#include <math.h>

#include "surface_tension.h"

/* One smoothing pass over the free-surface particles (see st_smooth_curvature). */
typedef struct smooth_acc {
    int x;
    double sw, sk;
} smooth_acc;

static inline bool smooth_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    smooth_acc *a = acc;
    const size_t j = pr->j;
    const st_data *d = c->d;
    if (isnan(c->kin[j]) || d->fdir[3 * j] == 0 || c->p->kind[j] != MF_FLUID ||
        fluid_of(c->fid, j) != a->x)
        return true;
    const double len = pr->len, rst = d->r;
    if (len >= rst)
        return true;
    double w = 1 - len / rst;
    a->sw += w;
    a->sk += w * c->kin[j];
    return true;
}

static void smooth_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    c->kout[i] = c->kin[i];
    if (isnan(c->kin[i]) || c->d->fdir[3 * i] == 0) /* free-surface particles only */
        return;
    smooth_acc a = {fluid_of(c->fid, i), 1, c->kin[i]};
    mf_pairs_row(c->v, i, NULL, smooth_pair, c, &a);
    c->kout[i] = a.sk / a.sw;
}

/* Smoothing (free surfaces), d->s.smoothing passes: the mean of kappa over the free-surface
 * particles of the same fluid within r_st, weight 1 - r/r_st. A free
 * surface is picked by a count and its normal is one-sided: in motion its
 * curvature is noisy, and the noise, multiplied by delta n, does not
 * average out (a 2-D drop: the force jump 1.26 sigma/R unsmoothed, 1.02
 * smoothed). An interface between fluids is not smoothed: there the
 * average over its band of 2 r_st would pull kappa down (0.87 of 1/R on
 * a lattice drop). */
/* Returns the curvature after the passes (d->kappa or d->kappa_s). */
const double *st_smooth_curvature(st_ctx *c)
{
    st_data *d = c->d;
    double *kin = d->kappa, *kout = d->kappa_s;
    for (long pass = 0; pass < d->s.smoothing; pass++) {
        c->kin = kin;
        c->kout = kout;
        mf_pairs_each(c->v, NULL, smooth_row, c);
        double *t = kin;
        kin = kout;
        kout = t;
    }
    return kin;
}
