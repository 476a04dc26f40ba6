/* mf_run.h: the time loop. It knows modules only through their ops tables.
 *
 * Each step: choose dt (Courant, viscous, solver's own limit, user maximum;
 * or fixed), keep a copy of the particles, let the solver advance; a
 * recoverable failure (e.g. a pressure solve that did not converge) restores
 * the copy and retries with half the step, a few times; then the function
 * objects observe, and at write times the writer writes. A run that cannot
 * go on stops with a diagnosis; every snapshot already written stays whole.
 */
#ifndef MF_RUN_H
#define MF_RUN_H

#include <stdbool.h>

#include "mf_clock.h" /* mf_wall_seconds, mf_cpu_seconds */
#include "mf_modules.h"
#include "mf_sim.h"
#include "mf_watch.h"

typedef struct mf_run_control {
    double delta_t;      /* first (or fixed) step */
    bool adjust;         /* choose dt from the limits */
    double max_co, max_di, max_delta_t;
    double min_delta_t;  /* below this an adjustable step means the run went unstable */
    bool write_by_steps; /* writeControl timeStep */
    double write_interval;
    long max_retries;
} mf_run_control;

typedef struct mf_run {
    mf_sim *sim;
    mf_run_control ctl;
    const mf_solver_ops *solver_ops;
    mf_module *solver;
    const mf_writer_ops *writer_ops; /* may be NULL: no output */
    mf_module *writer;
    size_t nfunctions;
    mf_module *functions;            /* function objects */
    const mf_dict *params;           /* resolved case, handed to the writer */
    mf_watch watch;                  /* checks after every step (mf_watch_init first) */
    /* Filled by the loop. */
    long steps, retries;
    double wall_seconds;
    int writes;
} mf_run;

/* Run from sim->time to sim->end_time. Writes the initial state first when
 * write_initial is set (a fresh start; a restart has it already). */
int mf_run_loop(mf_run *run, bool write_initial);

/* Peak resident memory of this process, bytes. */
size_t mf_peak_memory(void);

#endif
