/* fine_in_place.c: hypre's fine matrix for the AMG set-up of one rank made
 * in the caller's own arrays (mf_csr.lent_capacity), so that the set-up
 * does not hold the pressure matrix twice (ours and hypre's IJ copy: 20 MB
 * of the 3-D bench case's peak, docs/notes/speed.md, 2026-12-03).
 *
 * Slot space (hypre_common.c) is our rows spread out to their slots, an
 * identity row (the rows' mean diagonal, as assemble() puts there) in each
 * free slot, and the columns renamed to slots. When the slots grow with the
 * row (the MPS rows: particles in index order) and each row starts with its
 * diagonal (what hypre's ParCSR wants first in a row), that matrix is ours
 * with the rows moved right by the free slots before them: one backward
 * pass moves them and renames the columns, one forward pass after the
 * set-up puts them back. The values are never touched, and hypre reads the
 * rows in the order its IJ assembly would have given them (the diagonal,
 * then the others as we have them). */
#define MF_PRESSURE_HYPRE_INTERNAL
#include "pressure_hypre.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <_hypre_parcsr_mv.h>
#pragma GCC diagnostic pop

#include "mf_error.h"

/* Whether A can lend its arrays: slots increasing, each row's diagonal
 * first and only there, room for one entry a free slot. */
static bool can_lend(const mf_csr *A, const mf_row_names *rows)
{
    const size_t n = A->nrows;
    if (A->lent_capacity == 0 || n == 0 || A->row_offset != 0 || rows == NULL ||
        rows->nslots < (int64_t)n || rows->nslots > INT32_MAX)
        return false;
    const size_t k0 = A->rowptr[0], nnz = A->rowptr[n] - k0;
    const size_t nfree = (size_t)rows->nslots - n;
    if (k0 + nnz + nfree > A->lent_capacity || nnz + nfree > INT32_MAX)
        return false;
    for (size_t i = 0; i < n; i++) {
        if ((i > 0 && rows->slot[i] <= rows->slot[i - 1]) || A->rowptr[i + 1] <= A->rowptr[i] ||
            A->col[A->rowptr[i]] != (int32_t)i)
            return false;
        for (size_t k = A->rowptr[i] + 1; k < A->rowptr[i + 1]; k++)
            if (A->col[k] == (int32_t)i)
                return false;
    }
    return true;
}

/* Rows to slots, backward: row r's entries go to I[slot[r]], its columns
 * renamed; each free slot s gets (s, d). */
static void spread(const mf_csr *A, const mf_row_names *rows, const int32_t *row_of_slot,
                   double d, HYPRE_Int *I)
{
    const size_t k0 = A->rowptr[0];
    int32_t *col = A->col + k0;
    double *val = A->val + k0;
    const int64_t nslots = rows->nslots;
    size_t w = A->rowptr[A->nrows] - k0 + (size_t)nslots - A->nrows;
    I[nslots] = (HYPRE_Int)w;
    for (int64_t s = nslots - 1; s >= 0; s--) {
        const int32_t r = row_of_slot[s];
        if (r < 0) {
            w--;
            col[w] = (int32_t)s;
            val[w] = d;
        } else {
            const size_t src = A->rowptr[r] - k0, len = A->rowptr[r + 1] - A->rowptr[r];
            w -= len;
            memmove(col + w, col + src, len * sizeof *col);
            memmove(val + w, val + src, len * sizeof *val);
            for (size_t e = w; e < w + len; e++)
                col[e] = (int32_t)rows->slot[col[e]];
        }
        I[s] = (HYPRE_Int)w;
    }
}

/* Slots to rows, forward: spread's inverse (the free slots' entries are
 * dropped). */
static void gather(const mf_csr *A, const mf_row_names *rows, const int32_t *row_of_slot,
                   const HYPRE_Int *I)
{
    const size_t k0 = A->rowptr[0];
    int32_t *col = A->col + k0;
    double *val = A->val + k0;
    for (int64_t s = 0; s < rows->nslots; s++) {
        const int32_t r = row_of_slot[s];
        if (r < 0)
            continue;
        const size_t src = (size_t)I[s], dst = A->rowptr[r] - k0;
        const size_t len = A->rowptr[r + 1] - A->rowptr[r];
        for (size_t e = src; e < src + len; e++)
            col[e] = row_of_slot[col[e]];
        memmove(col + dst, col + src, len * sizeof *col);
        memmove(val + dst, val + src, len * sizeof *val);
    }
}

int mf_hypre_setup_in_place(const char *who, HYPRE_Solver amg, const mf_csr *A,
                            const mf_row_names *rows, bool *done)
{
    _Static_assert(sizeof(HYPRE_Int) == sizeof(int32_t) && sizeof(HYPRE_Real) == sizeof(double),
                   "hypre's fine matrix in our int32_t and double arrays");
    *done = false;
    if (!can_lend(A, rows))
        return 0;
    const size_t n = A->nrows;
    const int64_t nslots = rows->nslots;
    int32_t *row_of_slot = malloc((size_t)nslots * sizeof *row_of_slot);
    HYPRE_Int *I = malloc(((size_t)nslots + 1) * sizeof *I);
    if (row_of_slot == NULL || I == NULL) {
        free(row_of_slot);
        free(I);
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory (%lld slots)", who,
                        (long long)nslots);
    }
    for (int64_t s = 0; s < nslots; s++)
        row_of_slot[s] = -1;
    double dsum = 0; /* the free slots' diagonal: assemble()'s, summed in its order */
    for (size_t i = 0; i < n; i++) {
        row_of_slot[rows->slot[i]] = (int32_t)i;
        dsum += fabs(A->val[A->rowptr[i]]);
    }
    const double d = dsum > 0 ? dsum / (double)n : 1.0;
    const size_t k0 = A->rowptr[0];
    const HYPRE_Int nnz = (HYPRE_Int)(A->rowptr[n] - k0 + (size_t)nslots - n);

    HYPRE_BigInt starts[2] = {0, (HYPRE_BigInt)nslots};
    hypre_ParCSRMatrix *M = hypre_ParCSRMatrixCreate(MPI_COMM_WORLD, nslots, nslots, starts,
                                                     starts, 0, nnz, 0);
    HYPRE_ParVector b = NULL, x = NULL;
    int rc = 0;
    if (M == NULL) {
        rc = MF_ERROR(MF_ERR_LIBRARY, "%s: hypre_ParCSRMatrixCreate failed", who);
        goto out;
    }
    MF_HYPRE_CALL(who, rc, out, hypre_CSRMatrixInitialize, (hypre_ParCSRMatrixOffd(M)));
    MF_HYPRE_CALL(who, rc, out, HYPRE_ParVectorCreate, (MPI_COMM_WORLD, nslots, starts, &b));
    MF_HYPRE_CALL(who, rc, out, HYPRE_ParVectorInitialize, (b)); /* zeros */
    MF_HYPRE_CALL(who, rc, out, HYPRE_ParVectorCreate, (MPI_COMM_WORLD, nslots, starts, &x));
    MF_HYPRE_CALL(who, rc, out, HYPRE_ParVectorInitialize, (x));

    spread(A, rows, row_of_slot, d, I);
    hypre_CSRMatrix *D = hypre_ParCSRMatrixDiag(M);
    hypre_CSRMatrixI(D) = I;
    hypre_CSRMatrixJ(D) = A->col + k0;
    hypre_CSRMatrixData(D) = A->val + k0;
    hypre_CSRMatrixOwnsData(D) = 0;
    hypre_ParCSRMatrixSetNumNonzeros(M);
    HYPRE_Int ierr = HYPRE_BoomerAMGSetup(amg, (HYPRE_ParCSRMatrix)M, b, x);
    if (ierr != 0)
        rc = mf_hypre_error(who, "HYPRE_BoomerAMGSetup", ierr, __FILE__, __LINE__, __func__);
    else if (hypre_CSRMatrixI(D) != I || hypre_CSRMatrixJ(D) != A->col + k0 ||
             hypre_CSRMatrixData(D) != A->val + k0)
        rc = MF_ERROR(MF_ERR_INTERNAL, "%s: hypre replaced the arrays of the fine matrix", who);
    /* Ours again, whatever happened: hypre's matrix lets go of them first. */
    hypre_CSRMatrixI(D) = NULL;
    hypre_CSRMatrixJ(D) = NULL;
    hypre_CSRMatrixData(D) = NULL;
    gather(A, rows, row_of_slot, I);
    *done = rc == 0;
out:
    if (M)
        hypre_ParCSRMatrixDestroy(M);
    if (b)
        HYPRE_ParVectorDestroy(b);
    if (x)
        HYPRE_ParVectorDestroy(x);
    free(row_of_slot);
    free(I);
    return rc;
}
