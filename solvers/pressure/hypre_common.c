/* hypre_common.c: what PCG_BoomerAMG and PCG_diagonal share: checks of the
 * system, residual norms from the caller's CSR, assembly of the hypre IJ
 * objects, the PCG run and the report. The modules only choose the
 * preconditioner (see mf_hypre_pcg in pressure_hypre.h).
 *
 * Collective calls (MPI_Allreduce, hypre assembly, the solve) are made by
 * every rank in the same order; a failure found on one rank alone is first
 * agreed on (mf_hypre_agree) so that the others do not wait for it.
 */
#define MF_PRESSURE_HYPRE_INTERNAL
#include "pressure_hypre.h"

#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "amg_vcycle.h"
#include "halo_columns.h"
#include "mf_error.h"
#include "mf_hash.h"
#include "row_dot.h"

/* Largest values hypre's index types hold in this build (Debian's 2.26:
 * both 32-bit). */
#define HYPRE_BIGINT_MAX (sizeof(HYPRE_BigInt) == 8 ? (int64_t)INT64_MAX : (int64_t)INT32_MAX)
#define HYPRE_INT_MAX (sizeof(HYPRE_Int) == 8 ? (int64_t)INT64_MAX : (int64_t)INT32_MAX)

/* ---- errors and agreement ---------------------------------------------- */

int mf_hypre_error(const char *who, const char *hypre_func, HYPRE_Int code, const char *file,
                   int line, const char *func)
{
    char descr[512] = "";
    HYPRE_DescribeError(code, descr);
    HYPRE_ClearAllErrors();
    return mf_error_raise(MF_ERR_LIBRARY, file, line, func, "%s: %s failed (hypre error %d: %s)",
                          who, hypre_func, (int)code, descr);
}

int mf_hypre_agree(const char *who, int rc)
{
    int mine = rc != 0, any = 0;
    MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (rc != 0)
        return rc;
    if (any)
        return MF_ERROR(MF_ERR_INPUT, "%s: another MPI rank failed (see its message)", who);
    return 0;
}

bool mf_hypre_all(bool local)
{
    int nprocs = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
    if (nprocs == 1)
        return local;
    int mine = local, all = 0;
    MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return all != 0;
}

int mf_hypre_check_pcg_settings(const char *who, double tolerance, long max_iter)
{
    if (!(tolerance > 0.0 && tolerance <= 1.0))
        return MF_ERROR(MF_ERR_INPUT, "%s: tolerance %g is not in (0, 1]", who, tolerance);
    if (max_iter < 1 || max_iter > HYPRE_INT_MAX)
        return MF_ERROR(MF_ERR_INPUT, "%s: maxIter %ld is not in [1, %" PRId64 "]", who, max_iter,
                        HYPRE_INT_MAX);
    return 0;
}

/* ---- the row layout over the ranks --------------------------------------- */

typedef struct layout {
    int nprocs;
    int *displs; /* first global row of each rank (only when nprocs > 1) */
} layout;

static void layout_free(layout *lay)
{
    free(lay->displs);
    lay->displs = NULL;
}

/* Is every column in [0, nglobal)? Four at a time (GCC/clang vector
 * extensions, SSE2 or NEON), the outcomes or-ed without a branch: about two
 * instructions a column where the loop that names a bad one takes five. */
typedef int32_t col_v4 __attribute__((vector_size(4 * sizeof(int32_t))));

static bool columns_in_range(const int32_t *col, size_t n, int64_t nglobal)
{
    if (nglobal <= 0)
        return n == 0;
    const int32_t last = nglobal - 1 > INT32_MAX ? INT32_MAX : (int32_t)(nglobal - 1);
    const col_v4 zero = {0, 0, 0, 0}, top = {last, last, last, last};
    col_v4 bad = zero;
    size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        col_v4 c;
        memcpy(&c, col + k, sizeof c);
        bad |= (c < zero) | (c > top);
    }
    int32_t any = bad[0] | bad[1] | bad[2] | bad[3];
    for (; k < n; k++)
        any |= col[k] < 0 || col[k] > last;
    return any == 0;
}

/* Local checks of this rank's part: sizes that fit hypre's index types, a
 * monotone rowptr, columns inside the matrix. */
static int check_local(const char *who, const mf_csr *A, const double *b, const double *x)
{
    if (A == NULL)
        return MF_ERROR(MF_ERR_INPUT, "%s: no matrix", who);
    if (A->nglobal < 0 || A->row_offset < 0 || (uint64_t)A->nrows > (uint64_t)INT64_MAX ||
        A->row_offset > A->nglobal - (int64_t)A->nrows)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: local rows [%" PRId64 ", %" PRId64 ") are not inside the %" PRId64
                        " rows of the matrix",
                        who, A->row_offset, A->row_offset + (int64_t)A->nrows, A->nglobal);
    if (A->nglobal > HYPRE_BIGINT_MAX)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: the matrix has %" PRId64 " rows but this hypre build's HYPRE_BigInt "
                        "holds at most %" PRId64 " (rebuild hypre with --enable-bigint)",
                        who, A->nglobal, HYPRE_BIGINT_MAX);
    if ((int64_t)A->nrows > HYPRE_INT_MAX)
        return MF_ERROR(MF_ERR_INPUT, "%s: %zu local rows exceed hypre's HYPRE_Int", who,
                        A->nrows);
    if (A->nrows == 0)
        return 0;
    if (A->rowptr == NULL || b == NULL || x == NULL)
        return MF_ERROR(MF_ERR_INPUT, "%s: NULL rowptr, right-hand side or solution", who);
    for (size_t i = 0; i < A->nrows; i++)
        if (A->rowptr[i + 1] < A->rowptr[i])
            return MF_ERROR(MF_ERR_INPUT, "%s: rowptr decreases at local row %zu", who, i);
    size_t nnz = A->rowptr[A->nrows] - A->rowptr[0];
    if ((uint64_t)nnz > (uint64_t)HYPRE_INT_MAX)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: %zu local non-zeros exceed hypre's HYPRE_Int (use more ranks)", who,
                        nnz);
    if (nnz > 0 && (A->col == NULL || A->val == NULL))
        return MF_ERROR(MF_ERR_INPUT, "%s: NULL column or value array", who);
    if (columns_in_range(A->col + A->rowptr[0], nnz, A->nglobal))
        return 0;
    for (size_t k = A->rowptr[0]; k < A->rowptr[A->nrows]; k++) /* the first one, named */
        if (A->col[k] < 0 || A->col[k] >= A->nglobal) {
            size_t i = 0;
            while (A->rowptr[i + 1] <= k)
                i++;
            return MF_ERROR(MF_ERR_INPUT,
                            "%s: column %" PRId64 " in row %" PRId64 " is outside [0, %" PRId64
                            ") (it must also fit HYPRE_BigInt)",
                            who, (int64_t)A->col[k], A->row_offset + (int64_t)i, A->nglobal);
        }
    return 0;
}

/* Collective: check every rank's part, then that the ranks' row ranges
 * follow each other in rank order and cover [0, nglobal) (hypre's IJ layout). */
static int check_system(const char *who, const mf_csr *A, const double *b, const double *x,
                        layout *lay)
{
    memset(lay, 0, sizeof *lay);
    MF_CALL(mf_hypre_agree(who, check_local(who, A, b, x)));
    MPI_Comm_size(MPI_COMM_WORLD, &lay->nprocs);
    if (lay->nprocs == 1) {
        if (A->row_offset != 0 || (int64_t)A->nrows != A->nglobal)
            return MF_ERROR(MF_ERR_INPUT,
                            "%s: a single rank must own all %" PRId64 " rows (it owns [%" PRId64
                            ", %" PRId64 "))",
                            who, A->nglobal, A->row_offset, A->row_offset + (int64_t)A->nrows);
        return 0;
    }
    /* Several ranks: MPI counts and offsets (the layout, the halo of
     * columns) are ints, so the rows must fit one too. */
    int rc = 0;
    int64_t mine[3] = {A->row_offset, (int64_t)A->nrows, A->nglobal};
    int64_t *all = malloc(3 * (size_t)lay->nprocs * sizeof *all);
    lay->displs = malloc((size_t)lay->nprocs * sizeof *lay->displs);
    if (all == NULL || lay->displs == NULL)
        rc = MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for the row layout", who);
    MF_CALL_GOTO(rc, mf_hypre_agree(who, rc), fail);
    MPI_Allgather(mine, 3, MPI_INT64_T, all, 3, MPI_INT64_T, MPI_COMM_WORLD);
    int64_t next = 0;
    for (int p = 0; p < lay->nprocs; p++) {
        const int64_t *r = all + 3 * p;
        if (r[0] != next || r[2] != A->nglobal || A->nglobal > INT_MAX) {
            rc = MF_ERROR(MF_ERR_INPUT,
                          "%s: rank %d owns rows [%" PRId64 ", %" PRId64 ") of %" PRId64
                          "; ranks must own consecutive ranges in rank order starting at 0 "
                          "(and at most %d rows in all)",
                          who, p, r[0], r[0] + r[1], r[2], INT_MAX);
            goto fail;
        }
        lay->displs[p] = (int)r[0];
        next = r[0] + r[1];
    }
    if (next != A->nglobal) {
        rc = MF_ERROR(MF_ERR_INPUT, "%s: the ranks own %" PRId64 " of the %" PRId64 " rows", who,
                      next, A->nglobal);
        goto fail;
    }
    free(all);
    return 0;
fail:
    free(all);
    layout_free(lay);
    return rc;
}

/* ---- norms from the caller's CSR ----------------------------------------- */

static double global_sum(double local)
{
    double sum = 0.0;
    MPI_Allreduce(&local, &sum, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    return sum;
}

/* ||b - A x|| over all ranks, from the caller's CSR (independent of the hypre
 * copy, so a wrong assembly would show here). On several ranks the columns
 * of other ranks need their x: the halo of columns brings exactly those
 * (halo_columns.h), into xe = [x | halo], which each non-zero reads through
 * its ext index: the same values in the same order as a gathered x. */
static int residual_norm(const char *who, const mf_csr *A, const double *b, const double *x,
                         mf_halo_columns *halo, double *norm)
{
    const double *xe = x;
    const int32_t *ext = NULL;
    double *buf = NULL;
    int rc = 0;
    if (halo != NULL) {
        buf = malloc((A->nrows + (size_t)halo->n + 1) * sizeof *buf);
        if (buf == NULL)
            rc = MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for x and its halo (%zu + %d rows)",
                          who, A->nrows, (int)halo->n);
        rc = mf_hypre_agree(who, rc);
        if (rc != 0) {
            free(buf);
            return mf_error_trace(rc, __FILE__, __LINE__, __func__);
        }
        if (A->nrows > 0)
            memcpy(buf, x, A->nrows * sizeof *buf);
        mf_halo_columns_doubles(halo, x, buf + A->nrows);
        xe = buf;
        ext = halo->ext;
    }
    const size_t k0 = A->nrows > 0 ? A->rowptr[0] : 0;
    const int64_t shift = A->row_offset; /* one rank: global column -> row */
    double sum = 0.0;
    for (size_t i = 0; i < A->nrows; i++) {
        double r = b[i];
        if (ext != NULL)
            for (size_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
                r -= A->val[k] * xe[ext[k - k0]];
        else
            for (size_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
                r -= A->val[k] * xe[A->col[k] - shift];
        sum += r * r;
    }
    free(buf);
    *norm = sqrt(global_sum(sum));
    return 0;
}

/* One rank: r = b - A x from the caller's CSR; returns ||r||. */
typedef struct local_system {
    const mf_csr *A;
    const double *b;
} local_system;

static double residual_local(const void *ctx, const double *x, double *r)
{
    const local_system *sys = ctx;
    const mf_csr *A = sys->A;
    double sum = 0.0;
    for (size_t i = 0; i < A->nrows; i++) {
        const size_t k = A->rowptr[i];
        r[i] = sys->b[i] - mf_row_dot(A->col + k, A->val + k, A->rowptr[i + 1] - k, x);
        sum += r[i] * r[i];
    }
    return sqrt(sum);
}

/* ---- slot space over the ranks ------------------------------------------- */

/* Where hypre's rows are when the caller names them (mf_row_names): rank p's
 * slots are hypre's rows [first_p, first_p + nslots_p), first_p the sum of
 * the slots of the ranks before it, so each rank's hypre rows stay its own
 * and keep their meaning while its particles do (a kept hierarchy's
 * partition is then still the matrix's). A column names a global row, which
 * may be another rank's: on several ranks its owner sends the global slot of
 * each of its rows this rank reads, once a solve, through the halo of
 * columns (halo_slot; halo_columns.h: O(halo) a rank, not O(nglobal)). */
typedef struct slot_space {
    const mf_row_names *rows;      /* NULL: row space */
    int64_t first;                 /* this rank's first hypre row (0 on one rank) */
    int64_t total;                 /* slots of all ranks */
    const mf_halo_columns *halo;   /* several ranks: the other ranks' rows read */
    int *halo_slot;                /* several ranks: hypre row of each of them */
} slot_space;

static void slot_space_free(slot_space *ss)
{
    free(ss->halo_slot);
    memset(ss, 0, sizeof *ss);
}

/* The hypre row of the column of A's non-zero k. */
static HYPRE_BigInt slot_of_column(const slot_space *ss, const mf_csr *A, size_t k)
{
    if (ss->halo) {
        const int32_t e = ss->halo->ext[k - A->rowptr[0]];
        if (e >= (int32_t)A->nrows)
            return (HYPRE_BigInt)ss->halo_slot[e - (int32_t)A->nrows];
        return (HYPRE_BigInt)(ss->first + ss->rows->slot[e]);
    }
    return (HYPRE_BigInt)(ss->first + ss->rows->slot[A->col[k] - A->row_offset]);
}

/* This rank's check of the names: one per row, distinct, in [0, nslots). */
static int check_names(const char *who, const mf_csr *A, const mf_row_names *rows)
{
    if (rows->nslots < (int64_t)A->nrows || rows->nslots > HYPRE_INT_MAX ||
        (A->nrows > 0 && rows->slot == NULL))
        return MF_ERROR(MF_ERR_INPUT, "%s: %" PRId64 " slots for %zu rows", who, rows->nslots,
                        A->nrows);
    uint8_t *used = calloc((size_t)rows->nslots + 1, 1);
    if (used == NULL)
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory (%" PRId64 " slots)", who,
                        rows->nslots);
    int rc = 0;
    for (size_t i = 0; i < A->nrows && rc == 0; i++) {
        const int64_t s = rows->slot[i];
        if (s < 0 || s >= rows->nslots || used[s])
            rc = MF_ERROR(MF_ERR_INPUT, "%s: row %zu names slot %" PRId64 ", %s", who, i, s,
                          s < 0 || s >= rows->nslots ? "outside [0, nslots)"
                                                     : "named by another row too");
        else
            used[s] = 1;
    }
    free(used);
    return rc;
}

/* Collective: the slot space of this solve (rows NULL: row space); halo:
 * the solve's halo of columns on several ranks. */
static int slot_space_build(const char *who, const mf_csr *A, const mf_row_names *rows,
                            const layout *lay, mf_halo_columns *halo, slot_space *ss)
{
    memset(ss, 0, sizeof *ss);
    ss->rows = rows;
    if (rows == NULL)
        return 0;
    MF_CALL(mf_hypre_agree(who, check_names(who, A, rows)));
    ss->total = rows->nslots;
    if (lay->nprocs == 1)
        return 0;
    int rc = 0;
    int64_t *nslots = malloc((size_t)lay->nprocs * sizeof *nslots);
    int *mine = malloc((A->nrows + 1) * sizeof *mine);
    ss->halo = halo;
    ss->halo_slot = malloc(((size_t)halo->n + 1) * sizeof *ss->halo_slot);
    if (nslots == NULL || mine == NULL || ss->halo_slot == NULL)
        rc = MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for the slots of %zu rows and %d more",
                      who, A->nrows, (int)halo->n);
    MF_CALL_GOTO(rc, mf_hypre_agree(who, rc), fail);
    MPI_Allgather(&rows->nslots, 1, MPI_INT64_T, nslots, 1, MPI_INT64_T, MPI_COMM_WORLD);
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    ss->total = 0;
    for (int p = 0; p < lay->nprocs; p++) {
        if (p == rank)
            ss->first = ss->total;
        ss->total += nslots[p];
    }
    /* Every rank computed the same total: the same decision everywhere. */
    if (ss->total > HYPRE_BIGINT_MAX || ss->total > INT_MAX) {
        rc = MF_ERROR(MF_ERR_INPUT, "%s: %" PRId64 " slots over the ranks exceed hypre's index",
                      who, ss->total);
        goto fail;
    }
    for (size_t i = 0; i < A->nrows; i++)
        mine[i] = (int)(ss->first + rows->slot[i]);
    mf_halo_columns_ints(halo, mine, ss->halo_slot);
    free(nslots);
    free(mine);
    return 0;
fail:
    free(nslots);
    free(mine);
    slot_space_free(ss);
    return rc;
}

/* ---- assembly ------------------------------------------------------------ */

typedef struct hypre_system {
    HYPRE_IJMatrix A;
    HYPRE_IJVector b, x;
    HYPRE_ParCSRMatrix parA;
    HYPRE_ParVector parb, parx;
    HYPRE_BigInt *rows; /* global index of each local row */
} hypre_system;

static void system_free(hypre_system *sys)
{
    if (sys->A)
        HYPRE_IJMatrixDestroy(sys->A);
    if (sys->b)
        HYPRE_IJVectorDestroy(sys->b);
    if (sys->x)
        HYPRE_IJVectorDestroy(sys->x);
    free(sys->rows);
    memset(sys, 0, sizeof *sys);
}

static int assemble_vector(const char *who, HYPRE_BigInt ilower, HYPRE_BigInt iupper,
                           HYPRE_Int n, const HYPRE_BigInt *rows, const double *values,
                           HYPRE_IJVector *ij, HYPRE_ParVector *par)
{
    int rc = 0;
    void *obj = NULL;
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJVectorCreate, (MPI_COMM_WORLD, ilower, iupper, ij));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJVectorSetObjectType, (*ij, HYPRE_PARCSR));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJVectorSetPrintLevel, (*ij, 0));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJVectorInitialize, (*ij));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJVectorSetValues, (*ij, n, rows, values));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJVectorAssemble, (*ij));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJVectorGetObject, (*ij, &obj));
    *par = (HYPRE_ParVector)obj;
out:
    return rc;
}

/* Copy the CSR, b and x into hypre IJ objects. The matrix goes in with ONE
 * HYPRE_IJMatrixSetValues call for all local rows, after telling hypre the
 * exact diagonal-block / off-diagonal-block counts of every row, so it
 * allocates once and never needs its auxiliary (row-by-row) structure.
 *
 * With names (slot space, ss->rows; checked by slot_space_build): hypre's
 * row first + slot[r] holds row r, its columns mapped the same way (through
 * the ranks' gathered slots on several ranks), and every slot no row names
 * holds the decoupled row d x = 0 (d: the mean diagonal of this rank's
 * rows, so that a smoother set up while the slot was one of them keeps its
 * scale). The list of hypre rows is the rows' slots in row order, then the
 * free slots; sys->rows[0, nrows) are where x comes back from. */
static int assemble(const char *who, const mf_csr *A, const slot_space *ss, const double *b,
                    const double *x, hypre_system *sys)
{
    const mf_row_names *rows = ss->rows;
    const HYPRE_Int nrows = (HYPRE_Int)A->nrows;
    const HYPRE_Int n = rows ? (HYPRE_Int)rows->nslots : nrows; /* hypre's local rows */
    const HYPRE_BigInt ilower = rows ? (HYPRE_BigInt)ss->first : (HYPRE_BigInt)A->row_offset;
    const HYPRE_BigInt iupper = ilower + n - 1; /* ilower - 1 on a rank with no rows */
    const size_t k0 = nrows > 0 ? A->rowptr[0] : 0;
    const size_t nnz_rows = nrows > 0 ? A->rowptr[nrows] - k0 : 0;
    const size_t nnz = nnz_rows + (size_t)(n - nrows); /* + one per free slot */
    int rc = 0;
    void *obj = NULL;

    memset(sys, 0, sizeof *sys);
    /* +1: malloc(0) may return NULL, which would read as a failure. */
    HYPRE_Int *ncols = malloc(((size_t)n + 1) * sizeof *ncols);
    HYPRE_Int *diag_sizes = malloc(((size_t)n + 1) * sizeof *diag_sizes);
    HYPRE_Int *offd_sizes = malloc(((size_t)n + 1) * sizeof *offd_sizes);
    HYPRE_BigInt *cols = malloc((nnz + 1) * sizeof *cols);
    /* The free slots' values (the rows' own go in from A->val). */
    double *vals = rows ? malloc(((size_t)(n - nrows) + 1) * sizeof *vals) : NULL;
    double *bx = rows ? malloc(((size_t)n + 1) * sizeof *bx) : NULL;
    uint8_t *used = rows ? calloc((size_t)n + 1, 1) : NULL;
    sys->rows = malloc(((size_t)n + 1) * sizeof *sys->rows);
    if (ncols == NULL || diag_sizes == NULL || offd_sizes == NULL || cols == NULL ||
        sys->rows == NULL || (rows && (vals == NULL || bx == NULL || used == NULL)))
        rc = MF_ERROR(MF_ERR_MEMORY, "%s: out of memory copying %zu non-zeros for hypre", who,
                      nnz);
    MF_CALL_GOTO(rc, mf_hypre_agree(who, rc), out);

    if (!rows) {
        /* Global columns were checked against nglobal, which fits HYPRE_BigInt. */
        for (HYPRE_Int i = 0; i < n; i++) {
            HYPRE_Int ndiag = 0, noffd = 0;
            sys->rows[i] = ilower + i;
            for (size_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++) {
                HYPRE_BigInt c = (HYPRE_BigInt)A->col[k];
                cols[k - k0] = c;
                if (c >= ilower && c <= iupper)
                    ndiag++;
                else
                    noffd++;
            }
            ncols[i] = ndiag + noffd;
            diag_sizes[i] = ndiag;
            offd_sizes[i] = noffd;
        }
    } else {
        double dsum = 0;
        for (HYPRE_Int i = 0; i < nrows; i++) {
            const int64_t s = rows->slot[i];
            HYPRE_Int ndiag = 0, noffd = 0;
            used[s] = 1;
            sys->rows[i] = ilower + (HYPRE_BigInt)s;
            ncols[i] = (HYPRE_Int)(A->rowptr[i + 1] - A->rowptr[i]);
            for (size_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++) {
                const HYPRE_BigInt c = slot_of_column(ss, A, k);
                cols[k - k0] = c;
                if (c >= ilower && c <= iupper)
                    ndiag++;
                else
                    noffd++;
                if (A->col[k] == A->row_offset + i)
                    dsum += fabs(A->val[k]);
            }
            diag_sizes[s] = ndiag;
            offd_sizes[s] = noffd;
            bx[i] = b[i];
        }
        const double d = nrows > 0 && dsum > 0 ? dsum / nrows : 1.0;
        HYPRE_Int next = nrows;
        size_t k = nnz_rows;
        for (HYPRE_Int s = 0; s < n; s++)
            if (!used[s]) {
                sys->rows[next] = ilower + s;
                ncols[next] = 1;
                diag_sizes[s] = 1;
                offd_sizes[s] = 0;
                cols[k] = ilower + s;
                vals[k++ - nnz_rows] = d;
                bx[next++] = 0.0;
            }
    }

    MF_HYPRE_CALL(who, rc, out, HYPRE_IJMatrixCreate,
                  (MPI_COMM_WORLD, ilower, iupper, ilower, iupper, &sys->A));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJMatrixSetObjectType, (sys->A, HYPRE_PARCSR));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJMatrixSetPrintLevel, (sys->A, 0));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJMatrixSetDiagOffdSizes, (sys->A, diag_sizes, offd_sizes));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJMatrixInitialize, (sys->A));
    /* The rows (their values as the caller has them), then the free slots. */
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJMatrixSetValues,
                  (sys->A, nrows, ncols, sys->rows, cols, nrows > 0 ? A->val + k0 : NULL));
    if (n > nrows)
        MF_HYPRE_CALL(who, rc, out, HYPRE_IJMatrixSetValues,
                      (sys->A, n - nrows, ncols + nrows, sys->rows + nrows, cols + nnz_rows,
                       vals));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJMatrixAssemble, (sys->A));
    MF_HYPRE_CALL(who, rc, out, HYPRE_IJMatrixGetObject, (sys->A, &obj));
    sys->parA = (HYPRE_ParCSRMatrix)obj;

    MF_CALL_GOTO(rc, assemble_vector(who, ilower, iupper, n, sys->rows, rows ? bx : b, &sys->b,
                                     &sys->parb),
                 out);
    if (rows)
        for (HYPRE_Int i = 0; i < nrows; i++)
            bx[i] = x[i]; /* the free slots keep 0 */
    MF_CALL_GOTO(rc, assemble_vector(who, ilower, iupper, n, sys->rows, rows ? bx : x, &sys->x,
                                     &sys->parx),
                 out);
out:
    free(ncols);
    free(diag_sizes);
    free(offd_sizes);
    free(cols);
    free(vals);
    free(bx);
    free(used);
    if (rc != 0)
        system_free(sys);
    return rc;
}

/* ---- a hierarchy for our own V-cycle (one rank) -------------------------- */

int mf_hypre_setup_cycle(const char *who, HYPRE_Solver amg, const mf_csr *A,
                         const mf_row_names *rows, mf_amg_vcycle **cycle)
{
    hypre_system sys = {0};
    int rc = 0;
    *cycle = NULL;
    /* The set-up reads the matrix only: zero vectors will do. */
    double *zero = calloc(A->nrows + 1, sizeof *zero);
    if (zero == NULL) {
        HYPRE_BoomerAMGDestroy(amg);
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory (%zu rows)", who, A->nrows);
    }
    const slot_space ss = {rows, 0, rows ? rows->nslots : 0, NULL, NULL}; /* one rank */
    rc = rows ? check_names(who, A, rows) : 0;
    bool in_place = false; /* hypre's matrix in A's arrays: no copy of A */
    if (rc == 0)
        rc = mf_hypre_setup_in_place(who, amg, A, rows, &in_place);
    if (rc == 0 && !in_place)
        rc = assemble(who, A, &ss, zero, zero, &sys);
    if (rc == 0 && !in_place) {
        HYPRE_Int ierr = HYPRE_BoomerAMGSetup(amg, sys.parA, sys.parb, sys.parx);
        if (ierr != 0)
            rc = mf_hypre_error(who, "HYPRE_BoomerAMGSetup", ierr, __FILE__, __LINE__, __func__);
    }
    /* The copy reads the coarse levels only: the fine matrix goes first, and
     * the copy frees hypre's levels as it goes (peak memory: one hierarchy
     * and a bit, not two and the matrix). amg then only needs destroying
     * (it never frees the finest level, the caller's). */
    system_free(&sys);
    if (rc == 0)
        rc = mf_amg_vcycle_take(amg, cycle);
    HYPRE_BoomerAMGDestroy(amg);
    free(zero);
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    return 0;
}

/* Collective: hypre's PCG with pc on the assembled system (*solver: the
 * caller destroys it); rep's iterations and set-up time, *t_solve when the
 * iterations began. */
static int hypre_pcg_run(const char *who, const mf_hypre_pcg *pcg, const mf_hypre_precond *pc,
                         const hypre_system *sys, HYPRE_Solver *solver_out, mf_solve_report *rep,
                         double t_start, double *t_solve)
{
    int rc = 0;
    HYPRE_Solver solver = NULL;
    MF_HYPRE_CALL(who, rc, done, HYPRE_ParCSRPCGCreate, (MPI_COMM_WORLD, &solver));
    *solver_out = solver;
    MF_HYPRE_CALL(who, rc, done, HYPRE_PCGSetTol, (solver, pcg->tolerance));
    MF_HYPRE_CALL(who, rc, done, HYPRE_PCGSetMaxIter, (solver, (HYPRE_Int)pcg->max_iter));
    /* Stop on ||r||_2 / ||b||_2, the residual we report, not the
     * preconditioned norm. */
    MF_HYPRE_CALL(who, rc, done, HYPRE_PCGSetTwoNorm, (solver, 1));
    /* Before accepting convergence, recompute r = b - A x (one matvec): the
     * recursively updated residual drifts from the true one, and we judge
     * convergence by the true one below. */
    MF_HYPRE_CALL(who, rc, done, HYPRE_PCGSetRecomputeResidual, (solver, 1));
    MF_HYPRE_CALL(who, rc, done, HYPRE_PCGSetPrintLevel, (solver, 0));
    MF_HYPRE_CALL(who, rc, done, HYPRE_PCGSetLogging, (solver, 0));
    MF_HYPRE_CALL(who, rc, done, HYPRE_ParCSRPCGSetPrecond,
                  (solver, pc->solve, pc->setup, pc->solver));
    MF_HYPRE_CALL(who, rc, done, HYPRE_ParCSRPCGSetup, (solver, sys->parA, sys->parb, sys->parx));
    *t_solve = MPI_Wtime();
    rep->setup_seconds = *t_solve - t_start;

    /* x holds the caller's initial guess: PCG starts from it. HYPRE_ERROR_CONV
     * (iteration limit, or a breakdown) is not a library failure: the true
     * residual decides (the caller's), and the caller may retry. */
    HYPRE_Int ierr = HYPRE_ParCSRPCGSolve(solver, sys->parA, sys->parb, sys->parx);
    if (ierr & ~HYPRE_ERROR_CONV) {
        rc = mf_hypre_error(who, "HYPRE_ParCSRPCGSolve", ierr, __FILE__, __LINE__, __func__);
        goto done;
    }
    HYPRE_ClearAllErrors();
    HYPRE_Int iterations = 0;
    MF_HYPRE_CALL(who, rc, done, HYPRE_ParCSRPCGGetNumIterations, (solver, &iterations));
    rep->iterations = (int)iterations;
done:
    return rc;
}

HYPRE_Int mf_hypre_keep_hierarchy(HYPRE_Solver amg, HYPRE_ParCSRMatrix A, HYPRE_ParVector b,
                                  HYPRE_ParVector x)
{
    (void)amg;
    (void)A;
    (void)b;
    (void)x;
    return 0;
}

/* ---- our V-cycle on several ranks ----------------------------------------- */

/* Why hypre's PCG runs instead of ours (why NULL: it does not), printed by
 * rank 0, once a module (pc->told). */
static void tell_fallback(const char *who, const mf_hypre_precond *pc, const char *why)
{
    if (why == NULL || pc->told == NULL || *pc->told)
        return;
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank == 0)
        fprintf(stderr, "%s: hypre's PCG and V-cycle run instead of ours on several ranks: %s\n",
                who, why);
    *pc->told = true;
}

/* Collective: PCG with our V-cycle over pc's hierarchy (set up here when
 * new) on the assembled system; *ran false when hypre's PCG is to run
 * instead (the hierarchy set up, pc->setup then a no-op), the reason
 * printed once by rank 0. */
static int par_cycle_solve(const char *who, const mf_hypre_pcg *pcg, mf_hypre_precond *pc,
                           const hypre_system *sys, double bnorm, mf_solve_report *rep,
                           double t_start, double *t_solve, bool *ran)
{
    int rc = 0;
    const char *why = NULL;
    *ran = false;
    if (pc->setup == HYPRE_BoomerAMGSetup) { /* a new hierarchy */
        MF_HYPRE_CALL(who, rc, fail, HYPRE_BoomerAMGSetup,
                      (pc->solver, sys->parA, sys->parb, sys->parx));
        pc->setup = mf_hypre_keep_hierarchy;
        mf_amg_par_free(*pc->par);
        *pc->par = NULL;
        MF_CALL(mf_amg_par_take(pc->solver, pc->par, &why));
    }
    if (*pc->par) {
        *t_solve = MPI_Wtime();
        rep->setup_seconds = *t_solve - t_start;
        rc = mf_amg_par_pcg(*pc->par, sys->parA, sys->parb, sys->parx, bnorm, pcg->tolerance,
                            pcg->max_iter, &rep->iterations, &rep->final_residual, &why);
        if (rc != 0 && rc != MF_RETRY)
            return mf_error_trace(rc, __FILE__, __LINE__, __func__);
        *ran = why == NULL;
    }
    tell_fallback(who, pc, why);
    return 0;
fail:
    return rc;
}

/* Collective: PCG with our V-cycle over the kept hierarchy (*pc->par), the
 * fine level built from the caller's rows in slot space; *ran false (x as
 * it was) when it cannot run, the reason printed once. */
static int par_rows_solve(const char *who, const mf_hypre_pcg *pcg, mf_hypre_precond *pc,
                          const mf_csr *A, const slot_space *ss, const double *b, double *x,
                          double bnorm, mf_solve_report *rep, double t_start, double *t_solve,
                          bool *ran)
{
    const mf_par_slots ps = {ss->rows->slot, ss->rows->nslots, ss->first, ss->halo};
    const char *why = NULL;
    *t_solve = MPI_Wtime();
    rep->setup_seconds = *t_solve - t_start;
    const int rc = mf_amg_par_pcg_rows(*pc->par, A, &ps, b, x, bnorm, pcg->tolerance,
                                       pcg->max_iter, &rep->iterations, &rep->final_residual,
                                       &why);
    if (rc != 0 && rc != MF_RETRY)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    *ran = why == NULL;
    tell_fallback(who, pc, why);
    return 0;
}

/* ---- pattern fingerprint (for reusing an AMG hierarchy) ------------------ */

int mf_hypre_pattern_hash(const mf_csr *A, uint64_t *hash)
{
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    uint64_t h = MF_HASH_START;
    h = mf_hash_word(h, (uint64_t)rank);
    h = mf_hash_word(h, (uint64_t)A->nglobal);
    h = mf_hash_word(h, (uint64_t)A->row_offset);
    h = mf_hash_word(h, (uint64_t)A->nrows);
    for (size_t i = 0; i < A->nrows; i++) {
        h = mf_hash_word(h, (uint64_t)(A->rowptr[i + 1] - A->rowptr[i]));
        for (size_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            h = mf_hash_word(h, (uint64_t)A->col[k]);
    }
    /* One value on every rank, so all ranks take the same reuse decision. */
    MPI_Allreduce(&h, hash, 1, MPI_UINT64_T, MPI_BXOR, MPI_COMM_WORLD);
    return 0;
}

/* ---- the solve ----------------------------------------------------------- */

/* MF_HALO_BYTES set: one line a rank a solve on stderr, the bytes this rank
 * received from the others in the exchanges of other ranks' rows (the halo's
 * build: its counts and requests; the slots; x for each residual), counted
 * as they are made, against what the gathers they replaced received for
 * the same solve, reckoned from their counts (an MPI_Allgatherv receives
 * every other rank's rows): one int a global row for the slots, one double
 * a global row for each residual, and the rows block's own MPI_Alltoall and
 * MPI_Alltoallv of its requests (nprocs - 1 counts, one int a value asked of
 * this rank). */
static void tell_bytes(const mf_csr *A, const layout *lay, const mf_halo_columns *h,
                       bool slots, int residuals, bool rows_block)
{
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    const uint64_t others = (uint64_t)A->nglobal - A->nrows;
    const uint64_t gathers =
        (slots ? others * sizeof(int) : 0) + others * sizeof(double) * (uint64_t)residuals +
        (rows_block ? (uint64_t)(lay->nprocs - 1) * sizeof(int) + (uint64_t)h->nsend * sizeof(int)
                    : 0);
    fprintf(stderr,
            "MF_HALO_BYTES rank %d: rows %zu of %" PRId64 ", halo %d, asked %d, residuals %d, "
            "slots %d, rows block %d: received %" PRIu64 " B, gathers %" PRIu64 " B\n",
            rank, A->nrows, A->nglobal, (int)h->n, (int)h->nsend, residuals, (int)slots,
            (int)rows_block, h->bytes_received, gathers);
}

int mf_hypre_pcg_solve(const mf_hypre_pcg *pcg, const mf_csr *A, const double *b, double *x,
                       mf_solve_report *rep)
{
    const char *who = pcg->name;
    const double t_start = MPI_Wtime();
    mf_solve_report unused;
    layout lay;
    hypre_system sys = {0};
    slot_space ss = {0};
    mf_hypre_precond pc = {0};
    HYPRE_Solver solver = NULL;
    bool prepared = false, converged = false;
    double *r = NULL;
    mf_halo_columns halo_store = {0}, *halo = NULL; /* several ranks */
    /* MF_HALO_BYTES: what the exchanges of other ranks' rows received, and
     * what the gathers of one value a global row they replace received. */
    int residuals = 0;
    bool rows_block = false;
    int rc = 0;

    if (rep == NULL)
        rep = &unused;
    memset(rep, 0, sizeof *rep);
    MF_CALL(mf_hypre_check_pcg_settings(who, pcg->tolerance, pcg->max_iter));
    MF_CALL(check_system(who, A, b, x, &lay));

    /* Cheap exits first: they need neither assembly nor a preconditioner. */
    double bnorm = 0.0;
    for (size_t i = 0; i < A->nrows; i++)
        bnorm += b[i] * b[i];
    bnorm = sqrt(global_sum(bnorm));
    if (!isfinite(bnorm)) {
        rc = MF_ERROR(MF_ERR_NUMERIC, "%s: the right-hand side holds NaN or Inf", who);
        goto done;
    }
    if (bnorm == 0.0) {
        /* A x = 0 with A SPD: x = 0 exactly, whatever the guess. */
        for (size_t i = 0; i < A->nrows; i++)
            x[i] = 0.0;
        converged = true;
        rep->converged = true;
        rep->setup_seconds = MPI_Wtime() - t_start;
        goto done;
    }
    /* Several ranks: the other ranks' rows this rank's rows read, for the
     * residuals, the slots and our cycle's fine level (halo_columns.h). */
    if (lay.nprocs > 1) {
        MF_CALL_GOTO(rc, mf_halo_columns_build(who, A, lay.displs, lay.nprocs, &halo_store),
                     done);
        halo = &halo_store;
    }
    /* One rank with a module that runs its own V-cycle: the residual vector
     * is PCG's start. */
    const bool own = lay.nprocs == 1 && pcg->cycle_prepare != NULL;
    const local_system loc = {A, b};
    double rnorm = 0.0;
    if (own) {
        r = malloc((A->nrows + 1) * sizeof *r);
        if (r == NULL) {
            rc = MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for the residual (%zu rows)", who,
                          A->nrows);
            goto done;
        }
        rnorm = residual_local(&loc, x, r);
    } else {
        MF_CALL_GOTO(rc, residual_norm(who, A, b, x, halo, &rnorm), done);
        residuals++;
    }
    rep->initial_residual = rnorm / bnorm;
    if (!isfinite(rep->initial_residual)) {
        rc = MF_ERROR(MF_ERR_NUMERIC,
                      "%s: the initial residual is not finite: the matrix or the initial guess "
                      "holds NaN or Inf",
                      who);
        goto done;
    }
    if (rep->initial_residual <= pcg->tolerance) {
        /* A warm start that already satisfies the tolerance: nothing to do. */
        rep->final_residual = rep->initial_residual;
        converged = true;
        rep->converged = true;
        rep->setup_seconds = MPI_Wtime() - t_start;
        goto done;
    }

    /* hypre's error flag is global and sticky: start clean so that a failure
     * left by someone else is not reported as ours. */
    HYPRE_ClearAllErrors();
    /* Slot space when the rows are named: each rank's slots a block of
     * hypre's rows (slot_space). */
    const mf_row_names *rows = pcg->rows;
    MF_CALL_GOTO(rc, slot_space_build(who, A, rows, &lay, halo, &ss), done);
    if (own) {
        mf_amg_vcycle *cycle = NULL;
        MF_CALL_GOTO(rc, pcg->cycle_prepare(pcg->ctx, A, rows, &cycle), done);
        if (cycle != NULL) {
            prepared = true;
            const double t_solve = MPI_Wtime();
            rep->setup_seconds = t_solve - t_start;
            rc = mf_amg_pcg(cycle, A, rows ? rows->slot : NULL, x, r, bnorm, pcg->tolerance,
                            pcg->max_iter, residual_local, &loc, &rep->iterations,
                            &rep->final_residual);
            if (rc != 0 && rc != MF_RETRY) {
                mf_error_trace(rc, __FILE__, __LINE__, __func__);
                goto done;
            }
            rc = 0; /* not converged: said below, with the figures */
            converged = rep->final_residual <= pcg->tolerance; /* false for NaN */
            rep->converged = converged;
            rep->solve_seconds = MPI_Wtime() - t_solve;
            goto done;
        }
        /* Not a hierarchy our cycle runs: hypre's PCG. */
    }
    rc = pcg->precond_prepare(pcg->ctx, A, rows, &pc);
    prepared = rc == 0;
    MF_CALL_GOTO(rc, mf_hypre_agree(who, rc), done);

    double t_solve = MPI_Wtime();
    bool ran = false; /* our PCG and V-cycle on several ranks */
    if (lay.nprocs > 1 && pc.par != NULL && *pc.par != NULL && pc.setup != HYPRE_BoomerAMGSetup &&
        ss.rows != NULL) {
        /* A kept hierarchy: the fine level from the caller's rows, no hypre matrix. */
        rows_block = true;
        MF_CALL_GOTO(rc, par_rows_solve(who, pcg, &pc, A, &ss, b, x, bnorm, rep, t_start,
                                        &t_solve, &ran),
                     done);
    }
    /* Our PCG over the caller's rows has the honest number already: its last
     * residual is the true ||b - A x|| of those rows (build_rows_block in
     * amg_vcycle_par.c copies them, no hypre assembly in between), as the
     * serial mf_amg_pcg's is of residual_local. */
    const bool rows_residual = ran;
    if (!ran) {
        MF_CALL_GOTO(rc, assemble(who, A, &ss, b, x, &sys), done);
        if (lay.nprocs > 1 && pc.par != NULL)
            MF_CALL_GOTO(rc, par_cycle_solve(who, pcg, &pc, &sys, bnorm, rep, t_start, &t_solve,
                                             &ran),
                         done);
        if (!ran)
            MF_CALL_GOTO(rc,
                         hypre_pcg_run(who, pcg, &pc, &sys, &solver, rep, t_start, &t_solve),
                         done);
        MF_HYPRE_CALL(who, rc, done, HYPRE_IJVectorGetValues,
                      (sys.x, (HYPRE_Int)A->nrows, sys.rows, x));
    }

    /* The honest number: ||b - A x|| / ||b|| from the caller's matrix. */
    if (!rows_residual) {
        MF_CALL_GOTO(rc, residual_norm(who, A, b, x, halo, &rnorm), done);
        residuals++;
        rep->final_residual = rnorm / bnorm;
    }
    converged = rep->final_residual <= pcg->tolerance; /* false for NaN */
    rep->converged = converged;
    rep->solve_seconds = MPI_Wtime() - t_solve;

done:
    if (solver)
        HYPRE_ParCSRPCGDestroy(solver);
    if (prepared && pcg->precond_release)
        pcg->precond_release(pcg->ctx, rep, rc == 0 && converged);
    system_free(&sys);
    if (halo != NULL && getenv("MF_HALO_BYTES") != NULL)
        tell_bytes(A, &lay, halo, ss.rows != NULL, residuals, rows_block);
    slot_space_free(&ss);
    mf_halo_columns_free(&halo_store);
    layout_free(&lay);
    free(r);
    if (rc == 0 && !converged)
        rc = MF_ERROR(MF_RETRY,
                      "%s: not converged after %d iterations (final residual %g > tolerance %g)",
                      who, rep->iterations, rep->final_residual, pcg->tolerance);
    return rc;
}
