/* multifluid_module.c: create and destroy the multi-fluid solver; its ops
 * table. The MPS data it composes is made by mps_create_data. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "multifluid.h"

int multifluid_reserve(multifluid_data *d, size_t n)
{
    if (n <= d->cap)
        return 0;
    size_t cap = n + n / 4 + 64;
    double **dbl[] = {&d->rho, &d->rho_light, &d->mu, &d->p_dirichlet, &d->p_prev};
    for (size_t k = 0; k < sizeof dbl / sizeof dbl[0]; k++) {
        if (mf_resize(dbl[k], cap, sizeof **dbl[k]))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particles", n);
    }
    if (mf_resize(&d->grad_prev, 3 * cap, sizeof *d->grad_prev))
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particles", n);
    uint8_t **masks[] = {&d->in_all, &d->light_mask, &d->heavy_mask, &d->heavy_rows};
    for (size_t k = 0; k < sizeof masks / sizeof masks[0]; k++) {
        if (mf_resize(masks[k], cap, 1))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particles", n);
    }
    d->cap = cap;
    return 0;
}

static void destroy_data(multifluid_data *d)
{
    if (!d)
        return;
    mps_destroy_data(d->mps);
    free(d->rho);
    free(d->rho_light);
    free(d->mu);
    free(d->p_dirichlet);
    free(d->p_prev);
    free(d->grad_prev);
    free(d->heavy_rows);
    free(d->in_all);
    free(d->light_mask);
    free(d->heavy_mask);
    free(d);
}

/* Every fluid particle's id names a fluid of constant/fluids. */
static int check_fluid_ids(const multifluid_data *d, const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    const int32_t *fid = mf_particles_fi(p, d->f_fluid);
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->kind[i] == MF_FLUID && (fid[i] < 0 || fid[i] >= sim->nfluids))
            return MF_ERROR(MF_ERR_INPUT,
                            "particle id %lld has FluidId %d, but constant/fluids defines %d "
                            "fluids (0 to %d)",
                            (long long)p->id[i], (int)fid[i], sim->nfluids, sim->nfluids - 1);
    return 0;
}

static int setup_fluids(multifluid_data *d, mf_sim *sim)
{
    d->rho_min = INFINITY;
    d->rho_max = 0;
    for (int k = 0; k < sim->nfluids; k++) {
        d->rho_min = fmin(d->rho_min, sim->fluid[k].rho);
        d->rho_max = fmax(d->rho_max, sim->fluid[k].rho);
    }
    d->ratio = d->rho_max / d->rho_min;
    d->iterative = d->ratio >= d->s.ratio_threshold;
    for (int k = 0; k < sim->nfluids; k++)
        d->heavy[k] = d->iterative && sim->fluid[k].rho >= d->s.ratio_threshold * d->rho_min;
    mps_data *m = d->mps;
    m->rho_average = strcmp(d->s.density_average, "harmonic") == 0 ? MF_AVERAGE_HARMONIC
                                                                   : MF_AVERAGE_ARITHMETIC;
    m->mu_average = strcmp(d->s.viscosity_average, "arithmetic") == 0 ? MF_AVERAGE_ARITHMETIC
                                                                      : MF_AVERAGE_HARMONIC;
    if (d->iterative)
        MF_CALL(mf_particles_request_field(sim->p, "LightPressure", 1, MF_FIELD_DOUBLE, true,
                                           &d->f_light_pressure));
    for (int k = 0; k < sim->nfluids; k++)
        mf_log_printf(sim->log, MF_LOG_NORMAL,
                      "multiFluid: fluid %d %s: rho = %g kg/m^3, nu = %g m^2/s, sigma = %g "
                      "N/m%s\n",
                      k, sim->fluid[k].name, sim->fluid[k].rho, sim->fluid[k].nu,
                      sim->fluid[k].sigma,
                      d->iterative ? (d->heavy[k] ? " (heavy)" : " (light)") : "");
    if (d->iterative)
        mf_log_printf(sim->log, MF_LOG_NORMAL,
                      "multiFluid: density ratio %g >= densityRatioThreshold %g: iterative "
                      "two-step pressure (all particles as the light fluid, then the heavy "
                      "fluid), at most %ld rounds, converged when no particle moves more than "
                      "%g l0\n",
                      d->ratio, d->s.ratio_threshold, d->s.max_outer, d->s.outer_tolerance);
    else
        mf_log_printf(sim->log, MF_LOG_NORMAL,
                      "multiFluid: density ratio %g < densityRatioThreshold %g: one pressure "
                      "solve per step\n",
                      d->ratio, d->s.ratio_threshold);
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "multiFluid: pair averages: density %s (1/rho_ij in the PPE and the "
                  "gradient), viscosity %s\n",
                  d->s.density_average, d->s.viscosity_average);
    return 0;
}

static void log_surface_pressure(const multifluid_data *d, const mf_sim *sim)
{
    if (d->surface_pressure)
        mf_log_printf(sim->log, MF_LOG_NORMAL,
                      "multiFluid: free-surface particles (eq. 18) hold the Laplace pressure "
                      "sigma kappa (surfaceTension freeSurface pressure)\n");
}

static int create_data(const multifluid_settings *s, mf_sim *sim, const mf_dict *solver_dict,
                       multifluid_data *d)
{
    d->s = *s;
    d->f_fluid = mf_particles_field_index(sim->p, "FluidId");
    d->f_light_pressure = -1;
    MF_CALL(mps_create_data(&d->s.mps, sim, solver_dict, &d->mps));
    if (d->f_fluid < 0) {
        d->surface_pressure = mf_forces_claim_surface_pressure(sim);
        log_surface_pressure(d, sim);
        if (sim->nfluids > 1)
            return MF_ERROR(MF_ERR_INTERNAL, "%d fluids but no FluidId field", sim->nfluids);
        mf_log_printf(sim->log, MF_LOG_NORMAL,
                      "multiFluid: one fluid (%s): each step is the MPS step\n",
                      sim->fluid[0].name);
        return 0;
    }
    MF_CALL(check_fluid_ids(d, sim));
    MF_CALL(setup_fluids(d, sim));
    /* The iterative solve holds other pressures on its Dirichlet particles:
     * a module asking for the free-surface pressure stops with its message. */
    d->surface_pressure = !d->iterative && mf_forces_claim_surface_pressure(sim);
    log_surface_pressure(d, sim);
    MF_CALL(multifluid_reserve(d, sim->p->n));
    return 0;
}

static int multifluid_create(const void *settings, mf_sim *sim, const mf_dict *solver_dict,
                             void **data)
{
    multifluid_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    int rc = create_data(settings, sim, solver_dict, d);
    if (rc != 0) {
        destroy_data(d);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    *data = d;
    return 0;
}

static int multifluid_step_op(void *data, mf_sim *sim, double dt)
{
    MF_CALL(multifluid_step(data, sim, dt));
    return 0;
}

static void multifluid_destroy(void *data) { destroy_data(data); }

static void multifluid_report(void *data, const mf_sim *sim, mf_log *log)
{
    const multifluid_data *d = data;
    mf_solver_MPS.report(d->mps, sim, log);
    if (d->iterative && d->iterative_steps > 0)
        mf_log_printf(log, MF_LOG_QUIET,
                      "multiFluid: iterative pressure: %.2f rounds per step on average, at "
                      "most %ld; %ld step(s) not converged within maxOuterIterations %ld\n",
                      (double)d->outer_total / (double)d->iterative_steps, d->outer_max,
                      d->unconverged, d->s.max_outer);
}

const mf_solver_ops mf_solver_multiFluid = {
    .info = {MF_ABI_VERSION, MF_KIND_SOLVER, "multiFluid",
             "MPS for several fluids (section 3.4): density, viscosity and surface tension "
             "per particle; one or an iterative two-step pressure solve",
             multifluid_params, MULTIFLUID_NPARAMS, sizeof(multifluid_settings)},
    .create = multifluid_create,
    .step = multifluid_step_op,
    .destroy = multifluid_destroy,
    .stable_dt = NULL, /* the forces' limits are the time loop's (mf_stable_dt) */
    .report = multifluid_report,
};
