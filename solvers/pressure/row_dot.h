/* row_dot.h: the sum over one sparse row, sum_k val[k] x[col[k]], with four
 * partial sums so that the additions do not wait for each other (a single
 * running sum makes each product wait for the previous addition: a sparse
 * row of 25 entries then costs 25 addition latencies). The order of the
 * additions differs from the plain loop's by rounding only. */
#ifndef MF_ROW_DOT_H
#define MF_ROW_DOT_H

#include <stddef.h>
#include <stdint.h>

static inline double mf_row_dot(const int32_t *restrict col, const double *restrict val,
                                size_t n, const double *restrict x)
{
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        s0 += val[k] * x[col[k]];
        s1 += val[k + 1] * x[col[k + 1]];
        s2 += val[k + 2] * x[col[k + 2]];
        s3 += val[k + 3] * x[col[k + 3]];
    }
    for (; k < n; k++)
        s0 += val[k] * x[col[k]];
    return (s0 + s1) + (s2 + s3);
}

#endif
