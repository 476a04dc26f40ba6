/* log.c: the run log and the terminal progress line. */
#include "mf_log.h"

#include <stdarg.h>
#include <unistd.h>

void mf_log_init(mf_log *log, FILE *out, int level)
{
    log->out = out;
    log->level = level;
    log->progress = level == MF_LOG_NORMAL && isatty(fileno(out));
    log->progress_shown = false;
}

void mf_log_printf(mf_log *log, int level, const char *fmt, ...)
{
    if (!log || !log->out)
        return;
    if (level == MF_LOG_STEP) {
        if (log->progress || log->level < MF_LOG_NORMAL)
            return;
    } else if (log->level < level) {
        return;
    }
    if (log->progress_shown) { /* do not write over the progress line */
        fputc('\n', log->out);
        log->progress_shown = false;
    }
    va_list ap;
    va_start(ap, fmt);
    vfprintf(log->out, fmt, ap);
    va_end(ap);
}

void mf_log_progress(mf_log *log, double time, double end_time, double elapsed)
{
    if (!log->progress || !log->out)
        return;
    double frac = end_time > 0 ? time / end_time : 1.0;
    if (frac > 1) frac = 1;
    char bar[31];
    int filled = (int)(frac * 30);
    for (int k = 0; k < 30; k++)
        bar[k] = k < filled ? '#' : '.';
    bar[30] = '\0';
    double eta = frac > 0 ? elapsed * (1 - frac) / frac : 0;
    fprintf(log->out, "\rTime = %-12g [%s] %3.0f%%  ETA %dm%02ds ", time, bar, 100 * frac,
            (int)(eta / 60), (int)eta % 60);
    fflush(log->out);
    log->progress_shown = true;
}

void mf_log_progress_end(mf_log *log)
{
    if (log->progress_shown && log->out) {
        fputc('\n', log->out);
        log->progress_shown = false;
    }
}
