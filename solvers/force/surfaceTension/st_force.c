/* st_force.c: the force sigma kappa delta n (eq. 33) of each interface
 * particle, and accumulate: the phases of the step in order. */
#include <math.h>
#include <string.h>

#include "surface_tension.h"
#include "mf_error.h"

/* sigma kappa delta n of one particle (see st_accumulate). */
typedef struct force_acc {
    int x;
    bool free_surface;
    double f[3];
} force_acc;

static inline bool force_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    force_acc *a = acc;
    const st_data *d = c->d;
    const size_t i = pr->i, j = pr->j;
    const double len = pr->len, rst = d->r;
    if (len >= rst || len <= 0)
        return true;
    const int x = a->x;
    double s = colour_weight(len, rst) / len; /* phi(r) r_hat */
    double coef = a->free_surface && !d->pressure_mode ? 2 * d->sigma[x][x] * c->kap[i] : 0.0;
    if (!own(c->p, c->fid, j, x)) {
        double kj = isnan(c->kap[j]) ? -c->kap[i] : c->kap[j];
        coef -= d->sigma[x][fluid_of(c->fid, j)] * 0.5 * (c->kap[i] - kj);
    }
    for (int q = 0; q < 3; q++)
        a->f[q] += coef * s * pr->r[q];
    return true;
}

static void force_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    const st_data *d = c->d;
    if (isnan(c->kap[i]))
        return;
    force_acc a = {fluid_of(c->fid, i), d->fdir[3 * i] != 0, {0, 0, 0}};
    mf_pairs_row(c->v, i, NULL, force_pair, c, &a);
    const double rho = c->sim->fluid[a.x].rho;
    for (int q = 0; q < 3; q++) {
        c->accel_out[3 * i + q] = d->g_coef * a.f[q] / rho;
        c->acc[3 * i + q] += c->accel_out[3 * i + q];
    }
    c->kappa_out[i] = c->kap[i];
}

int st_accumulate(void *data, const mf_sim *sim, double *acc)
{
    st_data *d = data;
    const mf_particles *p = sim->p;
    d->p_surface_n = 0;
    d->out_n = 0;
    if (!d->any)
        return 0;
    if (d->pressure_mode && !d->claimed)
        return MF_ERROR(MF_ERR_INPUT, "system/solverDict: forces { surfaceTension { "
                        "freeSurface pressure; } } makes the Laplace pressure the free "
                        "surface's Dirichlet value, which this solver does not apply (use "
                        "solver multiFluid with one pressure solve per step, or freeSurface "
                        "force)");
    mf_pairs v;
    MF_CALL(mf_neighbours_pairs(sim->neighbours, p, d->pairs, &v));
    MF_CALL(st_reserve(d, p->n));
    double *kappa_out = d->kappa_out, *accel_out = d->accel_out;
    memset(kappa_out, 0, p->n * sizeof *kappa_out);
    memset(accel_out, 0, 3 * p->n * sizeof *accel_out);
    d->out_n = p->n;
    int ff = mf_particles_field_index(p, "FluidId");
    st_ctx c = {.d = d, .p = p, .fid = ff >= 0 ? mf_particles_fi(p, ff) : NULL, .v = &v,
                .acc = acc, .accel_out = accel_out, .kappa_out = kappa_out, .sim = sim};
    st_count_neighbours(&c);
    c.n_full = st_measured_full_count(&c);
    st_find_interface(&c);
    if (d->normal) {
        st_smooth_normals(&c);
        st_normal_divergence(&c);
    }
    const double *kappa = st_smooth_curvature(&c);
    /* sigma kappa delta n. An unlike pair (i in x, j in y) adds
     * -sigma_xy kappa_ij C phi r_hat_ij to both i and j, kappa_ij the mean of
     * the curvature seen from x and minus the one seen from y: the two sides
     * of an interface carry the same force, half the jump each (unequal
     * shares pull one side off the other and open a gap). A free surface
     * adds 2 sigma_x kappa_i C sum phi r_hat over the particles present. */
    c.kap = kappa;
    mf_pairs_each(&v, NULL, force_row, &c);
    if (d->pressure_mode)
        st_surface_pressure_field(&c);
    return 0;
}
