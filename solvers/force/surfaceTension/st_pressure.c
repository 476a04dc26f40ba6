/* st_pressure.c: freeSurface pressure, the Laplace pressure sigma kappa on
 * the solver's free-surface particles (forces.h, mf_forces_surface_pressure). */
#include <math.h>

#include "surface_tension.h"

typedef struct mean_kappa_acc {
    int x;
    double sw, sk;
} mean_kappa_acc;

static inline bool surface_kappa_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    mean_kappa_acc *a = acc;
    const size_t j = pr->j;
    const st_data *d = c->d;
    if (c->p->kind[j] != MF_FLUID || d->fdir[3 * j] == 0 || isnan(c->kap[j]) ||
        fluid_of(c->fid, j) != a->x)
        return true;
    const double len = pr->len, rst = d->r;
    if (len >= rst)
        return true;
    a->sw += 1 - len / rst;
    a->sk += (1 - len / rst) * c->kap[j];
    return true;
}

static void surface_pressure_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    st_data *d = c->d;
    d->p_surface[i] = NAN;
    if (c->p->kind[i] != MF_FLUID)
        return;
    const int x = fluid_of(c->fid, i);
    const double sig = d->sigma[x][x];
    if (!(sig > 0))
        return;
    if (d->fdir[3 * i] != 0 && !isnan(c->kap[i])) {
        d->p_surface[i] = sig * c->kap[i];
        return;
    }
    mean_kappa_acc a = {x, 0, 0};
    mf_pairs_row(c->v, i, NULL, surface_kappa_pair, c, &a);
    if (a.sw > 0)
        d->p_surface[i] = sig * a.sk / a.sw;
}

/* freeSurface pressure: the Laplace pressure sigma_x kappa of every fluid
 * particle near a free surface of a fluid with sigma_x > 0, for the solver
 * to hold on its free-surface (Dirichlet) particles of eq. 18 at r*. A
 * free-surface interface particle takes its own (smoothed) curvature; any
 * other particle the mean of those within r_st (weight 1 - r/r_st): the
 * solver's free surface (n* < beta n0 at r*) is not exactly the one found
 * here (a count within r_st at r^n). NAN where there is none. */
void st_surface_pressure_field(const st_ctx *c)
{
    mf_pairs_each(c->v, NULL, surface_pressure_row, c);
    c->d->p_surface_n = c->p->n_owned;
}

bool st_claim_surface_pressure(void *data)
{
    st_data *d = data;
    if (!(d->pressure_mode && d->any))
        return false;
    d->claimed = true;
    return true;
}

int st_surface_pressure(void *data, const mf_sim *sim, const uint8_t *dirichlet,
                               double *p)
{
    const st_data *d = data;
    const mf_particles *ps = sim->p;
    if (!d->pressure_mode)
        return 0;
    for (size_t i = 0; i < d->p_surface_n && i < ps->n_owned; i++)
        if (dirichlet[i] && ps->kind[i] == MF_FLUID && !isnan(d->p_surface[i]))
            p[i] += d->p_surface[i];
    return 0;
}
