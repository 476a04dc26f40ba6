/* mf_error.h: status codes and the error trace (PETSc habit).
 *
 * Every function that can fail returns an int status:
 *   0   success;
 *   >0  recoverable (the caller may retry, e.g. a pressure solve that did not
 *       converge: cut dt and redo the step);
 *   <0  fatal (bad input, out of memory, I/O failure).
 * The first failure records a message; each level it passes through adds
 * its file, line and function. Nothing in the library calls exit().
 * The trace is thread-local, so OpenMP workers never share it.
 */
#ifndef MF_ERROR_H
#define MF_ERROR_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdarg.h>
#include <stdio.h>

enum {
    MF_OK = 0,
    MF_RETRY = 1,           /* recoverable: e.g. linear solve not converged */
    MF_ERR_INPUT = -1,      /* bad case file, bad option, bad parameter */
    MF_ERR_MEMORY = -2,     /* allocation failed or request too large */
    MF_ERR_IO = -3,         /* file could not be read or written */
    MF_ERR_NUMERIC = -4,    /* NaN, divergence, unphysical state */
    MF_ERR_LIBRARY = -5,    /* a dependency (hypre, HDF5, SUNDIALS, dlopen) failed */
    MF_ERR_INTERNAL = -6    /* a broken invariant: a bug in mpsflow */
};

/* Record a new error (clearing any earlier trace) and return code. */
int mf_error_raise(int code, const char *file, int line, const char *func,
                   const char *fmt, ...) __attribute__((format(printf, 5, 6)));
/* Add one frame (file, line, function) to the current trace; return code. */
int mf_error_trace(int code, const char *file, int line, const char *func);
/* The message of the first failure ("" when none). */
const char *mf_error_message(void);
/* Print message and trace to f, then clear them. */
void mf_error_print(FILE *f);
void mf_error_clear(void);
const char *mf_status_name(int code);

#define MF_ERROR(code, ...) mf_error_raise((code), __FILE__, __LINE__, __func__, __VA_ARGS__)

/* Call expr; on a non-zero status add this frame and return it. */
#define MF_CALL(expr)                                                        \
    do {                                                                     \
        int mf_call_rc_ = (expr);                                            \
        if (mf_call_rc_ != 0)                                                \
            return mf_error_trace(mf_call_rc_, __FILE__, __LINE__, __func__); \
    } while (0)

/* Same, but jump to a cleanup label with rc set. */
#define MF_CALL_GOTO(rc, expr, label)                                        \
    do {                                                                     \
        (rc) = (expr);                                                       \
        if ((rc) != 0) {                                                     \
            mf_error_trace((rc), __FILE__, __LINE__, __func__);              \
            goto label;                                                      \
        }                                                                    \
    } while (0)

#pragma GCC visibility pop
#endif
