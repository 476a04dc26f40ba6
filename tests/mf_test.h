/* mf_test.h: the few checks our tests need. Each test is an executable run
 * by `meson test`; it prints each failed check with file and line, a summary
 * line, and exits non-zero if anything failed. */
#ifndef MF_TEST_H
#define MF_TEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "mf_error.h"

static int mf_test_failures = 0;
static int mf_test_checks = 0;

#define CHECK(cond)                                                                 \
    do {                                                                            \
        mf_test_checks++;                                                           \
        if (!(cond)) {                                                              \
            mf_test_failures++;                                                     \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
        }                                                                           \
    } while (0)

#define CHECK_MSG(cond, ...)                                                        \
    do {                                                                            \
        mf_test_checks++;                                                           \
        if (!(cond)) {                                                              \
            mf_test_failures++;                                                     \
            fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                           \
            fputc('\n', stderr);                                                    \
        }                                                                           \
    } while (0)

/* |a - b| <= tol, printing both values when it fails. */
#define CHECK_NEAR(a, b, tol)                                                       \
    do {                                                                            \
        double mf_a_ = (a), mf_b_ = (b), mf_t_ = (tol);                             \
        mf_test_checks++;                                                           \
        if (!(fabs(mf_a_ - mf_b_) <= mf_t_)) {                                      \
            mf_test_failures++;                                                     \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.12g, %s = %.12g, tol %.3g\n", \
                    __FILE__, __LINE__, #a, mf_a_, #b, mf_b_, mf_t_);               \
        }                                                                           \
    } while (0)

/* A call that must succeed; prints the error trace if it does not. */
#define CHECK_OK(expr)                                                              \
    do {                                                                            \
        int mf_rc_ = (expr);                                                        \
        mf_test_checks++;                                                           \
        if (mf_rc_ != 0) {                                                          \
            mf_test_failures++;                                                     \
            fprintf(stderr, "%s:%d: %s returned %d\n", __FILE__, __LINE__, #expr, mf_rc_); \
            mf_error_print(stderr);                                                 \
        }                                                                           \
    } while (0)

static inline int mf_test_summary(const char *name)
{
    printf("%s: %d checks, %d failed\n", name, mf_test_checks, mf_test_failures);
    return mf_test_failures ? EXIT_FAILURE : EXIT_SUCCESS;
}

#endif
