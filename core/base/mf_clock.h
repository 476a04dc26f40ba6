/* mf_clock.h: clocks for timers (wall and CPU seconds). */
#ifndef MF_CLOCK_H
#define MF_CLOCK_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

/* Seconds since an arbitrary origin (monotonic) and process CPU seconds. */
double mf_wall_seconds(void);
double mf_cpu_seconds(void);

#pragma GCC visibility pop
#endif
