/* run_control.c: what happens between two steps besides the step itself,
 * the OpenFOAM way: stopAt, runTimeModifiable (through run->modified),
 * purgeWrite, and SIGINT/SIGTERM stopping the run with a last snapshot.
 *
 * The loop (run.c) calls mf_run_between_steps after each accepted step and
 * mf_run_after_write after each snapshot. */
#include "mf_run_internal.h"

#include <math.h>
#include <signal.h>
#include <string.h>

#include "mf_error.h"

/* ---- signals ---------------------------------------------------------------
 * The one piece of process state outside the registry: a signal handler can
 * only reach a static of type volatile sig_atomic_t. */
static volatile sig_atomic_t received_signal;
static struct sigaction saved_int, saved_term;
static bool installed;

static void on_signal(int sig)
{
    received_signal = sig;
}

int mf_run_signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND; /* a second Ctrl-C kills, as without us */
    received_signal = 0;
    if (sigaction(SIGINT, &sa, &saved_int) != 0 || sigaction(SIGTERM, &sa, &saved_term) != 0)
        return MF_ERROR(MF_ERR_LIBRARY, "cannot install the SIGINT/SIGTERM handlers");
    installed = true;
    return 0;
}

void mf_run_signals_restore(void)
{
    if (!installed)
        return;
    sigaction(SIGINT, &saved_int, NULL);
    sigaction(SIGTERM, &saved_term, NULL);
    installed = false;
}

int mf_run_signal_received(void)
{
    return (int)received_signal;
}

static const char *signal_name(int sig)
{
    return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "a signal";
}

/* ---- stopAt ---------------------------------------------------------------- */
static const char *const stop_names[] = {"endTime", "writeNow", "noWriteNow", "nextWrite"};

int mf_stop_at_parse(const char *word, mf_stop_at *out)
{
    for (int k = 0; k < 4; k++)
        if (strcmp(word, stop_names[k]) == 0) {
            *out = (mf_stop_at)k;
            return 0;
        }
    return MF_ERROR(MF_ERR_INPUT, "stopAt '%s': expected endTime, writeNow, noWriteNow or nextWrite",
                    word);
}

const char *mf_stop_at_name(mf_stop_at s)
{
    return (unsigned)s < 4 ? stop_names[s] : "?";
}

/* ---- between steps -------------------------------------------------------- */
double mf_run_first_write(const mf_run *run)
{
    const double interval = run->ctl.write_interval;
    if (run->ctl.write_by_steps)
        return (double)(run->sim->step + (long)interval);
    return interval * (floor(run->sim->time / interval + 1e-9) + 1);
}

int mf_run_between_steps(mf_run *run, bool wrote, double *next_write, bool *stop, bool *write)
{
    mf_sim *sim = run->sim;
    *stop = *write = false;
    if (run->modified) {
        const double interval = run->ctl.write_interval;
        const bool by_steps = run->ctl.write_by_steps;
        /* One rank reads the changed controlDict and the others take what it
         * found, so that every rank stops and writes at the same step. */
        int rc = mf_parallel_is_root(sim->par) ? run->modified(run->modified_ctx, run) : 0;
        MF_CALL(mf_parallel_agree(sim->par, rc));
        if (sim->par) {
            struct {
                mf_run_control ctl;
                double end_time;
                int watching;
            } b = {run->ctl, sim->end_time, run->modified != NULL};
            mf_parallel_bcast(sim->par, &b, sizeof b, 0);
            run->ctl = b.ctl;
            sim->end_time = b.end_time;
            if (!b.watching)
                run->modified = NULL;
        }
        if (run->ctl.write_interval != interval || run->ctl.write_by_steps != by_steps)
            *next_write = mf_run_first_write(run);
        /* endTime moved to before now: the loop ends here, with this state. */
        if (!wrote && sim->time >= sim->end_time * (1 - 1e-12))
            *write = true;
    }
    /* mpirun passes a Ctrl-C to every rank, but not at the same step: the
     * first that sees it stops them all. */
    double seen = mf_run_signal_received();
    mf_parallel_max(sim->par, &seen, 1);
    const int sig = (int)seen;
    if (sig) {
        run->stop_signal = sig;
        snprintf(run->stop_reason, sizeof run->stop_reason, "stopped by signal %s",
                 signal_name(sig));
        *stop = true;
        *write = !wrote;
        return 0;
    }
    switch (run->ctl.stop_at) {
    case MF_STOP_END_TIME:
        break;
    case MF_STOP_WRITE_NOW:
    case MF_STOP_NO_WRITE_NOW:
        *stop = true;
        *write = *write || (run->ctl.stop_at == MF_STOP_WRITE_NOW && !wrote);
        break;
    case MF_STOP_NEXT_WRITE:
        *stop = wrote;
        break;
    }
    if (*stop)
        snprintf(run->stop_reason, sizeof run->stop_reason, "stopAt %s",
                 mf_stop_at_name(run->ctl.stop_at));
    return 0;
}

int mf_run_after_write(mf_run *run)
{
    if (run->ctl.purge_write > 0 && run->writer_ops && run->writer_ops->purge)
        MF_CALL(run->writer_ops->purge(run->writer->data, run->ctl.purge_write));
    return 0;
}
