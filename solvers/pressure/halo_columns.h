/* halo_columns.h: the halo of columns of a distributed CSR, for the
 * pressure solve on several MPI ranks (hypre_common.c, amg_vcycle_par.c).
 *
 * A rank's rows (mf_csr: global columns, the ranks' rows consecutive blocks
 * in rank order) read some rows of other ranks: the off-rank columns of its
 * local rows. Each rank lists them once each, ascending (so grouped by
 * owner), tells every owner how many it reads (MPI_Alltoall of the counts)
 * and which (MPI_Alltoallv of the global row numbers), once a solve; after
 * that an exchange moves exactly those values, O(halo) bytes a rank instead
 * of one value per global row (issue 14; docs/topics/parallel.md, "No
 * gathers of one value a global row"). What crosses the network is the
 * values only: the ranks that have nothing to say to each other send zero
 * counts, and the counts are one int a rank (O(nprocs), not O(nglobal)).
 *
 * Each non-zero's column is also given as an index into the rank's extended
 * vector [its rows | the halo] (ext), so that a product reads the same
 * values in the same order as one over a gathered vector: the results are
 * bit for bit those of the gathers this replaces.
 */
#ifndef MF_HALO_COLUMNS_H
#define MF_HALO_COLUMNS_H

#include <stddef.h>
#include <stdint.h>

#include "mf_modules.h"

typedef struct mf_halo_columns {
    int nprocs;
    size_t nrows;          /* this rank's rows */
    int32_t n;             /* other ranks' rows read, once each */
    int32_t *col;          /* their global row numbers, ascending */
    int32_t *ext;          /* each non-zero of the rows (k - rowptr[0]): its column
                              as an index into [rows (nrows) | halo (n)] */
    int *recv_counts, *recv_displs; /* per rank: its rows in col (nprocs each) */
    int32_t nsend;         /* values this rank sends an exchange */
    int32_t *send_rows;    /* the local rows the other ranks read, by rank */
    int *send_counts, *send_displs;
    double *send_d;        /* send buffers (nsend) */
    int *send_i;
    uint64_t bytes_received; /* from other ranks, by the build and the exchanges */
} mf_halo_columns;

/* Collective: the halo of A's rows; displs[p] the first global row of rank
 * p (nprocs entries, the last rank's rows ending at A->nglobal). The columns
 * must be inside [0, nglobal) (checked by the caller). Agreed over the ranks
 * (mf_hypre_agree): 0 everywhere, or an error everywhere. */
int mf_halo_columns_build(const char *who, const mf_csr *A, const int *displs, int nprocs,
                          mf_halo_columns *h);
void mf_halo_columns_free(mf_halo_columns *h);

/* Collective: halo[j] = the value its owner holds in local[] for row col[j]
 * (local: the owner's rows, in its row order). */
void mf_halo_columns_doubles(mf_halo_columns *h, const double *local, double *halo);
void mf_halo_columns_ints(mf_halo_columns *h, const int *local, int *halo);

#endif
