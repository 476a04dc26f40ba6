/* error.c: the thread-local error trace behind mf_error.h. */
#include "mf_error.h"

#include <string.h>

#define MF_TRACE_DEPTH 32

static _Thread_local struct {
    char message[2048];
    int code;
    int depth;
    struct { const char *file, *func; int line; } frame[MF_TRACE_DEPTH];
} trace;

static void push_frame(const char *file, int line, const char *func)
{
    if (trace.depth < MF_TRACE_DEPTH) {
        trace.frame[trace.depth].file = file;
        trace.frame[trace.depth].line = line;
        trace.frame[trace.depth].func = func;
        trace.depth++;
    }
}

int mf_error_raise(int code, const char *file, int line, const char *func, const char *fmt, ...)
{
    /* Format aside first: callers may pass mf_error_message() itself to wrap
     * an earlier failure in context. */
    char message[sizeof trace.message];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    memcpy(trace.message, message, sizeof message);
    trace.code = code;
    trace.depth = 0;
    push_frame(file, line, func);
    return code;
}

int mf_error_trace(int code, const char *file, int line, const char *func)
{
    if (trace.code == 0 && trace.message[0] == '\0') {
        /* A status with no message (a bug, or a silent library): say so. */
        snprintf(trace.message, sizeof trace.message, "failed with status %d (%s)", code,
                 mf_status_name(code));
        trace.code = code;
    }
    push_frame(file, line, func);
    return code;
}

const char *mf_error_message(void) { return trace.message; }

void mf_error_clear(void)
{
    trace.message[0] = '\0';
    trace.code = 0;
    trace.depth = 0;
}

void mf_error_print(FILE *f)
{
    if (trace.message[0] == '\0' && trace.depth == 0)
        return;
    fprintf(f, "\n--> mpsflow FATAL ERROR: %s\n", trace.message);
    for (int k = 0; k < trace.depth; k++)
        fprintf(f, "    from %s() at %s:%d\n", trace.frame[k].func, trace.frame[k].file,
                trace.frame[k].line);
    fflush(f);
    mf_error_clear();
}

const char *mf_status_name(int code)
{
    switch (code) {
    case MF_OK: return "ok";
    case MF_RETRY: return "recoverable";
    case MF_ERR_INPUT: return "bad input";
    case MF_ERR_MEMORY: return "out of memory";
    case MF_ERR_IO: return "I/O error";
    case MF_ERR_NUMERIC: return "numerical failure";
    case MF_ERR_LIBRARY: return "library failure";
    case MF_ERR_INTERNAL: return "internal error";
    default: return code > 0 ? "recoverable" : "error";
    }
}
