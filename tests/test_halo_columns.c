/* test_halo_columns.c: the halo of columns of a distributed CSR
 * (solvers/pressure/halo_columns.h) against a brute force over the whole
 * matrix, which every rank builds from the same seed: the other ranks' rows
 * each rank's rows read, once each and ascending; each non-zero's index
 * into [rows | halo]; the values and ints an exchange brings (a function of
 * the global row, so a wrong row shows); the plan's totals over the ranks;
 * the bytes it counts. Uneven blocks, a rank with no rows (from 3 ranks),
 * columns repeated within a row and in any order, a block-diagonal matrix
 * (no halo at all). Meson runs it on 1, 3 and 4 ranks.
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "mf_test.h"
#define MF_PRESSURE_HYPRE_INTERNAL
#include "pressure/halo_columns.h"
#include "pressure/pressure_hypre.h"

static int rank = 0, nprocs = 1;

/* The same pseudo-random numbers on every rank (xorshift64). */
static uint64_t next(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

/* First global row of each rank: uneven, rank 1 empty from 3 ranks. */
static void blocks(int nglobal, int *displs)
{
    int weight_sum = 0;
    int *w = malloc((size_t)nprocs * sizeof *w);
    for (int p = 0; p < nprocs; p++) {
        w[p] = nprocs >= 3 && p == 1 ? 0 : p + 2;
        weight_sum += w[p];
    }
    int at = 0;
    for (int p = 0; p < nprocs; p++) {
        displs[p] = at;
        at += p + 1 < nprocs ? nglobal * w[p] / weight_sum : nglobal - at;
    }
    displs[nprocs] = nglobal;
    free(w);
}

/* The whole matrix's pattern (values unused): row g has its diagonal and
 * up to 6 more columns, some repeated; block_diag keeps every column in
 * the row's own block. */
typedef struct pattern {
    int n;
    size_t *ptr;
    int32_t *col;
} pattern;

static void make_pattern(pattern *P, int n, const int *displs, bool block_diag, uint64_t seed)
{
    P->n = n;
    P->ptr = malloc(((size_t)n + 1) * sizeof *P->ptr);
    P->col = malloc(((size_t)n * 8 + 1) * sizeof *P->col);
    size_t k = 0;
    for (int g = 0; g < n; g++) {
        P->ptr[g] = k;
        int p = 0;
        while (displs[p + 1] <= g)
            p++;
        const int lo = displs[p], hi = displs[p + 1];
        const int extra = (int)(next(&seed) % 7);
        P->col[k++] = g;
        for (int e = 0; e < extra; e++) {
            int c;
            if (block_diag)
                c = lo + (int)(next(&seed) % (uint64_t)(hi - lo));
            else if (next(&seed) % 3 == 0)
                c = (int)(next(&seed) % (uint64_t)n); /* anywhere */
            else /* near: across a block boundary now and then */
                c = ((g + (int)(next(&seed) % 21) - 10) % n + n) % n;
            P->col[k++] = c;
            if (next(&seed) % 5 == 0)
                P->col[k++] = c; /* repeated */
        }
    }
    P->ptr[n] = k;
}

static double value_of(int g)
{
    return 0.5 + 1.25 * g;
}

static void check_halo(int n, bool block_diag, uint64_t seed)
{
    int *displs = malloc(((size_t)nprocs + 1) * sizeof *displs);
    blocks(n, displs);
    pattern P;
    make_pattern(&P, n, displs, block_diag, seed);
    const int lo = displs[rank], hi = displs[rank + 1], nrows = hi - lo;

    /* This rank's rows, the row pointers offset as a caller's may be. */
    const size_t shift = 3;
    mf_csr A = {0};
    A.nrows = (size_t)nrows;
    A.row_offset = lo;
    A.nglobal = n;
    A.rowptr = malloc(((size_t)nrows + 1) * sizeof *A.rowptr);
    const size_t nnz = P.ptr[hi] - P.ptr[lo];
    A.col = malloc((nnz + shift + 1) * sizeof *A.col);
    A.val = calloc(nnz + shift + 1, sizeof *A.val);
    for (int r = 0; r <= nrows; r++)
        A.rowptr[r] = P.ptr[lo + r] - P.ptr[lo] + shift;
    memcpy(A.col + shift, P.col + P.ptr[lo], nnz * sizeof *A.col);

    mf_halo_columns h;
    const int rc = mf_halo_columns_build("test", &A, displs, nprocs, &h);
    CHECK_OK(rc);
    if (rc != 0) {
        fprintf(stderr, "rank %d: n %d, block_diag %d: no halo\n", rank, n, (int)block_diag);
        goto out;
    }

    /* Brute force: the other ranks' rows read, ascending. */
    bool *read = calloc((size_t)n + 1, 1);
    for (size_t k = P.ptr[lo]; k < P.ptr[hi]; k++)
        if (P.col[k] < lo || P.col[k] >= hi)
            read[P.col[k]] = true;
    int expect = 0;
    for (int g = 0; g < n; g++)
        expect += read[g];
    CHECK_MSG(h.n == expect, "rank %d: halo of %d rows, brute force %d", rank, (int)h.n, expect);
    if (block_diag || nprocs == 1)
        CHECK(h.n == 0);
    bool listed_ok = true;
    for (int32_t j = 0; j < h.n && h.n == expect; j++)
        listed_ok = listed_ok && read[h.col[j]] && (j == 0 || h.col[j] > h.col[j - 1]);
    CHECK_MSG(listed_ok, "rank %d: the halo is not the rows read, once each, ascending", rank);

    /* Each non-zero's place in [rows | halo]. */
    bool ext_ok = true;
    for (size_t k = 0; k < nnz; k++) {
        const int32_t c = A.col[shift + k], e = h.ext[k];
        if (c >= lo && c < hi)
            ext_ok = ext_ok && e == c - lo;
        else
            ext_ok = ext_ok && e >= nrows && e < nrows + h.n && h.col[e - nrows] == c;
    }
    CHECK_MSG(ext_ok, "rank %d: a non-zero's index into [rows | halo] is wrong", rank);

    /* The plan: every value asked for is sent once, from a row of the rank. */
    int sent = h.nsend, asked = h.n, sent_all = 0, asked_all = 0;
    MPI_Allreduce(&sent, &sent_all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    MPI_Allreduce(&asked, &asked_all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    CHECK(sent_all == asked_all);
    bool rows_ok = true;
    for (int32_t k = 0; k < h.nsend; k++)
        rows_ok = rows_ok && h.send_rows[k] >= 0 && h.send_rows[k] < nrows;
    CHECK(rows_ok);

    /* The exchanges bring the owners' values of exactly those rows. */
    double *xl = malloc(((size_t)nrows + 1) * sizeof *xl), *xh = malloc(((size_t)h.n + 1) * sizeof *xh);
    int *il = malloc(((size_t)nrows + 1) * sizeof *il), *ih = malloc(((size_t)h.n + 1) * sizeof *ih);
    for (int r = 0; r < nrows; r++) {
        xl[r] = value_of(lo + r);
        il[r] = 7 * (lo + r) + 3;
    }
    const uint64_t before = h.bytes_received;
    CHECK(before == (uint64_t)(nprocs - 1) * sizeof(int) + (uint64_t)h.nsend * sizeof(int32_t));
    mf_halo_columns_doubles(&h, xl, xh);
    mf_halo_columns_ints(&h, il, ih);
    bool values_ok = true;
    for (int32_t j = 0; j < h.n; j++)
        values_ok = values_ok && xh[j] == value_of(h.col[j]) && ih[j] == 7 * h.col[j] + 3;
    CHECK_MSG(values_ok, "rank %d: an exchange brought another row's value", rank);
    CHECK(h.bytes_received == before + (uint64_t)h.n * (sizeof(double) + sizeof(int)));

    /* A product through ext reads what a gathered vector would give. */
    bool product_ok = true;
    for (int r = 0; r < nrows; r++) {
        double a = 0.0, b = 0.0;
        for (size_t k = A.rowptr[r]; k < A.rowptr[r + 1]; k++) {
            const int32_t e = h.ext[k - A.rowptr[0]];
            a += e < nrows ? xl[e] : xh[e - nrows];
            b += value_of(A.col[k]);
        }
        product_ok = product_ok && a == b;
    }
    CHECK(product_ok);

    mf_halo_columns_free(&h);
    CHECK(h.col == NULL && h.ext == NULL && h.n == 0);
    mf_halo_columns_free(&h); /* twice is harmless */
    free(xl);
    free(xh);
    free(il);
    free(ih);
    free(read);
out:
    free(A.rowptr);
    free(A.col);
    free(A.val);
    free(P.ptr);
    free(P.col);
    free(displs);
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &nprocs);

    check_halo(1000, false, 0x9e3779b97f4a7c15ull);
    check_halo(97, false, 12345);
    check_halo(500, true, 777);
    check_halo(nprocs + 1, false, 31); /* about a row a rank */

    int status = mf_test_summary("halo_columns");
    int any = status != EXIT_SUCCESS, all = 0;
    MPI_Allreduce(&any, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    MPI_Finalize();
    return all ? EXIT_FAILURE : EXIT_SUCCESS;
}
