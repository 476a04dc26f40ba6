/* multifluid_step.c: one multi-fluid step (section 3.4), phase by phase,
 * through the MPS phases with a density and viscosity per particle. */
#include <math.h>

#include "mf_error.h"
#include "multifluid.h"

/* A wall's density: the w-weighted mean density of its fluid neighbours. */
typedef struct wall_rho_ctx {
    const mf_sim *sim;
    const int32_t *fid;
    double re;
} wall_rho_ctx;

typedef struct wall_rho_acc {
    double sw, swr;
} wall_rho_acc;

static inline bool wall_rho_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const wall_rho_ctx *c = ctx;
    wall_rho_acc *a = acc;
    if (c->sim->p->kind[pr->j] != MF_FLUID)
        return true;
    const double w = mf_weight(pr->len, c->re);
    a->sw += w;
    a->swr += w * c->sim->fluid[c->fid[pr->j]].rho;
    return true;
}

/* Density and viscosity per particle from FluidId. A wall takes the
 * w-weighted mean density of its fluid neighbours (the heaviest fluid's
 * when it has none), so that a wall under water is water to the PPE and a
 * wall in air is air; its viscosity is not used (a wall takes that of the
 * fluid particle it touches). rho_light: every heavy particle as the
 * lightest fluid (the first solve of the iterative pressure). */
int multifluid_fill_properties(multifluid_data *d, const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    const int32_t *fid = mf_particles_fi(p, d->f_fluid);
    mf_pairs v;
    MF_CALL(mps_pairs(d->mps, sim, d->mps->h_max, &v));
    const wall_rho_ctx c = {sim, fid, v.radius};
    for (size_t i = 0; i < p->n; i++) {
        if (p->kind[i] == MF_FLUID) {
            const mf_fluid *f = &sim->fluid[fid[i]];
            d->rho[i] = f->rho;
            d->mu[i] = f->rho * f->nu;
            d->rho_light[i] = d->heavy[fid[i]] ? d->rho_min : f->rho;
            continue;
        }
        wall_rho_acc a = {0, 0};
        if (i < v.ni)
            mf_pairs_row(&v, i, NULL, wall_rho_pair, &c, &a);
        d->rho[i] = a.sw > 0 ? a.swr / a.sw : d->rho_max;
        d->mu[i] = 0;
        /* In the light solve every particle is light: the wall's fluid
         * neighbours are, so is the wall. */
        d->rho_light[i] = d->iterative ? fmin(d->rho[i], d->rho_min) : d->rho[i];
    }
    return 0;
}

/* One fluid with the Laplace pressure on its free surface: the phases of
 * mps_lagrangian_step, pressure and correction from multifluid_surface.c. */
static int one_fluid_step(multifluid_data *d, mf_sim *sim, double dt)
{
    mps_data *m = d->mps;
    MF_CALL(mps_reserve(m, sim->p->n));
    MF_CALL(multifluid_reserve(d, sim->p->n));
    MF_CALL(mps_build_neighbours(m, sim, true));
    mps_set_masks(m, sim->p);
    MF_CALL(mps_explicit_phase(m, sim, dt));
    MF_CALL(mps_build_neighbours(m, sim, false));
    MF_CALL(multifluid_surface_pressure_phase(d, sim, dt));
    MF_CALL(multifluid_surface_correction(d, sim, dt));
    MF_CALL(mps_shift(m, sim)); /* the scheme's particle shifting */
    return 0;
}

int multifluid_step(multifluid_data *d, mf_sim *sim, double dt)
{
    mps_data *m = d->mps;
    if (d->f_fluid < 0) { /* one fluid: the MPS step itself */
        if (d->surface_pressure)
            MF_CALL(one_fluid_step(d, sim, dt));
        else
            MF_CALL(mps_lagrangian_step(m, sim, dt));
        return 0;
    }
    mf_particles *p = sim->p;
    MF_CALL(mps_reserve(m, p->n));
    MF_CALL(multifluid_reserve(d, p->n));
    MF_CALL(mps_build_neighbours(m, sim, true)); /* at r^n; may reorder the particles */
    mps_set_masks(m, p);
    MF_CALL(multifluid_fill_properties(d, sim));
    m->rho = d->rho;
    m->mu = d->mu;
    m->p_dirichlet = NULL;
    MF_CALL(mps_explicit_phase(m, sim, dt));      /* eq. 27 */
    MF_CALL(mps_build_neighbours(m, sim, false)); /* at r* */
    if (d->iterative) {
        MF_CALL(multifluid_iterative_pressure(d, sim, dt));
        MF_CALL(mps_shift(m, sim));
        return 0;
    }
    if (d->surface_pressure) { /* p = sigma kappa on the free surface */
        MF_CALL(multifluid_surface_pressure_phase(d, sim, dt));
        MF_CALL(multifluid_surface_correction(d, sim, dt));
        MF_CALL(mps_shift(m, sim));
        return 0;
    }
    MF_CALL(mps_pressure_phase(m, sim, dt));   /* variable-density PPE, one solve */
    MF_CALL(mps_correction_phase(m, sim, dt)); /* with 1/rho_ij */
    return 0;
}
