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
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>

#include "mf_clock.h" /* mf_wall_seconds, mf_cpu_seconds */
#include "mf_modules.h"
#include "mf_sim.h"
#include "mf_watch.h"

/* controlDict stopAt (OpenFOAM's words): when the run ends. */
typedef enum mf_stop_at {
    MF_STOP_END_TIME,    /* at endTime */
    MF_STOP_WRITE_NOW,   /* after the current step, writing a snapshot */
    MF_STOP_NO_WRITE_NOW,/* after the current step, writing nothing */
    MF_STOP_NEXT_WRITE   /* after the next scheduled write */
} mf_stop_at;

typedef struct mf_run_control {
    double delta_t;      /* first (or fixed) step */
    bool adjust;         /* choose dt from the limits */
    double max_co, max_di, max_delta_t;
    double min_delta_t;  /* below this an adjustable step means the run went unstable */
    bool write_by_steps; /* writeControl timeStep */
    double write_interval;
    long max_retries;
    /* Run control between steps (run_control.c). */
    mf_stop_at stop_at;
    long purge_write;    /* keep only the newest N snapshots of this run (0: all) */
} mf_run_control;

typedef struct mf_run mf_run;
/* Called between steps (runTimeModifiable): may change run->ctl and
 * run->sim->end_time. A non-zero return stops the run with that error. */
typedef int (*mf_run_modified_fn)(void *ctx, mf_run *run);

struct mf_run {
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
    /* Run control (run_control.c). `modified` may be NULL. */
    mf_run_modified_fn modified;
    void *modified_ctx;
    int stop_signal;          /* filled: the signal that stopped the run, or 0 */
    char stop_reason[128];    /* filled: why it stopped before endTime ("" if it did not) */
};

/* Run from sim->time to sim->end_time. Writes the initial state first when
 * write_initial is set (a fresh start; a restart has it already). */
int mf_run_loop(mf_run *run, bool write_initial);

/* ---- run control (run_control.c) ---------------------------------------- */
/* SIGINT and SIGTERM (Ctrl-C, a batch scheduler's time limit) set a flag
 * that the loop reads after each step: it writes a last snapshot and stops
 * (run->stop_signal). The handlers reset themselves: a second signal kills
 * at once, as without them. */
int mf_run_signals_install(void);
void mf_run_signals_restore(void);
/* The signal received since install, or 0. */
int mf_run_signal_received(void);
/* "endTime" | "writeNow" | "noWriteNow" | "nextWrite". */
int mf_stop_at_parse(const char *word, mf_stop_at *out);
const char *mf_stop_at_name(mf_stop_at s);

/* Peak resident memory of this process, bytes. */
size_t mf_peak_memory(void);

#pragma GCC visibility pop
#endif
