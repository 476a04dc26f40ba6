/* row_dot.h: the sum over one sparse row, sum_k val[k] x[col[k]], with four
 * partial sums so that the additions do not wait for each other (a single
 * running sum makes each product wait for the previous addition: a sparse
 * row of 25 entries then costs 25 addition latencies). The order of the
 * additions differs from the plain loop's by rounding only.
 *
 * The partial sums go in pairs, (s0, s1) and (s2, s3), as the two lanes of a
 * 16-byte vector (GCC/clang vector extensions: SSE2 on x86-64, NEON on
 * AArch64, both baselines): each lane computes exactly the scalar s += v x
 * of its entries, so the sums are the four scalar ones bit for bit, in
 * fewer instructions (one load, multiply and add for two entries; issue
 * 12, docs/notes/speed.md). */
#ifndef MF_ROW_DOT_H
#define MF_ROW_DOT_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

typedef double mf_row_dot_v2 __attribute__((vector_size(2 * sizeof(double))));

static inline double mf_row_dot(const int32_t *restrict col, const double *restrict val,
                                size_t n, const double *restrict x)
{
    mf_row_dot_v2 s01 = {0.0, 0.0}, s23 = {0.0, 0.0};
    size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        mf_row_dot_v2 v01, v23;
        memcpy(&v01, val + k, sizeof v01);
        memcpy(&v23, val + k + 2, sizeof v23);
        const mf_row_dot_v2 x01 = {x[col[k]], x[col[k + 1]]};
        const mf_row_dot_v2 x23 = {x[col[k + 2]], x[col[k + 3]]};
        s01 += v01 * x01;
        s23 += v23 * x23;
    }
    double s0 = s01[0];
    for (; k < n; k++)
        s0 += val[k] * x[col[k]];
    return (s0 + s01[1]) + (s23[0] + s23[1]);
}

#endif
