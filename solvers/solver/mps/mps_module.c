/* mps_module.c: create and destroy the MPS solver; its ops table. */
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mps.h"

static bool module_has_param(const mf_module_info *info, const char *key)
{
    for (size_t i = 0; i < info->nparams; i++)
        if (strcmp(info->params[i].name, key) == 0)
            return true;
    return false;
}

/* The case's `key { ... }` (vd, may be NULL) with the solver's defaults
 * added where the module declares the key and the case does not give it. */
static int solve_dict(const mf_dict *vd, const mf_module_info *info, const mps_default *defaults,
                      size_t ndefaults, mf_dict **out)
{
    mf_dict *m = mf_dict_new(info->name, NULL);
    if (!m)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    *out = m;
    for (size_t k = 0; vd && k < vd->n; k++) {
        const mf_entry *e = vd->entries[k];
        mf_value **items = calloc(e->n ? e->n : 1, sizeof *items);
        if (!items)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory");
        for (size_t i = 0; i < e->n; i++)
            items[i] = mf_value_copy(e->items[i], m);
        if (!mf_dict_set(m, e->key, e->loc, e->n, items))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    }
    for (size_t k = 0; k < ndefaults; k++)
        if (module_has_param(info, defaults[k].key) && !mf_dict_find(m, defaults[k].key))
            MF_CALL(mf_dict_set_number(m, defaults[k].key, defaults[k].value));
    return 0;
}

int mps_create_solve(const mf_sim *sim, const mf_dict *solver_dict, const char *key,
                     const mps_default *defaults, size_t ndefaults, mf_module *out,
                     double *tolerance)
{
    const mf_dict *vd = solver_dict ? mf_dict_subdict(solver_dict, key) : NULL;
    const char *name = "PCG_BoomerAMG";
    if (vd)
        MF_CALL(mf_dict_get_word_or(vd, "solver", name, &name));
    const mf_module_info *info = NULL;
    MF_CALL(mf_registry_find(sim->reg, MF_KIND_PRESSURE, name, &info));
    mf_dict *merged = NULL;
    static const char *const extra[] = {"solver", NULL};
    int rc = solve_dict(vd, info, defaults, ndefaults, &merged);
    if (rc == 0)
        rc = mf_module_prepare(sim->reg, MF_KIND_PRESSURE, name, merged, extra, NULL, out);
    for (size_t k = 0; rc == 0 && vd && k < vd->n; k++) /* read through the copy */
        vd->entries[k]->used = true;
    if (rc == 0 && tolerance)
        mf_dict_get_number_or(merged, "tolerance", NAN, tolerance);
    mf_dict_free(merged);
    MF_CALL(rc);
    const mf_pressure_ops *ops = (const mf_pressure_ops *)out->info;
    MF_CALL(ops->create(out->settings, &out->data));
    return 0;
}

/* The pressure solve's defaults where the case is silent: with the AMG
 * hierarchy kept across steps (reuseHierarchy), no aggressive coarsening in
 * 2-D (its costlier set-up, made once per hierarchy, is repaid by fewer
 * and cheaper iterations at every step); in 3-D the module's one level
 * (without it the coarse levels are too dense). docs/validation-and-performance.md has
 * the measurements. */
static int create_pressure(mps_data *d, mf_sim *sim, const mf_dict *solver_dict)
{
    const mf_dict *pd = solver_dict ? mf_dict_subdict(solver_dict, "pressure") : NULL;
    bool reuse = true;
    if (pd && mf_dict_find(pd, "reuseHierarchy"))
        MF_CALL(mf_dict_get_bool(pd, "reuseHierarchy", &reuse));
    const mps_default defaults[] = {{"aggressiveLevels", 0}};
    MF_CALL(mps_create_solve(sim, solver_dict, "pressure", defaults,
                             sim->dim == 2 && reuse ? 1 : 0, &d->pressure, NULL));
    d->pressure_ops = (const mf_pressure_ops *)d->pressure.info;
    return 0;
}

/* Every radius in the order of the largest one's cells (the order every
 * sum has had since the first MPS step of this code). */
static int request_neighbours(mps_data *d, mf_sim *sim)
{
    d->nb = sim->neighbours;
    if (!d->nb)
        return MF_ERROR(MF_ERR_INPUT, "solver MPS: the run has no neighbour service");
    double rmax = d->k_nd.re;
    if (d->k_grad.re > rmax) rmax = d->k_grad.re;
    if (d->k_lap.re > rmax) rmax = d->k_lap.re;
    MF_CALL(mf_neighbours_request(d->nb, rmax, rmax, &d->h_max));
    MF_CALL(mf_neighbours_request(d->nb, d->k_nd.re, rmax, &d->h_nd));
    MF_CALL(mf_neighbours_request(d->nb, d->k_grad.re, rmax, &d->h_grad));
    MF_CALL(mf_neighbours_request(d->nb, d->k_lap.re, rmax, &d->h_lap));
    const double dc = d->s.collision_distance * sim->l0;
    d->h_coll = -1;
    if (d->s.collision)
        MF_CALL(mf_neighbours_request(d->nb, dc < rmax ? dc : rmax, rmax, &d->h_coll));
    return 0;
}

int mps_reserve(mps_data *d, size_t n)
{
    if (n <= d->cap)
        return 0;
    size_t cap = n + n / 16 + 64;
    if (mf_resize(&d->acc, 3 * cap, sizeof *d->acc) ||
        mf_resize(&d->grad, 3 * cap, sizeof *d->grad) ||
        mf_resize(&d->is_fluid, cap, 1) || mf_resize(&d->in_ppe, cap, 1) ||
        mf_resize(&d->dirichlet, cap, 1) || mf_resize(&d->not_dummy, cap, 1) ||
        mf_resize(&d->row, cap, sizeof *d->row) ||
        mf_resize(&d->row_global, cap, sizeof *d->row_global))
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particles", n);
    d->cap = cap;
    return 0;
}

/* wallPressureExtrapolated acts in the paper gradient's correction of one
 * fluid with wall particles (mps_correction_phase, mps_wall_pressure.c):
 * refused where it would be ignored (wall wallWeight: mps_wall_create). */
static int refuse_wall_pressure(const mps_settings *s, const mps_scheme *sc, const mf_sim *sim,
                                const mf_dict *solver_dict)
{
    if (!s->wall_pressure_extrapolated)
        return 0;
    const char *why = NULL;
    if (sc->gradient != MPS_GRADIENT_PAPER)
        why = "it continues the walls' pressure for gradient paper (eq. 5) only";
    else if (sim->nfluids > 1)
        why = "it continues the pressure with one fluid's density (not with several fluids)";
    if (!why)
        return 0;
    char where[512];
    return MF_ERROR(MF_ERR_INPUT, "%s: key 'wallPressureExtrapolated': %s; set it to no there",
                    mps_key_where(solver_dict, "wallPressureExtrapolated", where, sizeof where),
                    why);
}

/* gradientWeight: eq. 5's weight (mf_kernel.h, mf_grad_weight) on the
 * gradient's kernel, its n0_g from the same ideal lattice as n0. Refused
 * where the gradient is not eq. 5's sum (leastSquares: LSMPS has its own
 * weight; its fallback would take this one) and with wall wallWeight
 * (mps_wall_create: its tables integrate the paper's w). */
static int gradient_weight(const mps_settings *s, const mps_scheme *sc,
                           const mf_dict *solver_dict, mf_kernel *k)
{
    const int shape =
        s->gradient_weight ? mps_choice(mps_gradient_weight_choices, s->gradient_weight) : -1;
    if (shape <= MF_GRAD_WEIGHT_PAPER)
        return 0;
    if (sc->gradient == MPS_GRADIENT_LEAST_SQUARES) {
        char where[512];
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: key 'gradientWeight': it weights eq. 5's sum (gradient paper or "
                        "corrected), not the least-squares gradient; set it to paper there",
                        mps_key_where(solver_dict, "gradientWeight", where, sizeof where));
    }
    return mf_kernel_set_gradient_weight(k, shape);
}

int mps_create_data(const mps_settings *s, mf_sim *sim, const mf_dict *solver_dict,
                    mps_data **out)
{
    if (s->periodic_length > 0)
        return MF_ERROR(MF_ERR_INPUT, "periodicLength: only solver MPS has a periodic axis");
    if (s->velocity_filter > 0) {
        char where[512];
        return MF_ERROR(MF_ERR_INPUT, "%s: key 'velocityFilter': only solver MPS has it (a "
                        "composing solver's phases do not take it); set it to 0 there",
                        mps_key_where(solver_dict, "velocityFilter", where, sizeof where));
    }
    /* mps_create takes the key away for solver MPS; a composing solver
     * (MAFL's Eulerian points, multiFluid's density per particle) has no
     * wall terms yet. */
    MF_CALL(mps_wall_refuse(s, solver_dict, "only solver MPS takes its walls through wall "
                                             "weight functions yet"));
    mps_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    *out = d;
    d->s = *s;
    MF_CALL(mps_scheme_resolve(s, sim->dim, &d->sc));
    MF_CALL(refuse_wall_pressure(s, &d->sc, sim, solver_dict));
    d->s.collision = d->sc.collision;
    d->density_scale = 1.0;
    d->attempt_step = -1;
    MF_CALL(mf_kernel_init(&d->k_nd, sim->dim, sim->l0, s->re_number_density * sim->l0));
    MF_CALL(mf_kernel_init(&d->k_grad, sim->dim, sim->l0, s->re_gradient * sim->l0));
    MF_CALL(gradient_weight(s, &d->sc, solver_dict, &d->k_grad));
    MF_CALL(mf_kernel_init(&d->k_lap, sim->dim, sim->l0, s->re_laplacian * sim->l0));
    MF_CALL(request_neighbours(d, sim));
    sim->n0 = d->k_nd.n0; /* the NumberDensity field's reference, for the run's watch */
    d->rho_default = sim->fluid[0].rho;
    MF_CALL(mf_particles_request_field(sim->p, "Pressure", 1, MF_FIELD_DOUBLE, true,
                                       &d->f_pressure));
    MF_CALL(mf_particles_request_field(sim->p, "NumberDensity", 1, MF_FIELD_DOUBLE, true,
                                       &d->f_number_density));
    MF_CALL(mf_particles_request_field(sim->p, "Flags", 1, MF_FIELD_INT32, true, &d->f_flags));
    MF_CALL(create_pressure(d, sim, solver_dict));
    if (strcmp(s->viscosity, "implicit") == 0) {
        MF_CALL(mps_viscosity_create(d, sim, solver_dict));
    } else if (solver_dict && mf_dict_find(solver_dict, "viscosity")) {
        char where[512];
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: a viscosity { solver ...; } dictionary, but the viscosity is "
                        "explicit: set viscosity implicit; in the solver's Coeffs, or remove it",
                        mf_loc_str(mf_dict_find(solver_dict, "viscosity")->loc, where,
                                   sizeof where));
    }
    MF_CALL(mps_reserve(d, sim->p->n));
    MF_CALL(mps_halo_create(d, sim)); /* copies from other ranks (none in a serial run) */
    MF_CALL(mps_bodies_halo(d, sim));
    const mf_kernel *ks[3] = {&d->k_nd, &d->k_grad, &d->k_lap};
    const char *names[3] = {"number density", "gradient", "Laplacian"};
    for (int k = 0; k < 3; k++)
        mf_log_printf(sim->log, MF_LOG_NORMAL,
                      "MPS kernel (%s): re = %g l0, n0 = %.6g, lambda = %.6g l0^2\n", names[k],
                      ks[k]->re / sim->l0, ks[k]->n0, ks[k]->lambda / (sim->l0 * sim->l0));
    if (d->k_grad.grad_weight != MF_GRAD_WEIGHT_PAPER)
        mf_log_printf(sim->log, MF_LOG_NORMAL, "MPS gradient weight: %s, n0_g = %.6g\n",
                      s->gradient_weight, d->k_grad.n0_grad);
    mf_log_printf(sim->log, MF_LOG_NORMAL, "Pressure solver: %s\n", d->pressure.info->name);
    mps_scheme_log(d, sim->log);
    return 0;
}

void mps_destroy_data(mps_data *d)
{
    if (!d)
        return;
    if (d->pressure_ops && d->pressure.data)
        d->pressure_ops->destroy(d->pressure.data);
    mf_module_release(&d->pressure);
    mps_viscosity_destroy(d->visc);
    mps_halo_destroy(d->halo);
    mps_wall_destroy(d->wall);
    free(d->acc);
    free(d->grad);
    free(d->is_fluid);
    free(d->in_ppe);
    free(d->dirichlet);
    free(d->not_dummy);
    free(d->row);
    free(d->row_global);
    free(d->slot);
    free(d->rhs);
    free(d->x);
    free(d->A.rowptr);
    free(d->A.col);
    free(d->A.val);
    mps_scheme_free(d);
    free(d);
}

static int mps_create(const void *settings, mf_sim *sim, const mf_dict *solver_dict, void **data)
{
    if (sim->nfluids > 1)
        return MF_ERROR(MF_ERR_INPUT,
                        "solver MPS models one fluid, but constant/fluids defines %d (%s, %s%s): "
                        "use solver multiFluid",
                        sim->nfluids, sim->fluid[0].name, sim->fluid[1].name,
                        sim->nfluids > 2 ? ", ..." : "");
    /* Only this solver has a periodic axis (mps_halo.c): the composing
     * solvers call the phases themselves. */
    mps_settings s = *(const mps_settings *)settings;
    const double period = s.periodic_length;
    const char *wall = s.wall;
    const double velocity_filter = s.velocity_filter;
    s.periodic_length = 0;
    s.velocity_filter = 0;
    s.wall = "particles";
    mps_data *d = NULL;
    int rc = mps_create_data(&s, sim, solver_dict, &d);
    if (rc == 0) /* the XSPH filter after the correction (mps_xsph.c) */
        d->s.velocity_filter = velocity_filter;
    if (rc == 0 && period > 0) { /* the halo of mps_create_data gains the period */
        mps_halo_destroy(d->halo);
        d->halo = NULL;
        d->s.periodic_length = period;
        rc = mps_halo_create(d, sim);
        if (rc == 0)
            rc = mps_bodies_halo(d, sim);
    }
    if (rc == 0) { /* wall wallWeight: the walls' terms (mps_wall.c) */
        d->s.wall = wall;
        rc = mps_wall_create(d, sim, solver_dict);
    }
    if (rc != 0) {
        mps_destroy_data(d);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    *data = d;
    return 0;
}

static int mps_step(void *data, mf_sim *sim, double dt)
{
    MF_CALL(mps_lagrangian_step(data, sim, dt));
    return 0;
}

static void mps_destroy(void *data) { mps_destroy_data(data); }

static void mps_report(void *data, const mf_sim *sim, mf_log *log)
{
    const mps_data *d = data;
    const double attempts = d->attempts > 0 ? (double)d->attempts : 1.0;
    const double total = d->t_neighbours + d->t_explicit + d->t_assembly + d->t_solve +
                         d->t_correction;
    mf_log_printf(log, MF_LOG_QUIET,
                  "MPS time per step (ms): neighbour search %.3f, explicit %.3f, number density "
                  "+ assembly %.3f, pressure solve %.3f (AMG setup %.3f, PCG %.3f), correction "
                  "%.3f; total %.3f\n",
                  1e3 * d->t_neighbours / attempts, 1e3 * d->t_explicit / attempts,
                  1e3 * d->t_assembly / attempts, 1e3 * d->t_solve / attempts,
                  1e3 * d->t_setup / attempts, 1e3 * d->t_pcg / attempts,
                  1e3 * d->t_correction / attempts, 1e3 * total / attempts);
    if (sim->par) { /* every rank's split: where the ranks wait for each other */
        const int size = mf_parallel_size(sim->par);
        double mine[5] = {d->t_neighbours, d->t_explicit, d->t_assembly, d->t_solve,
                          d->t_correction};
        double *all = malloc(5 * (size_t)size * sizeof *all);
        if (all) {
            mf_parallel_allgather(sim->par, mine, sizeof mine, all);
            for (int r = 0; r < size && r < 16; r++)
                mf_log_printf(log, MF_LOG_QUIET,
                              "    rank %d (ms/step): neighbours and halo %.3f, explicit %.3f, "
                              "assembly %.3f, solve %.3f, correction %.3f\n",
                              r, 1e3 * all[5 * r] / attempts, 1e3 * all[5 * r + 1] / attempts,
                              1e3 * all[5 * r + 2] / attempts, 1e3 * all[5 * r + 3] / attempts,
                              1e3 * all[5 * r + 4] / attempts);
            free(all);
        }
    }
    double rows = (double)d->ppe_rows; /* over the ranks */
    mf_parallel_sum(sim->par, &rows, 1);
    mf_log_printf(log, MF_LOG_QUIET,
                  "MPS pressure: %.0f unknowns in the last solve, %.2f iterations per solve on "
                  "average\n",
                  rows,
                  (double)sim->pressure_iterations / (d->solves > 0 ? (double)d->solves : 1.0));
    mf_neighbours_stats nb;
    mf_neighbours_get_stats(d->nb, &nb);
    mf_log_printf(log, MF_LOG_QUIET,
                  "MPS neighbours: %ld list builds and %ld re-sorts in %ld steps, %.1f list "
                  "entries a particle, %.1f MB\n",
                  nb.builds, nb.sorts, d->attempts, nb.entries,
                  mf_neighbours_memory(d->nb) / 1048576.0);
    mps_viscosity_report(d->visc, sim, log);
    mps_wall_report(d->wall, log);
}

const mf_solver_ops mf_solver_MPS = {
    .info = {MF_ABI_VERSION, MF_KIND_SOLVER, "MPS",
             "Moving Particle Semi-implicit method (the paper's Algorithm 1)", mps_params,
             MPS_NPARAMS, sizeof(mps_settings)},
    .create = mps_create,
    .step = mps_step,
    .destroy = mps_destroy,
    .stable_dt = NULL, /* the forces' limits are the time loop's (mf_stable_dt) */
    .report = mps_report,
};
