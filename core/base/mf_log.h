/* mf_log.h: the run log, in OpenFOAM's strings so existing log parsers work.
 * Levels: MF_LOG_QUIET (errors, End), MF_LOG_NORMAL (the per-step block),
 * MF_LOG_VERBOSE (details). On a terminal at normal level the per-step block
 * is replaced by one progress line with an ETA. */
#ifndef MF_LOG_H
#define MF_LOG_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stdio.h>

enum { MF_LOG_QUIET = 0, MF_LOG_NORMAL = 1, MF_LOG_VERBOSE = 2 };

typedef struct mf_log {
    FILE *out;
    int level;
    bool progress;  /* terminal: progress line instead of the per-step block */
    bool progress_shown;
} mf_log;

void mf_log_init(mf_log *log, FILE *out, int level);
/* Printed when level >= `level`. Per-step lines use MF_LOG_STEP, which is
 * suppressed while the progress line is in use. */
enum { MF_LOG_STEP = 3 };
void mf_log_printf(mf_log *log, int level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* One line "Time = t/end  [####......] 45%  ETA 1m12s" overwritten in place. */
void mf_log_progress(mf_log *log, double time, double end_time, double elapsed);
void mf_log_progress_end(mf_log *log);

#pragma GCC visibility pop
#endif
