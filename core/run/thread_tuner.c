/* thread_tuner.c: the team size chosen by measurement (mf_thread_tuner.h). */
#include "mf_thread_tuner.h"

#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

void mf_thread_tuner_init(mf_thread_tuner *t, bool on, int full)
{
    memset(t, 0, sizeof *t);
    t->full = full > 1 ? full : 1;
    t->on = on && t->full > 1;
    t->current = t->full;
    t->phase = t->on ? 1 : 0; /* a run starts by probing */
}

static int by_value(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(const double *v, int n)
{
    double s[MF_TUNER_PROBE];
    memcpy(s, v, (size_t)n * sizeof *s);
    qsort(s, (size_t)n, sizeof *s, by_value);
    return n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
}

int mf_thread_tuner_next(mf_thread_tuner *t, double seconds, bool timed)
{
    t->steps_with[t->current == 1]++;
    if (!t->on)
        return t->current;
    if (t->phase == 0) {
        if (--t->left <= 0) {
            t->phase = 1;
            t->count = 0;
            t->current = t->full;
        }
        return t->current;
    }
    if (!timed)
        return t->current;
    t->times[t->phase - 1][t->count++] = seconds;
    if (t->count < MF_TUNER_PROBE)
        return t->current;
    if (t->phase == 1) { /* the full team timed: now one thread */
        t->phase = 2;
        t->count = 0;
        t->current = 1;
        return t->current;
    }
    /* Both timed: one thread only when it is faster (ties keep the team). */
    const bool one = median(t->times[1], MF_TUNER_PROBE) < median(t->times[0], MF_TUNER_PROBE);
    t->probes++;
    t->chose_one += one;
    t->current = one ? 1 : t->full;
    t->phase = 0;
    t->left = MF_TUNER_PERIOD;
    return t->current;
}

void mf_thread_tuner_start(mf_thread_tuner *t)
{
    int full = 1;
    const char *set = getenv("OMP_NUM_THREADS");
#ifdef _OPENMP
    full = omp_get_max_threads();
#endif
    mf_thread_tuner_init(t, !(set && *set), full);
    mf_thread_tuner_apply(t);
}

void mf_thread_tuner_apply(const mf_thread_tuner *t)
{
#ifdef _OPENMP
    if (t->on)
        omp_set_num_threads(t->current);
#else
    (void)t;
#endif
}
