/* module_calls.c: the thin wrappers through which modules are called
 * (mf_modules.h, "calling modules"). Whatever every call of a kind needs
 * (the log line, the timers, the checks of the result, the fault-injection
 * point) is here once, not in each caller. */
#include <math.h>
#include <string.h>

#include "mf_clock.h"
#include "mf_error.h"
#include "mf_modules.h"
#include "mf_parallel.h"

static int fault_point(const mf_sim *sim, mf_fault_site site, const char *module,
                       double *values, size_t n, int rc)
{
    if (!sim->fault.fn)
        return rc;
    return sim->fault.fn(sim->fault.ctx, sim, site, module, values, n, rc);
}

static inline const mf_force_ops *force_ops(const mf_module *m)
{
    return (const mf_force_ops *)m->info;
}

/* The first owned particle whose acceleration is not finite, after force
 * `name` added its part: a fault of that force, said as the watch says it. */
static int check_accelerations(const mf_sim *sim, const char *name, const double *a)
{
    const mf_particles *p = sim->p;
    for (size_t i = 0; i < p->n_owned; i++)
        if (!isfinite(a[3 * i]) || !isfinite(a[3 * i + 1]) || !isfinite(a[3 * i + 2]))
            return MF_ERROR(MF_ERR_NUMERIC,
                            "unstable (nonFinite) at time %g, step %ld: force '%s' gave %s "
                            "particle id %lld at (%g %g %g) a non-finite acceleration",
                            sim->time, sim->step, name, mf_particle_kind_name(p->kind[i]),
                            (long long)p->id[i], p->pos[3 * i], p->pos[3 * i + 1],
                            p->pos[3 * i + 2]);
    return 0;
}

int mf_force_accumulate(mf_sim *sim, double *acc)
{
    mf_particles *p = sim->p;
    sim->forces_record.valid = false;
    if (sim->nforces == 0)
        return 0;
    int fa = 0;
    MF_CALL(mf_particles_request_field(p, MF_FORCE_FIELD, 3, MF_FIELD_DOUBLE, false, &fa));
    /* Zeroed here and summed by the forces at every step; read only after
     * (mf_watch_check, while forces_record.valid, which each attempt clears
     * first): a retry needs no copy of it. */
    MF_CALL(mf_particles_set_step_scratch(p, fa));
    double *a = mf_particles_fd(p, fa);
    memset(a, 0, 3 * p->n * sizeof *a);
    for (size_t k = 0; k < sim->nforces; k++) {
        mf_module *m = &sim->forces[k];
        const mf_force_ops *ops = force_ops(m);
        const double t0 = mf_wall_seconds();
        int rc = ops->accumulate(m->data, sim, a);
        rc = fault_point(sim, MF_FAULT_FORCE, m->info->name, a, 3 * p->n, rc);
        if (rc == 0 && ops->write_fields)
            rc = ops->write_fields(m->data, sim);
        m->calls++;
        m->seconds += mf_wall_seconds() - t0;
        if (rc == 0)
            rc = check_accelerations(sim, m->info->name, a);
        /* On several ranks every rank stops, naming what failed where. */
        MF_CALL(mf_parallel_agree(sim->par, rc));
    }
    const int ff = mf_particles_field_index(p, "FluidId");
    double power = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        for (int c = 0; c < 3; c++)
            acc[3 * i + c] += a[3 * i + c];
        if (p->kind[i] == MF_FLUID) {
            const double *v = &p->vel[3 * i], *ai = &a[3 * i];
            power += mf_sim_particle_mass(sim, ff, i) * (ai[0] * v[0] + ai[1] * v[1] + ai[2] * v[2]);
        }
    }
    sim->forces_record.power = power;
    sim->forces_record.valid = true;
    return 0;
}

int mf_forces_stable_dt(const mf_sim *sim, double *dt, const char **who)
{
    *dt = INFINITY;
    *who = NULL;
    for (size_t k = 0; k < sim->nforces; k++) {
        const mf_module *m = &sim->forces[k];
        const mf_force_ops *ops = force_ops(m);
        if (!ops->stable_dt || !m->data)
            continue;
        double lim = INFINITY;
        MF_CALL(ops->stable_dt(m->data, sim, &lim));
        if (lim < *dt) {
            *dt = lim;
            *who = m->info->name;
        }
    }
    return 0;
}

int mf_stable_dt(const mf_module *solver, const mf_sim *sim, double *dt, const char **who)
{
    MF_CALL(mf_forces_stable_dt(sim, dt, who));
    const mf_solver_ops *ops = solver ? (const mf_solver_ops *)solver->info : NULL;
    if (ops && ops->stable_dt) {
        double lim = INFINITY;
        MF_CALL(ops->stable_dt(solver->data, sim, &lim));
        if (lim < *dt) {
            *dt = lim;
            *who = solver->info->name;
        }
    }
    return 0;
}

bool mf_forces_claim_surface_pressure(mf_sim *sim)
{
    bool any = false;
    for (size_t k = 0; k < sim->nforces; k++) {
        mf_module *m = &sim->forces[k];
        const mf_force_ops *ops = force_ops(m);
        if (ops->claim_surface_pressure && m->data && ops->claim_surface_pressure(m->data))
            any = true;
    }
    return any;
}

int mf_forces_surface_pressure(const mf_sim *sim, const uint8_t *dirichlet, double *p)
{
    for (size_t i = 0; i < sim->p->n; i++)
        p[i] = 0;
    for (size_t k = 0; k < sim->nforces; k++) {
        const mf_module *m = &sim->forces[k];
        const mf_force_ops *ops = force_ops(m);
        if (ops->surface_pressure && m->data)
            MF_CALL(ops->surface_pressure(m->data, sim, dirichlet, p));
    }
    return 0;
}

int mf_pressure_solve(mf_module *m, const mf_sim *sim, const char *field, const mf_csr *A,
                      const double *b, double *x, mf_solve_report *rep)
{
    return mf_pressure_solve_rows(m, sim, field, A, NULL, b, x, rep);
}

int mf_pressure_solve_rows(mf_module *m, const mf_sim *sim, const char *field, const mf_csr *A,
                           const mf_row_names *rows, const double *b, double *x,
                           mf_solve_report *rep)
{
    const mf_pressure_ops *ops = (const mf_pressure_ops *)m->info;
    mf_solve_report local;
    if (!rep)
        rep = &local;
    memset(rep, 0, sizeof *rep);
    const double t0 = mf_wall_seconds();
    int rc = rows && ops->solve_rows ? ops->solve_rows(m->data, A, rows, b, x, rep)
                                     : ops->solve(m->data, A, b, x, rep);
    rc = fault_point(sim, MF_FAULT_PRESSURE, m->info->name, x, A ? A->nrows : 0, rc);
    m->calls++;
    m->seconds += mf_wall_seconds() - t0;
    mf_parallel_stats *st = mf_parallel_statistics(sim->par); /* NULL: a serial run */
    if (st) {
        st->solves++;
        st->solve_setups += rep->setups;
        st->t_solve_setup += rep->setup_seconds;
        st->t_solve_iterate += rep->solve_seconds;
    }
    mf_log_printf(sim->log, MF_LOG_STEP,
                  "%s:  Solving for %s, Initial residual = %g, Final residual = %g, No "
                  "Iterations %d\n",
                  m->info->name, field, rep->initial_residual, rep->final_residual,
                  rep->iterations);
    if (rc != 0)
        rc = mf_error_trace(rc, __FILE__, __LINE__, __func__);
    for (size_t r = 0; rc == 0 && A && r < A->nrows; r++)
        if (!isfinite(x[r]))
            rc = MF_ERROR(MF_ERR_NUMERIC,
                          "unstable (nonFinite) at time %g, step %ld: %s returned a "
                          "non-finite %s in row %zu of %zu",
                          sim->time, sim->step, m->info->name, field, r, A->nrows);
    /* The solve is collective: on several ranks one outcome for all. */
    return mf_parallel_agree(sim->par, rc);
}

int mf_solver_step(mf_module *solver, mf_sim *sim, double dt)
{
    const mf_solver_ops *ops = (const mf_solver_ops *)solver->info;
    const double t0 = mf_wall_seconds();
    int rc = ops->step(solver->data, sim, dt);
    rc = fault_point(sim, MF_FAULT_STEP, solver->info->name, NULL, 0, rc);
    solver->calls++;
    solver->seconds += mf_wall_seconds() - t0;
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    return 0;
}
