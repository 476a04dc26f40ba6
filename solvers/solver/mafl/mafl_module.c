/* mafl_module.c: create and destroy the MPS-MAFL solver; its ops table. */
#include <stdlib.h>
#include <string.h>

#include "mafl.h"
#include "mf_emitter.h"
#include "mf_error.h"

int mafl_reserve(mafl_data *d, size_t n)
{
    if (n <= d->cap)
        return 0;
    size_t cap = n + n / 4 + 64;
    free(d->pos_l);
    free(d->pos_new);
    free(d->value);
    free(d->convected);
    free(d->remove);
    free(d->n_offset);
    free(d->shift);
    d->shift = malloc(3 * cap * sizeof *d->shift);
    d->n_offset = malloc(cap * sizeof *d->n_offset);
    d->pos_l = malloc(3 * cap * sizeof *d->pos_l);
    d->pos_new = malloc(3 * cap * sizeof *d->pos_new);
    d->value = malloc(MAFL_MAX_CARRIED * cap * sizeof *d->value);
    d->convected = malloc(cap);
    d->remove = malloc(cap);
    if (!d->n_offset || !d->pos_l || !d->pos_new || !d->value || !d->convected || !d->remove ||
        !d->shift) {
        d->cap = 0;
        return MF_ERROR(MF_ERR_MEMORY, "MPS-MAFL: out of memory for %zu points", n);
    }
    d->cap = cap;
    return 0;
}

static int create_convection(mafl_data *d, mf_sim *sim)
{
    const char *name = "QUICK";
    if (d->s.convection)
        MF_CALL(mf_dict_get_word_or(d->s.convection, "scheme", name, &name));
    static const char *const extra[] = {"scheme", NULL};
    int rc = mf_module_prepare(sim->reg, MF_KIND_CONVECTION, name, d->s.convection, extra, NULL,
                               &d->conv);
    if (rc != 0)
        return MF_ERROR(rc, "MAFLCoeffs/convection: %s", mf_error_message());
    d->conv_ops = (const mf_convection_ops *)d->conv.info;
    MF_CALL(d->conv_ops->create(d->conv.settings, &d->conv.data));
    return 0;
}

static void mafl_destroy_data(mafl_data *d)
{
    if (!d)
        return;
    mps_destroy_data(d->mps);
    if (d->conv_ops && d->conv.data)
        d->conv_ops->destroy(d->conv.data);
    mf_module_release(&d->conv);
    mf_halo_destroy(d->halo);
    free(d->pos_l);
    free(d->pos_new);
    free(d->value);
    free(d->convected);
    free(d->remove);
    free(d->n_offset);
    free(d->shift);
    free(d);
}

static int create_data(mafl_data *d, mf_sim *sim, const mf_dict *solver_dict)
{
    static const char *const rule_names[] = {"fixed", "fraction", "relax", "lagrangian"};
    for (int r = 0; r < 4; r++)
        if (strcmp(d->s.reconfiguration, rule_names[r]) == 0)
            d->rule = (mafl_rule)r;
    d->linear_source = strcmp(d->s.density_reference, "divergence") == 0;
    d->incremental = d->linear_source || strcmp(d->s.density_reference, "startOfStep") == 0;
    MF_CALL(mps_create_data(&d->s.mps, sim, solver_dict, &d->mps));
    MF_CALL(create_convection(d, sim));
    mf_particles *p = sim->p;
    MF_CALL(mf_particles_request_field(p, "MaflPositionN", 3, MF_FIELD_DOUBLE, false,
                                       &d->f_pos_n));
    MF_CALL(mf_particles_request_field(p, "MaflVelocityN", 3, MF_FIELD_DOUBLE, false,
                                       &d->f_vel_n));
    MF_CALL(mf_particles_request_field(p, "MaflKind", 1, MF_FIELD_INT32, false, &d->f_kind));
    MF_CALL(mf_particles_request_field(p, "ConvectionVelocity", 3, MF_FIELD_DOUBLE, true,
                                       &d->f_conv_vel));
    MF_CALL(mf_particles_request_field(p, "PointVelocity", 3, MF_FIELD_DOUBLE, true,
                                       &d->f_point_vel));
    d->nscalars = sim->nscalars;
    for (int k = 0; k < sim->nscalars; k++) {
        d->f_scalar[k] = mf_particles_field_index(p, sim->scalar_name[k]);
        if (d->f_scalar[k] < 0)
            return MF_ERROR(MF_ERR_INTERNAL, "scalar '%s' has no particle field",
                            sim->scalar_name[k]);
    }
    /* Holes are filled on the scene's lattice: any fluid point's start
     * position is a site of it. */
    for (size_t i = 0; i < p->n; i++)
        if (p->kind[i] == MF_FLUID || i + 1 == p->n) {
            memcpy(d->lattice, &p->pos[3 * i], sizeof d->lattice);
            break;
        }
    /* On several ranks: the MPS phases' copies carry r^n (the PPE source of
     * densityReference startOfStep and divergence reads it), and the MAFL
     * phases have copies of their own. */
    MF_CALL(mps_halo_add_field(d->mps, d->f_pos_n, MPS_HALO_STAR));
    if (sim->par)
        MF_CALL(mf_halo_create(&d->halo));
    /* Inlet and outlet points are computation points that stay in place. */
    if (sim->emitters)
        sim->emitters->fixed_buffers = true;
    MF_CALL(mafl_reserve(d, p->n));
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "MPS-MAFL: reconfiguration %s, convection %s, dr = %g l0, carried fields: "
                  "velocity%s%s\n",
                  d->s.reconfiguration, d->conv.info->name, d->s.grid_spacing,
                  sim->nscalars ? " and " : "", sim->nscalars ? sim->scalar_name[0] : "");
    for (int k = 1; k < sim->nscalars; k++)
        mf_log_printf(sim->log, MF_LOG_NORMAL, "MPS-MAFL: also carries %s\n",
                      sim->scalar_name[k]);
    return 0;
}

static int mafl_create(const void *settings, mf_sim *sim, const mf_dict *solver_dict,
                       void **data)
{
    mafl_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->s = *(const mafl_settings *)settings;
    int rc = create_data(d, sim, solver_dict);
    if (rc != 0) {
        mafl_destroy_data(d);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    *data = d;
    return 0;
}

static int mafl_step_op(void *data, mf_sim *sim, double dt)
{
    MF_CALL(mafl_step(data, sim, dt));
    return 0;
}

static void mafl_destroy(void *data) { mafl_destroy_data(data); }

static void mafl_report(void *data, const mf_sim *sim, mf_log *log)
{
    const mafl_data *d = data;
    double points[3] = {(double)d->total_added, (double)d->total_removed,
                        (double)d->total_separated}; /* every rank's */
    mf_parallel_sum(sim->par, points, 3);
    /* Steps this run took (one explicit phase of the MPS module each);
     * sim->step counts from before a restart. */
    const double steps = d->mps->attempts > 0 ? (double)d->mps->attempts : 1.0;
    const double total = d->t_lagrangian + d->t_reconfigure + d->t_eulerian + d->t_points;
    mf_log_printf(log, MF_LOG_QUIET,
                  "MAFL time per step (ms): Lagrangian (MPS) %.3f, reconfiguration %.3f, "
                  "Eulerian %.3f, points %.3f; total %.3f\n",
                  1e3 * d->t_lagrangian / steps, 1e3 * d->t_reconfigure / steps,
                  1e3 * d->t_eulerian / steps, 1e3 * d->t_points / steps, 1e3 * total / steps);
    mf_log_printf(log, MF_LOG_QUIET,
                  "MAFL points: added %.0f (eq. 22), removed %.0f over the run; %.0f moves apart "
                  "(separation); %ld grid widenings where |u^a| dt > dr%s\n",
                  points[0], points[1], points[2], d->q_limited, sim->par ? " (on rank 0)" : "");
}

const mf_solver_ops mf_solver_MAFL = {
    .info = {MF_ABI_VERSION, MF_KIND_SOLVER, "MAFL",
             "MPS-MAFL: MPS with computation points reconfigured and fields convected on "
             "directional grids (the paper's Algorithm 2)",
             mafl_params, MAFL_NPARAMS, sizeof(mafl_settings)},
    .create = mafl_create,
    .step = mafl_step_op,
    .destroy = mafl_destroy,
    .stable_dt = NULL, /* the forces' limits are the time loop's (mf_stable_dt) */
    .report = mafl_report,
};
