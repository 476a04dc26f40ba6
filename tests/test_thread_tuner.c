/* test_thread_tuner.c: the team size chosen by measurement
 * (core/run/mf_thread_tuner.h), on made-up step times: the faster size is
 * kept, a tie keeps the full team, the choice is probed again after the
 * period and follows a change of load, and an off tuner never changes. */
#include "mf_test.h"
#include "mf_thread_tuner.h"

/* Run the tuner for `steps` steps whose time is ms_full with the full team
 * and ms_one with one thread; returns the size of the last step. */
static int run(mf_thread_tuner *t, long steps, double ms_full, double ms_one)
{
    for (long k = 0; k < steps; k++) {
        const double ms = t->current == 1 ? ms_one : ms_full;
        mf_thread_tuner_next(t, 1e-3 * ms, true);
    }
    return t->current;
}

int main(void)
{
    mf_thread_tuner t;
    /* One thread faster (a busy second core): chosen after both probes. */
    mf_thread_tuner_init(&t, true, 2);
    CHECK(t.on && t.current == 2);
    CHECK(run(&t, MF_TUNER_PROBE, 6.0, 5.5) == 1); /* the full team timed: probing one */
    CHECK(run(&t, MF_TUNER_PROBE, 6.0, 5.5) == 1); /* one thread was faster: kept */
    CHECK(t.probes == 1 && t.chose_one == 1);
    /* It stays for the period, then probes again; the load has gone. */
    CHECK(run(&t, MF_TUNER_PERIOD - 1, 6.0, 5.5) == 1);
    CHECK(run(&t, 1, 4.0, 5.5) == 2); /* the probe starts with the full team */
    CHECK(run(&t, 2 * MF_TUNER_PROBE, 4.0, 5.5) == 2);
    CHECK(t.probes == 2 && t.chose_one == 1);
    CHECK(t.steps_with[0] + t.steps_with[1] == 4 * MF_TUNER_PROBE + MF_TUNER_PERIOD);
    /* The median, not the mean: one slow step (a page-fault storm) in the
     * full team's probe does not decide. */
    mf_thread_tuner_init(&t, true, 2);
    for (int k = 0; k < MF_TUNER_PROBE; k++)
        mf_thread_tuner_next(&t, k == 2 ? 1.0 : 4e-3, true);
    CHECK(run(&t, MF_TUNER_PROBE, 4.0, 5.0) == 2);
    /* A tie keeps the full team; untimed steps are not counted. */
    mf_thread_tuner_init(&t, true, 4);
    for (int k = 0; k < 3; k++)
        mf_thread_tuner_next(&t, 100.0, false);
    CHECK(t.current == 4 && t.count == 0);
    CHECK(run(&t, 2 * MF_TUNER_PROBE, 5.0, 5.0) == 4);
    /* Off (OMP_NUM_THREADS set, or one thread): never changes. */
    mf_thread_tuner_init(&t, false, 2);
    CHECK(!t.on && run(&t, 1000, 9.0, 1.0) == 2);
    mf_thread_tuner_init(&t, true, 1);
    CHECK(!t.on && run(&t, 1000, 9.0, 1.0) == 1);
    return mf_test_summary("thread_tuner");
}
