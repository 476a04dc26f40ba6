/* mafl_step.c: one MPS-MAFL step, phase by phase (the paper's Algorithm 2). */
#include <math.h>
#include <string.h>

#include "mafl.h"
#include "mf_error.h"
#include "mf_halo.h"
#include "mf_run.h"

/* Keep r^n, u^n and the kinds in fields (the MPS step may reorder the
 * particles); inlet and outlet points join the Lagrangian motion as fluid,
 * so that the fluid beside them is neither stretched nor squeezed. */
static void save_start(mafl_data *d, mf_particles *p)
{
    double *xn = mf_particles_fd(p, d->f_pos_n), *un = mf_particles_fd(p, d->f_vel_n);
    int32_t *kind0 = mf_particles_fi(p, d->f_kind);
    memcpy(xn, p->pos, 3 * p->n * sizeof *xn);
    memcpy(un, p->vel, 3 * p->n * sizeof *un);
    for (size_t i = 0; i < p->n; i++) {
        kind0[i] = p->kind[i];
        if (p->kind[i] == MF_INLET || p->kind[i] == MF_OUTLET)
            p->kind[i] = MF_FLUID;
    }
}

static void restore_kinds(mafl_data *d, mf_particles *p)
{
    const int32_t *kind0 = mf_particles_fi(p, d->f_kind);
    for (size_t i = 0; i < p->n; i++)
        p->kind[i] = (uint8_t)kind0[i];
}

/* Inlet points are boundary values: what the Eulerian phase reads from them
 * is the prescribed velocity, not the one the Lagrangian phase gave them
 * (the pressure drop across the inlet buffer changes it by up to 2% a step
 * at Courant number 0.2; in a channel at l0 = H/10 this won back 0.05% of
 * the inflow). */
static void restore_inlet_velocity(mafl_data *d, mf_particles *p)
{
    const int32_t *kind0 = mf_particles_fi(p, d->f_kind);
    const double *un = mf_particles_fd(p, d->f_vel_n);
    for (size_t i = 0; i < p->n; i++)
        if (kind0[i] == MF_INLET)
            memcpy(&p->vel[3 * i], &un[3 * i], 3 * sizeof *un);
}

/* r^{n+1} and the convected values become the particles' state; inlet
 * points keep their prescribed velocity. */
static void commit(mafl_data *d, mf_sim *sim)
{
    mf_particles *p = sim->p;
    const size_t n = p->n;
    const int32_t *kind0 = mf_particles_fi(p, d->f_kind);
    const double *un = mf_particles_fd(p, d->f_vel_n);
    memcpy(p->pos, d->pos_new, 3 * n * sizeof *p->pos);
    for (size_t i = 0; i < n; i++) {
        if (kind0[i] == MF_INLET)
            memcpy(&p->vel[3 * i], &un[3 * i], 3 * sizeof *un);
        if (!d->convected[i])
            continue;
        for (int c = 0; c < sim->dim; c++)
            p->vel[3 * i + c] = d->value[c * n + i];
        for (int k = 0; k < d->nscalars; k++)
            mf_particles_fd(p, d->f_scalar[k])[i] = d->value[(sim->dim + k) * n + i];
    }
}

/* On several ranks, copies of the other ranks' points within `radius`
 * (positions, velocities, kinds, ids and the fields the MAFL phases read of
 * a neighbour: kinds before the Lagrangian phase, free-surface flags,
 * scalars). Nothing on one rank. */
int mafl_copies(mafl_data *d, mf_sim *sim, double radius, bool values)
{
    if (!d->halo)
        return 0;
    mf_halo_spec spec = {.radius = radius, .velocities = values};
    if (values) {
        spec.field[spec.nfields++] = d->f_kind;
        spec.field[spec.nfields++] = d->mps->f_flags;
        for (int k = 0; k < d->nscalars; k++)
            spec.field[spec.nfields++] = d->f_scalar[k];
    }
    MF_CALL(mf_halo_build(d->halo, sim->par, sim->p, &spec));
    MF_CALL(mafl_reserve(d, sim->p->n));
    return 0;
}

/* How far the Eulerian phase reads from a point at r^L: its 1-D grid
 * reaches two spacings upstream, each spacing dr or |u^a| dt when longer,
 * and |u^a| dt = |r^L - r^{n+1}| is at most the Lagrangian displacement plus
 * the reconfiguration's largest shifts (0.2 l0 of the rule or the surface,
 * 0.2 l0 of the separation); then the disk of eq. 23. */
static double eulerian_reach(const mafl_data *d, const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    const double *xn = mf_particles_fd(p, d->f_pos_n);
    double moved = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        double r2 = 0;
        for (int c = 0; c < 3; c++)
            r2 += (p->pos[3 * i + c] - xn[3 * i + c]) * (p->pos[3 * i + c] - xn[3 * i + c]);
        moved = fmax(moved, sqrt(r2));
    }
    mf_parallel_max(sim->par, &moved, 1);
    const double l0 = sim->l0, travel = moved + 0.4 * l0;
    return 2.0 * fmax(d->s.grid_spacing * l0, travel) + d->s.re_interpolation * l0;
}

int mafl_step(mafl_data *d, mf_sim *sim, double dt)
{
    mf_particles *p = sim->p;
    double t0 = mf_wall_seconds();
    MF_CALL(mafl_reserve(d, p->n));

    /* 1. Lagrangian phase: the MPS module's step. */
    save_start(d, p);
    int rc = mafl_lagrangian(d, sim, dt);
    restore_kinds(d, p);
    MF_CALL(rc);
    double t1 = mf_wall_seconds();
    d->t_lagrangian += t1 - t0;

    /* 2. Reconfiguration: r^{n+1}, u^c, u^a, with neighbours at r^L
     * (inlet points with their prescribed velocity, which the Eulerian
     * phase reads of them). */
    restore_inlet_velocity(d, p);
    double cell = d->s.re_interpolation;
    if (d->s.mps.re_gradient > cell)
        cell = d->s.mps.re_gradient;
    if (cell < 1.5)
        cell = 1.5;
    if (d->halo)
        MF_CALL(mafl_copies(d, sim, fmax(cell * sim->l0, eulerian_reach(d, sim)), true));
    memcpy(d->pos_l, p->pos, 3 * p->n * sizeof *d->pos_l);
    MF_CALL(mf_neighbours_grid(sim->neighbours, p, cell * sim->l0, &d->grid));
    MF_CALL(mafl_reconfigure(d, sim, dt));
    double t2 = mf_wall_seconds();
    d->t_reconfigure += t2 - t1;

    /* 3. Eulerian phase: every carried field to r^{n+1}. */
    MF_CALL(mafl_eulerian(d, sim, dt));
    commit(d, sim);
    if (d->halo)
        mf_halo_drop(d->halo, p);
    double t3 = mf_wall_seconds();
    d->t_eulerian += t3 - t2;

    /* 4. Where the number of points changes (eq. 22). */
    MF_CALL(mafl_update_points(d, sim));
    d->t_points += mf_wall_seconds() - t3;
    d->total_separated += d->last_separated;
    mf_log_printf(sim->log, MF_LOG_STEP,
                  "MAFL: points added %zu, removed %zu, moved apart %zu; max q %.3g\n",
                  d->last_added, d->last_removed, d->last_separated, d->q_max);
    return 0;
}
