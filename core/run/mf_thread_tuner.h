/* mf_thread_tuner.h: the OpenMP team size of a run, chosen by measurement
 * while it goes (core/run, internal).
 *
 * Why: with another process on the machine's second core, two threads make
 * a step slower than one (the 2-D bench case: 5.79 against 5.50 ms a step
 * with the passive wait policy, docs/validation-and-performance.md), on an
 * idle machine they make it faster; which holds changes as the machine's
 * load does. The results do not depend on the team size (the neighbour
 * lists are the same for any count, the loops' reductions are min, max and
 * integer sums), so the size may change between any two steps.
 *
 * The tuner runs `probe` steps with the full team, then `probe` with one
 * thread, keeps the size whose median step time is the lower, runs `period`
 * steps with it and probes again. Steps that write a snapshot are not
 * timed (their time is the disk's). Off when the user chose the team
 * (OMP_NUM_THREADS set), when one thread is all there is, and without
 * OpenMP. The decision logic is a pure function of the step times
 * (mf_thread_tuner_next), tested in tests/test_thread_tuner.c. */
#ifndef MF_THREAD_TUNER_H
#define MF_THREAD_TUNER_H

#include <stdbool.h>

enum { MF_TUNER_PROBE = 5, MF_TUNER_PERIOD = 200 };

typedef struct mf_thread_tuner {
    bool on;
    int full;                          /* the team OpenMP gives by default */
    int current;                       /* the size the next step runs with */
    int phase;                         /* 0: running the choice; 1: probing full; 2: probing one */
    int count;                         /* steps timed in this phase */
    long left;                         /* phase 0: steps until the next probe */
    double times[2][MF_TUNER_PROBE];   /* the probes' step times: full, one */
    long steps_with[2];                /* steps run with full and with one thread */
    int probes, chose_one;             /* probes made, and how many chose one thread */
} mf_thread_tuner;

/* Set up for a team of `full` threads (off: on = false, current = full). */
void mf_thread_tuner_init(mf_thread_tuner *t, bool on, int full);
/* A step ran with t->current threads in `seconds` (timed: false for a step
 * whose time says nothing, one that wrote a snapshot). Returns the team size
 * for the next step. */
int mf_thread_tuner_next(mf_thread_tuner *t, double seconds, bool timed);

/* The run's tuner from the environment: on unless OMP_NUM_THREADS is set
 * or OpenMP gives one thread; sets the team to t->current. */
void mf_thread_tuner_start(mf_thread_tuner *t);
/* Set the team to t->current (after mf_thread_tuner_next). */
void mf_thread_tuner_apply(const mf_thread_tuner *t);

#endif
