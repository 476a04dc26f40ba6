/* mf_timetext.h: a simulation time as text for people and for viewers.
 *
 * A time reached by adding steps carries rounding noise
 * (0.060000000000000005, 1.9999999999999998); shown as is, ParaView treats
 * 1.9999999999999998 as before 2 and gives the frame of time 1 for t = 2.
 * Snapshot headers keep the exact double (a restart needs it); every text
 * that names a time (the XDMF indexes, listTimes, the log) uses this. */
#ifndef MF_TIMETEXT_H
#define MF_TIMETEXT_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stddef.h>

/* Relative difference below which two times are the same time. */
#define MF_TIME_TOLERANCE 1e-9

/* The shortest decimal (%.Ng, N = 1..17) within MF_TIME_TOLERANCE of t,
 * relative to |t| (absolute below 1e-300): 0.060000000000000005 -> "0.06",
 * 0.40317234 stays. Returns buf (at least 32 bytes). */
const char *mf_time_text(double t, char *buf, size_t len);

/* t rounded the same way, as a number. */
double mf_time_round(double t);

#pragma GCC visibility pop
#endif
