/* halo_columns.c: the other ranks' rows a rank's matrix rows read, and the
 * exchange of their values (halo_columns.h). */
#define MF_PRESSURE_HYPRE_INTERNAL
#include "halo_columns.h"

#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "mf_error.h"
#include "pressure_hypre.h"

void mf_halo_columns_free(mf_halo_columns *h)
{
    free(h->col);
    free(h->ext);
    free(h->recv_counts);
    free(h->recv_displs);
    free(h->send_rows);
    free(h->send_counts);
    free(h->send_displs);
    free(h->send_d);
    free(h->send_i);
    memset(h, 0, sizeof *h);
}

static int cmp_i32(const void *a, const void *b)
{
    const int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* Index of c in the ascending col[0, n) (it is there). */
static int32_t find(const int32_t *col, int32_t n, int32_t c)
{
    int32_t lo = 0, hi = n - 1;
    while (lo < hi) {
        const int32_t mid = lo + (hi - lo) / 2;
        if (col[mid] < c)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* The off-rank columns once each, ascending, and each non-zero's index
 * into [rows | halo]. */
static int list_columns(const char *who, const mf_csr *A, mf_halo_columns *h)
{
    const int64_t lo = A->row_offset, hi = A->row_offset + (int64_t)A->nrows;
    const size_t k0 = A->nrows > 0 ? A->rowptr[0] : 0;
    const size_t nnz = A->nrows > 0 ? A->rowptr[A->nrows] - k0 : 0;
    h->ext = malloc((nnz + 1) * sizeof *h->ext);
    if (h->ext == NULL)
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for the columns of %zu non-zeros", who,
                        nnz);
    size_t m = 0;
    for (size_t k = 0; k < nnz; k++) {
        const int64_t c = A->col[k0 + k];
        m += c < lo || c >= hi;
    }
    h->col = malloc((m + 1) * sizeof *h->col);
    if (h->col == NULL)
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for %zu off-rank columns", who, m);
    m = 0;
    for (size_t k = 0; k < nnz; k++) {
        const int32_t c = A->col[k0 + k];
        if (c < lo || c >= hi)
            h->col[m++] = c;
    }
    qsort(h->col, m, sizeof *h->col, cmp_i32);
    int32_t n = 0;
    for (size_t j = 0; j < m; j++)
        if (n == 0 || h->col[j] != h->col[n - 1])
            h->col[n++] = h->col[j];
    h->n = n;
    for (size_t k = 0; k < nnz; k++) {
        const int32_t c = A->col[k0 + k];
        h->ext[k] = c >= lo && c < hi ? (int32_t)(c - lo)
                                      : (int32_t)A->nrows + find(h->col, n, c);
    }
    return 0;
}

int mf_halo_columns_build(const char *who, const mf_csr *A, const int *displs, int nprocs,
                          mf_halo_columns *h)
{
    memset(h, 0, sizeof *h);
    h->nprocs = nprocs;
    h->nrows = A->nrows;
    int rc = 0;
    const size_t np = (size_t)nprocs;
    h->recv_counts = calloc(np, sizeof *h->recv_counts);
    h->recv_displs = calloc(np, sizeof *h->recv_displs);
    h->send_counts = calloc(np, sizeof *h->send_counts);
    h->send_displs = calloc(np, sizeof *h->send_displs);
    if (!h->recv_counts || !h->recv_displs || !h->send_counts || !h->send_displs)
        rc = MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for the halo's counts (%d ranks)", who,
                      nprocs);
    if (rc == 0)
        rc = list_columns(who, A, h);
    MF_CALL_GOTO(rc, mf_hypre_agree(who, rc), fail);

    /* The owner of each column: the ranks' blocks follow each other. */
    for (int32_t j = 0, p = 0; j < h->n; j++) {
        while (p + 1 < nprocs && h->col[j] >= displs[p + 1])
            p++;
        h->recv_counts[p]++;
    }
    for (int p = 1; p < nprocs; p++)
        h->recv_displs[p] = h->recv_displs[p - 1] + h->recv_counts[p - 1];
    MPI_Alltoall(h->recv_counts, 1, MPI_INT, h->send_counts, 1, MPI_INT, MPI_COMM_WORLD);
    int64_t nsend = 0;
    for (int p = 0; p < nprocs; p++) {
        h->send_displs[p] = (int)nsend;
        nsend += h->send_counts[p];
    }
    if (nsend > INT32_MAX)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: %lld values to send exceed an int", who,
                      (long long)nsend);
    if (rc == 0) {
        h->nsend = (int32_t)nsend;
        h->send_rows = malloc(((size_t)nsend + 1) * sizeof *h->send_rows);
        h->send_d = malloc(((size_t)nsend + 1) * sizeof *h->send_d);
        h->send_i = malloc(((size_t)nsend + 1) * sizeof *h->send_i);
        if (!h->send_rows || !h->send_d || !h->send_i)
            rc = MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for a halo of %lld values", who,
                          (long long)nsend);
    }
    MF_CALL_GOTO(rc, mf_hypre_agree(who, rc), fail);
    MPI_Alltoallv(h->col, h->recv_counts, h->recv_displs, MPI_INT32_T, h->send_rows,
                  h->send_counts, h->send_displs, MPI_INT32_T, MPI_COMM_WORLD);
    h->bytes_received = (uint64_t)(nprocs - 1) * sizeof(int) + (uint64_t)nsend * sizeof(int32_t);
    /* Global row numbers asked of this rank -> its local rows. */
    for (int32_t k = 0; k < h->nsend && rc == 0; k++) {
        const int64_t r = (int64_t)h->send_rows[k] - A->row_offset;
        if (r < 0 || r >= (int64_t)A->nrows)
            rc = MF_ERROR(MF_ERR_INTERNAL, "%s: row %d asked of the rank that owns [%lld, %lld)",
                          who, (int)h->send_rows[k], (long long)A->row_offset,
                          (long long)(A->row_offset + (int64_t)A->nrows));
        else
            h->send_rows[k] = (int32_t)r;
    }
    MF_CALL_GOTO(rc, mf_hypre_agree(who, rc), fail);
    return 0;
fail:
    mf_halo_columns_free(h);
    return rc;
}

/* halo[j] = local[col[j]'s row] for elements of `size` bytes: the owner
 * packs the rows asked of it into send (nsend elements), one MPI_Alltoallv. */
static void exchange(mf_halo_columns *h, const void *local, void *send, size_t size,
                     MPI_Datatype type, void *halo)
{
    const char *from = local;
    char *to = send;
    for (int32_t k = 0; k < h->nsend; k++)
        memcpy(to + (size_t)k * size, from + (size_t)h->send_rows[k] * size, size);
    MPI_Alltoallv(send, h->send_counts, h->send_displs, type, halo, h->recv_counts,
                  h->recv_displs, type, MPI_COMM_WORLD);
    h->bytes_received += (uint64_t)h->n * size;
}

void mf_halo_columns_doubles(mf_halo_columns *h, const double *local, double *halo)
{
    exchange(h, local, h->send_d, sizeof *local, MPI_DOUBLE, halo);
}

void mf_halo_columns_ints(mf_halo_columns *h, const int *local, int *halo)
{
    exchange(h, local, h->send_i, sizeof *local, MPI_INT, halo);
}
