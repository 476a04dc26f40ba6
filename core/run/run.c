/* run.c: the time loop. */
#include "mf_run.h"
#include "mf_run_internal.h"
#include "mf_thread_tuner.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "mf_alloc.h"
#include "mf_bodies.h"
#include "mf_emitter.h"
#include "mf_error.h"
#include "mf_timestep.h"
#include "mf_walls.h"

size_t mf_peak_memory(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (size_t)ru.ru_maxrss * 1024u; /* Linux reports KiB */
}

/* ---- a copy of the particles to go back to when a step fails ----------
 * Every array but the fields a step writes in full before reading them
 * (mf_field.step_scratch): those are left as the failed attempt had them,
 * and the retry writes them again. */
typedef struct saved_state {
    size_t n, n_owned, cap;
    double *pos, *vel;
    uint8_t *kind;
    int64_t *id, next_id;
    void *field[MF_MAX_FIELDS];
    double time;
} saved_state;

static size_t field_bytes(const mf_field *f, size_t n)
{
    return n * (size_t)f->ncomp * (f->type == MF_FIELD_DOUBLE ? sizeof(double) : sizeof(int32_t));
}

static int save_state(saved_state *s, const mf_particles *p, double time)
{
    if (s->cap < p->n) {
        size_t cap = p->n + p->n / 4 + 16;
        bool grown = mf_resize(&s->pos, 3 * cap, sizeof(double)) == 0 &&
                     mf_resize(&s->vel, 3 * cap, sizeof(double)) == 0 &&
                     mf_resize(&s->kind, cap, 1) == 0 &&
                     mf_resize(&s->id, cap, sizeof(int64_t)) == 0;
        for (int f = 0; grown && f < p->nfields; f++)
            if (!p->field[f].step_scratch)
                grown = mf_resize(&s->field[f], field_bytes(&p->field[f], cap), 1) == 0;
        if (!grown)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory saving the state of step");
        s->cap = cap;
    }
    for (int f = 0; f < p->nfields; f++)
        if (!s->field[f] && !p->field[f].step_scratch)
            s->field[f] = malloc(field_bytes(&p->field[f], s->cap));
    bool ok = s->pos && s->vel && s->kind && s->id;
    for (int f = 0; f < p->nfields; f++)
        ok = ok && (s->field[f] || p->field[f].step_scratch);
    if (!ok)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory saving the state of step");
    s->n = p->n;
    s->n_owned = p->n_owned;
    s->next_id = p->next_id;
    s->time = time;
    memcpy(s->pos, p->pos, 3 * p->n * sizeof(double));
    memcpy(s->vel, p->vel, 3 * p->n * sizeof(double));
    memcpy(s->kind, p->kind, p->n);
    memcpy(s->id, p->id, p->n * sizeof(int64_t));
    for (int f = 0; f < p->nfields; f++)
        if (s->field[f])
            memcpy(s->field[f], p->field[f].data, field_bytes(&p->field[f], p->n));
    return 0;
}

static int restore_state(const saved_state *s, mf_particles *p)
{
    MF_CALL(mf_particles_reserve(p, s->n));
    p->n = s->n;
    p->n_owned = s->n_owned;
    p->next_id = s->next_id;
    memcpy(p->pos, s->pos, 3 * s->n * sizeof(double));
    memcpy(p->vel, s->vel, 3 * s->n * sizeof(double));
    memcpy(p->kind, s->kind, s->n);
    memcpy(p->id, s->id, s->n * sizeof(int64_t));
    for (int f = 0; f < p->nfields; f++)
        if (s->field[f])
            memcpy(p->field[f].data, s->field[f], field_bytes(&p->field[f], s->n));
    return 0;
}

static void free_state(saved_state *s)
{
    free(s->pos);
    free(s->vel);
    free(s->kind);
    free(s->id);
    for (int f = 0; f < MF_MAX_FIELDS; f++)
        free(s->field[f]);
}

/* ---- the loop ------------------------------------------------------------ */
static double max_fluid_nu(const mf_sim *sim)
{
    double nu = 0;
    for (int k = 0; k < sim->nfluids; k++)
        if (sim->fluid[k].nu > nu)
            nu = sim->fluid[k].nu;
    return nu;
}

/* The step fell below its floor: name the fastest particle, which is
 * nearly always where a run goes unstable. */
static int diagnose_collapse(const mf_sim *sim, double dt, double floor_dt, const char *limiter)
{
    const mf_particles *p = sim->p;
    size_t fastest = SIZE_MAX;
    double u2max = -1;
    for (size_t i = 0; i < p->n_owned; i++) {
        const double *v = &p->vel[3 * i];
        double u2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if (u2 > u2max) {
            u2max = u2;
            fastest = i;
        }
    }
    mf_particle_info f; /* the fastest over all ranks, named on every rank */
    mf_parallel_argmax(sim->par, &u2max, p, fastest, &f);
    const double *x = f.x;
    return MF_ERROR(MF_ERR_NUMERIC,
                    "unstable (timeStep): the time step fell to %g s (%s limit), below "
                    "minDeltaT %g s, at "
                    "time %g: particle id %lld at (%g %g %g) moves at %g m/s. A pressure "
                    "spike feeds back through the Courant limit: try relaxation 0.2, the "
                    "collision model, or a fixed deltaT",
                    dt, limiter, floor_dt, sim->time, (long long)f.id, x[0], x[1], x[2],
                    sqrt(fmax(u2max, 0)));
}

/* The time the step must not pass: the next write time (adjustableRunTime)
 * or the end. A step within a hair of it (relative 1e-9, far above the
 * rounding of sums of steps) is shortened to end there, and the time is then
 * set to the target itself, not to time + dt: a fixed step, or one chosen by
 * the limits, lands exactly on endTime and on every write time. *land is
 * the target when the step lands on it, NAN otherwise. */
static void land_on_target(const mf_run *run, double next_write, double *dt, double *land)
{
    const mf_sim *sim = run->sim;
    double target = sim->end_time;
    /* An end time that is a write time (0.018 and 9 x 0.002 differ in the
     * last bit) ends on the write time: a run stopped there and restarted
     * then takes the steps of the run that went on through it. */
    if (!run->ctl.write_by_steps &&
        (next_write < target || fabs(next_write - target) <= 1e-9 * target))
        target = next_write;
    const double left = target - sim->time;
    *land = NAN;
    if (left > 0 && *dt >= left * (1 - 1e-9)) {
        /* A fixed step that reaches the target but for rounding (k steps of
         * deltaT to a write time) stays deltaT: only the time is set. */
        if (run->ctl.adjust || fabs(*dt - left) > 1e-9 * *dt)
            *dt = left;
        *land = target;
    } else if (left > 0 && run->ctl.adjust && *dt > 0.5 * left) {
        *dt = 0.5 * left; /* two even steps rather than a sliver */
    }
}

/* The step the limits allow ("natural"), then shortened to land on the next
 * write time or the end. Growth is limited relative to the last natural
 * step, so a sliver taken to land on a write time does not hold dt down. */
static int choose_dt(mf_run *run, double next_write, double *dt, const char **limiter,
                     double *land)
{
    mf_sim *sim = run->sim;
    const mf_run_control *c = &run->ctl;
    if (!c->adjust) {
        *dt = c->delta_t;
        *limiter = "fixed";
        land_on_target(run, next_write, dt, land);
    } else {
        mf_dt_choice ch;
        /* A moving wall limits the step as the fluid does: it must not
         * cross more than maxCo spacings of fluid in one step. */
        double umax = fmax(mf_max_fluid_speed(sim->p), mf_walls_max_speed(sim->walls, sim->p));
        mf_parallel_max(sim->par, &umax, 1); /* every rank takes the same step */
        mf_dt_choose(sim->l0, umax, c->max_co,
                     sim->viscosity_implicit ? 0.0 : max_fluid_nu(sim),
                     c->max_di, c->max_delta_t, &ch);
        double natural = ch.dt;
        *limiter = ch.limiter;
        /* Start at deltaT, grow at most 20% a step (OpenFOAM's damping). */
        double last = run->sim->dt_natural > 0 ? run->sim->dt_natural : c->delta_t;
        if (natural > 1.2 * last) {
            natural = 1.2 * last;
            *limiter = "growth";
        }
        /* The solver's and every force's own limit (surfaceTension's
         * capillary step, a plugin's), whatever the solver; the smallest
         * over the ranks (the name is this rank's). */
        double sdt = INFINITY;
        const char *who = NULL;
        MF_CALL(mf_stable_dt(run->solver, sim, &sdt, &who));
        mf_parallel_min(sim->par, &sdt, 1);
        if (sdt < natural) {
            natural = sdt;
            *limiter = who ? who : "solver";
        }
        run->sim->dt_natural = natural;
        *dt = natural;
        land_on_target(run, next_write, dt, land);
    }
    if (!(*dt > 0) || !isfinite(*dt))
        return MF_ERROR(MF_ERR_NUMERIC, "the time step became %g at time %g", *dt, sim->time);
    if (c->adjust && *dt < c->min_delta_t && run->sim->dt_natural < c->min_delta_t)
        return diagnose_collapse(sim, *dt, c->min_delta_t, *limiter);
    return 0;
}

static int write_now(mf_run *run)
{
    if (!run->writer_ops)
        return 0;
    /* Collective, and rank 0 alone writes the index: agree on the outcome. */
    MF_CALL(mf_parallel_agree(run->sim->par,
                              run->writer_ops->write(run->writer->data, run->sim, run->params)));
    run->sim->snapshot_epoch++;
    int rc = 0;
    for (size_t k = 0; k < run->nfunctions && rc == 0; k++) {
        const mf_function_object_ops *fo = (const mf_function_object_ops *)run->functions[k].info;
        if (fo->write)
            rc = fo->write(run->functions[k].data, run->sim);
    }
    MF_CALL(mf_parallel_agree(run->sim->par, rc));
    run->writes++;
    MF_CALL(mf_run_after_write(run));
    return 0;
}

/* Inlets, outlets and nozzles add and remove particles before the solver's
 * step (inside the attempt, so a retry undoes them with the rest). The
 * kinetic energy they bring in is a source the watch counts as work. */
static int apply_emitters(mf_run *run, double dt, double *kinetic_in, size_t *added,
                          size_t *removed)
{
    mf_sim *sim = run->sim;
    *kinetic_in = 0;
    *added = *removed = 0;
    if (!sim->emitters)
        return 0;
    const double before = mf_emitters_fluid_kinetic_energy(sim);
    MF_CALL(mf_parallel_agree(sim->par, mf_emitters_apply(sim->emitters, sim, dt, added, removed)));
    double sums[3] = {mf_emitters_fluid_kinetic_energy(sim) - before, (double)*added,
                      (double)*removed};
    mf_parallel_sum(sim->par, sums, 3); /* over the ranks */
    *kinetic_in = sums[0];
    *added = (size_t)sums[1];
    *removed = (size_t)sums[2];
    mf_log_printf(sim->log, MF_LOG_STEP, "Emitters: added %zu, removed %zu\n", *added, *removed);
    return 0;
}

/* Courant numbers of the fluid over all ranks (the mean weighted by each
 * rank's fluid count). */
static void courant(const mf_sim *sim, double dt, double *mean, double *max)
{
    mf_courant(sim->p, dt, sim->l0, mean, max);
    if (!sim->par)
        return;
    size_t counts[MF_NKINDS];
    mf_particles_count_kinds(sim->p, counts);
    double v[2] = {*mean * (double)counts[MF_FLUID], (double)counts[MF_FLUID]};
    mf_parallel_sum(sim->par, v, 2);
    *mean = v[1] > 0 ? v[0] / v[1] : 0.0;
    mf_parallel_max(sim->par, max, 1);
}

static int step_once(mf_run *run, saved_state *saved, double next_write)
{
    mf_sim *sim = run->sim;
    double dt = 0, land = NAN;
    const char *limiter = NULL;
    MF_CALL(choose_dt(run, next_write, &dt, &limiter, &land));
    MF_CALL(save_state(saved, sim->p, sim->time));
    const double work0 = run->watch.work;
    size_t added = 0, removed = 0;
    for (long attempt = 0;; attempt++) {
        sim->dt = dt;
        double courant_mean = 0, courant_max = 0;
        courant(sim, dt, &courant_mean, &courant_max);
        mf_log_printf(sim->log, MF_LOG_STEP, "Courant Number mean: %g max: %g\n", courant_mean,
                      courant_max);
        mf_log_printf(sim->log, MF_LOG_STEP, "deltaT = %g\n", dt);
        mf_log_printf(sim->log, MF_LOG_STEP, "Time = %.10g\n\n", sim->time + dt);
        double kinetic_in = 0;
        /* Moving walls first, to where they are at the end of the step
         * (mf_walls_advance); a retry restores their particles with the rest. */
        int rc = mf_walls_advance(sim->walls, sim->p, saved->time, saved->time + dt);
        if (rc == 0)
            rc = apply_emitters(run, dt, &kinetic_in, &added, &removed);
        run->watch.work = work0 + kinetic_in;
        sim->forces_record.valid = false; /* set again by this attempt's forces */
        if (rc == 0)
            rc = mf_solver_step(run->solver, sim, dt);
        /* One outcome for every rank: all retry, stop or go on together. */
        rc = mf_parallel_agree(sim->par, rc);
        if (rc == 0) {
            sim->time = saved->time + dt; /* the watch reports the time reached */
            rc = mf_watch_check(&run->watch, sim, dt);
            sim->time = saved->time;
        }
        if (rc == 0)
            break;
        bool retry = (rc > 0 || rc == MF_ERR_NUMERIC) && attempt < run->ctl.max_retries;
        run->watch.work = work0;
        if (!retry) {
            MF_CALL(restore_state(saved, sim->p));
            sim->time = saved->time;
            mf_walls_set_time(sim->walls, sim->time); /* the walls where the particles are */
            mf_bodies_set_committed(sim->walls);
            return mf_error_trace(rc, __FILE__, __LINE__, __func__);
        }
        mf_log_printf(sim->log, MF_LOG_QUIET,
                      "--> step at time %g failed (%s); retrying with deltaT = %g (retry %ld of "
                      "%ld)\n",
                      saved->time, mf_error_message(), 0.5 * dt, attempt + 1,
                      run->ctl.max_retries);
        mf_error_clear();
        MF_CALL(restore_state(saved, sim->p));
        sim->time = saved->time;
        run->retries++;
        dt *= 0.5;
        land = NAN; /* half the step no longer reaches the target */
        run->sim->dt_natural = dt;
    }
    (void)limiter;
    if (sim->emitters) { /* counted once the step is accepted */
        sim->emitters->total_added += added;
        sim->emitters->total_removed += removed;
    }
    mf_watch_accept(&run->watch);
    sim->time = isnan(land) ? sim->time + dt : land;
    /* The rigid bodies take the step's state and impulse (mf_bodies.h). */
    MF_CALL(mf_bodies_accept(sim->walls, sim->time, dt));
    sim->step++;
    run->steps++;
    int rc = 0;
    for (size_t k = 0; k < run->nfunctions && rc == 0; k++) {
        const mf_function_object_ops *fo = (const mf_function_object_ops *)run->functions[k].info;
        rc = fo->execute(run->functions[k].data, sim);
    }
    MF_CALL(mf_parallel_agree(sim->par, rc));
    return 0;
}

/* The write time after `next_write`. Write times are k times the interval
 * (mf_run_first_write), never sums of it: a run restarted at a write time
 * finds the same next write time to the bit as the run that wrote it (0.002
 * added nine times is not 9 x 0.002, and the step that lands on it would
 * differ). With writeControl timeStep they are step counts, exact either way. */
static double next_write_after(const mf_run *run, double next_write)
{
    const double interval = run->ctl.write_interval;
    if (run->ctl.write_by_steps)
        return next_write + interval;
    return (floor(next_write / interval + 0.5) + 1) * interval;
}

int mf_run_loop(mf_run *run, bool write_initial)
{
    mf_sim *sim = run->sim;
    saved_state saved;
    memset(&saved, 0, sizeof saved);
    const double t0 = mf_wall_seconds(), c0 = mf_cpu_seconds();
    mf_thread_tuner tuner; /* the team size, by measurement (mf_thread_tuner.h) */
    mf_thread_tuner_init(&tuner, false, 1);
    /* Next write time: the first multiple of the interval after now. */
    double next_write = mf_run_first_write(run);
    int rc = 0;
    /* Inlets and outlets exchange energy with the outside (the inflow's
     * kinetic energy, the pressure work at the open ends) that the watch
     * cannot count: its energy criterion would stop a sound run. */
    if (sim->emitters && (sim->emitters->ninlets || sim->emitters->noutlets) &&
        run->watch.s.enabled && isfinite(run->watch.s.energy_tolerance)) {
        run->watch.s.energy_tolerance = INFINITY;
        mf_log_printf(sim->log, MF_LOG_NORMAL,
                      "Watch: no energy check, the inlets and outlets exchange energy with the "
                      "outside\n");
    }
    /* A nozzle's jet is thin on purpose: its number density says nothing
     * about the fluid blowing apart. */
    if (sim->emitters && sim->emitters->nnozzles && run->watch.s.enabled &&
        run->watch.s.density_collapse > 0) {
        run->watch.s.density_collapse = 0;
        mf_log_printf(sim->log, MF_LOG_NORMAL,
                      "Watch: no density-collapse check, nozzles add thin jets of fluid\n");
    }
    if (!run->ctl.adjust) { /* a fixed step is the user's choice: say when it is too long */
        double sdt = INFINITY;
        const char *who = NULL;
        MF_CALL_GOTO(rc, mf_stable_dt(run->solver, sim, &sdt, &who), done);
        if (run->ctl.delta_t > sdt)
            mf_log_printf(sim->log, MF_LOG_QUIET,
                          "Warning: deltaT %g s is above the stable step of %s, %g s "
                          "(adjustTimeStep no keeps it): the run may go unstable\n",
                          run->ctl.delta_t, who, sdt);
    }
    if (write_initial)
        MF_CALL_GOTO(rc, write_now(run), done);
    mf_log_printf(sim->log, MF_LOG_NORMAL, "\nStarting time loop\n\n");
    mf_thread_tuner_start(&tuner);
    while (sim->time < sim->end_time * (1 - 1e-12)) {
        const double step_start = mf_wall_seconds();
        rc = step_once(run, &saved, next_write);
        if (rc == 0) { /* the write below is not the step's time: timed before it */
            mf_thread_tuner_next(&tuner, mf_wall_seconds() - step_start, true);
            mf_thread_tuner_apply(&tuner);
        }
        if (rc != 0) {
            /* Keep what we had: the state before the failed step. */
            mf_log_printf(sim->log, MF_LOG_QUIET,
                          "--> the run stops at time %g (step %ld); the particles are back at "
                          "the last good state",
                          sim->time, sim->step);
            if (run->writer_ops) {
                int wrc = run->writer_ops->write(run->writer->data, sim, run->params);
                mf_log_printf(sim->log, MF_LOG_QUIET, wrc == 0 ? ", written as a snapshot.\n"
                                                               : ", which could not be written.\n");
            } else {
                mf_log_printf(sim->log, MF_LOG_QUIET, ".\n");
            }
            goto done;
        }
        bool write = run->ctl.write_by_steps ? (double)sim->step >= next_write - 0.5
                                             : sim->time >= next_write * (1 - 1e-9);
        bool wrote = write || sim->time >= sim->end_time * (1 - 1e-12);
        if (wrote) {
            MF_CALL_GOTO(rc, write_now(run), done);
            while (next_write <= (run->ctl.write_by_steps ? (double)sim->step : sim->time * (1 + 1e-9)))
                next_write = next_write_after(run, next_write);
        }
        double wall = mf_wall_seconds() - t0;
        mf_log_printf(sim->log, MF_LOG_STEP, "ExecutionTime = %.3f s  ClockTime = %.0f s\n\n",
                      mf_cpu_seconds() - c0, wall);
        mf_log_progress(sim->log, sim->time, sim->end_time, wall);
        bool stop = false, write_extra = false;
        MF_CALL_GOTO(rc, mf_run_between_steps(run, wrote, &next_write, &stop, &write_extra), done);
        if (write_extra)
            MF_CALL_GOTO(rc, write_now(run), done);
        if (stop)
            break;
    }
    mf_log_progress_end(sim->log);
done:
    if (tuner.on) {
        mf_log_printf(sim->log, MF_LOG_NORMAL,
                      "Threads: chosen by measurement (OMP_NUM_THREADS not set): %ld steps with "
                      "%d threads, %ld with 1; one thread was the faster in %d of %d probes\n",
                      tuner.steps_with[0], tuner.full, tuner.steps_with[1], tuner.chose_one,
                      tuner.probes);
        tuner.current = tuner.full; /* what comes after the run has the whole team */
        mf_thread_tuner_apply(&tuner);
    }
    if (sim->emitters)
        mf_log_printf(sim->log, MF_LOG_QUIET, "Emitters over the run: added %zu, removed %zu\n",
                      sim->emitters->total_added, sim->emitters->total_removed);
    run->wall_seconds = mf_wall_seconds() - t0;
    free_state(&saved);
    return rc;
}
