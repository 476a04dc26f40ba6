/* amg_vcycle_par.c: the V-cycle and PCG of amg_vcycle.h on N MPI ranks,
 * over the hierarchy hypre's BoomerAMG set up across the ranks.
 *
 * The operator is hypre's cycle with relaxType 3 down and 4 up on N ranks
 * (hypre_BoomerAMGRelax, hybrid Gauss-Seidel: within a rank's rows in order,
 * the other ranks' values those of before the sweep), in exact arithmetic:
 *
 *   down, level l (u = 0):  (D_l + L_l) u = f       (no exchange: u_halo = 0)
 *                           r = f - A u = -U_l u - O_l u_halo
 *                           f_{l+1} = P_l^T r       (offd part sent back)
 *   coarsest:               u = A_c^{-1} f          (gathered, dense LU)
 *   up, level l:            u += P_l u_{l+1}        (u_{l+1}'s halo fetched)
 *                           backward GS with O_l u_halo fixed
 *
 * D, L, U: the diagonal, lower and upper parts of the rank's diag block;
 * O: the offd block. The serial cycle (amg_vcycle.c) is the same with O = 0.
 * Briggs, Henson and McCormick, "A Multigrid Tutorial", 2nd ed., SIAM 2000,
 * ch. 3 (the V-cycle) and ch. 8 (AMG); Yang, "Parallel algebraic multigrid"
 * in hypre's documentation (hybrid smoothers).
 */
#define MF_PRESSURE_HYPRE_INTERNAL
#include "pressure_hypre.h"

#include "amg_vcycle.h"
#include "halo_columns.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <_hypre_parcsr_ls.h>
#pragma GCC diagnostic pop

#include "mf_error.h"
#include "row_dot.h"


/* ---- one rank's block of a ParCSR matrix ---------------------------------- */

typedef struct par_block {
    int32_t n;                   /* local rows */
    mf_split_csr D;              /* a level's matrix: the diag block, split */
    const int32_t *di, *dj;      /* an interpolation: the diag block, read in place */
    const double *dv;
    const int32_t *oi, *oj;      /* the offd block, in place (NULL: empty) */
    const double *ov;
    int32_t ncols_offd;
    hypre_ParCSRCommPkg *pkg;
    int32_t nsend;               /* values sent (the package's send map) */
    double *send, *halo;         /* send buffer; the offd columns' values */
    /* Built from the caller's rows (set_fine_rows): the offd block and the
     * package are the block's own. */
    int32_t *own_oi, *own_oj;
    double *own_ov;
    bool own_pkg;
} par_block;

static void block_free(par_block *b)
{
    if (b->own_pkg)
        hypre_MatvecCommPkgDestroy(b->pkg);
    free(b->own_oi);
    free(b->own_oj);
    free(b->own_ov);
    mf_split_csr_free(&b->D);
    free(b->send);
    free(b->halo);
    memset(b, 0, sizeof *b);
}

/* Whether a block holds entries (by its row pointers, not the count
 * field). */
static bool has_entries(hypre_CSRMatrix *M)
{
    const HYPRE_Int *I = hypre_CSRMatrixI(M);
    const HYPRE_Int n = hypre_CSRMatrixNumRows(M);
    return I != NULL && n > 0 && I[n] > I[0];
}

/* b over this rank's rows of M; split: the diag block copied for the
 * sweeps (a level's matrix), else read in place (an interpolation). */
static int block_set(par_block *b, hypre_ParCSRMatrix *M, bool split)
{
    hypre_CSRMatrix *D = hypre_ParCSRMatrixDiag(M), *O = hypre_ParCSRMatrixOffd(M);
    b->n = hypre_CSRMatrixNumRows(D);
    b->ncols_offd = hypre_CSRMatrixNumCols(O);
    if (has_entries(O)) {
        b->oi = hypre_CSRMatrixI(O);
        b->oj = hypre_CSRMatrixJ(O);
        b->ov = hypre_CSRMatrixData(O);
    }
    if (split)
        MF_CALL(mf_amg_copy_diag(&b->D, (HYPRE_ParCSRMatrix)M));
    else {
        b->di = hypre_CSRMatrixI(D);
        b->dj = hypre_CSRMatrixJ(D);
        b->dv = hypre_CSRMatrixData(D);
    }
    if (hypre_ParCSRMatrixCommPkg(M) == NULL)
        hypre_MatvecCommPkgCreate(M);
    b->pkg = hypre_ParCSRMatrixCommPkg(M);
    b->nsend = hypre_ParCSRCommPkgSendMapStart(b->pkg, hypre_ParCSRCommPkgNumSends(b->pkg));
    b->send = malloc(((size_t)b->nsend + 1) * sizeof *b->send);
    b->halo = calloc((size_t)b->ncols_offd + 1, sizeof *b->halo);
    if (!b->send || !b->halo)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for a halo of %d values", b->ncols_offd);
    return 0;
}

/* b->halo = the values of x (the columns' owners' rows) in b's offd columns. */
static void halo_fetch(par_block *b, const double *x)
{
    const HYPRE_Int *elmts = hypre_ParCSRCommPkgSendMapElmts(b->pkg);
    for (int32_t k = 0; k < b->nsend; k++)
        b->send[k] = x[elmts[k]];
    hypre_ParCSRCommHandleDestroy(hypre_ParCSRCommHandleCreate(1, b->pkg, b->send, b->halo));
}

/* The transpose: y (this rank's columns) += what the other ranks hold in
 * their b->halo for them. */
static void halo_return(par_block *b, double *y)
{
    const HYPRE_Int *elmts = hypre_ParCSRCommPkgSendMapElmts(b->pkg);
    hypre_ParCSRCommHandleDestroy(hypre_ParCSRCommHandleCreate(2, b->pkg, b->halo, b->send));
    for (int32_t k = 0; k < b->nsend; k++)
        y[elmts[k]] += b->send[k];
}

/* Row i of the offd block times b->halo. */
static inline double offd_dot(const par_block *b, int32_t i)
{
    if (b->oi == NULL)
        return 0.0;
    const int32_t k = b->oi[i];
    return mf_row_dot(b->oj + k, b->ov + k, (size_t)(b->oi[i + 1] - k), b->halo);
}

/* Whether every diagonal entry of the split block is positive, on every rank. */
static bool diag_positive(const mf_split_csr *D)
{
    bool ok = true;
    for (int32_t i = 0; i < D->n; i++)
        ok = ok && D->diag[i] > 0.0;
    return mf_hypre_all(ok);
}

/* ---- the hierarchy ---------------------------------------------------------- */

typedef struct par_level {
    par_block A; /* level 0: the solve's matrix, set at each solve */
    par_block P; /* to this level from the next coarser */
    double *f, *u, *res;
    int32_t n;
} par_level;

struct mf_amg_par {
    int nlevels;
    par_level *lev;
    /* The coarsest level, gathered on every rank. */
    int nc;
    double *lu;
    int *ipiv;
    int *counts, *displs; /* its rows of each rank */
    double *fc;           /* its whole right-hand side, then solution */
    int c_first, c_n;     /* this rank's rows of it */
    double *work[4];      /* PCG: r, z, p, q */
    size_t work_n;
};

void mf_amg_par_free(mf_amg_par *v)
{
    if (v == NULL)
        return;
    for (int l = 0; l < v->nlevels; l++) {
        par_level *L = &v->lev[l];
        block_free(&L->A);
        block_free(&L->P);
        free(L->f);
        free(L->u);
        free(L->res);
    }
    free(v->lev);
    free(v->lu);
    free(v->ipiv);
    free(v->counts);
    free(v->displs);
    free(v->fc);
    for (int k = 0; k < 4; k++)
        free(v->work[k]);
    free(v);
}

static int alloc_vectors(par_level *L, int32_t n)
{
    L->n = n;
    L->f = malloc(((size_t)n + 1) * sizeof *L->f);
    L->u = malloc(((size_t)n + 1) * sizeof *L->u);
    L->res = malloc(((size_t)n + 1) * sizeof *L->res);
    if (!L->f || !L->u || !L->res)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the AMG work vectors (%d rows)", n);
    return 0;
}

/* The coarsest matrix C on every rank, dense (column-major), from each
 * rank's rows as (row, column, value) triples. */
static int gather_coarsest(mf_amg_par *v, hypre_ParCSRMatrix *C, int nprocs)
{
    hypre_CSRMatrix *D = hypre_ParCSRMatrixDiag(C), *O = hypre_ParCSRMatrixOffd(C);
    const int n = hypre_CSRMatrixNumRows(D);
    const HYPRE_Int *I = hypre_CSRMatrixI(D), *J = hypre_CSRMatrixJ(D);
    const HYPRE_Real *V = hypre_CSRMatrixData(D);
    const bool has_offd = has_entries(O);
    const HYPRE_Int *OI = hypre_CSRMatrixI(O), *OJ = hypre_CSRMatrixJ(O);
    const HYPRE_Real *OV = hypre_CSRMatrixData(O);
    const HYPRE_BigInt *cmap = hypre_ParCSRMatrixColMapOffd(C);
    const int first = (int)hypre_ParCSRMatrixFirstRowIndex(C);
    const int first_col = (int)hypre_ParCSRMatrixFirstColDiag(C);
    const int nnz = (n > 0 ? I[n] - I[0] : 0) + (has_offd && n > 0 ? OI[n] - OI[0] : 0);
    const int nc = v->nc;
    int rc = 0;
    v->c_first = first;
    v->c_n = n;
    v->counts = malloc((size_t)nprocs * sizeof *v->counts);
    v->displs = malloc((size_t)nprocs * sizeof *v->displs);
    int *nnzs = malloc((size_t)nprocs * sizeof *nnzs);
    int *ndispl = malloc((size_t)nprocs * sizeof *ndispl);
    int *rc3 = malloc(((size_t)nnz + 1) * 2 * sizeof *rc3);
    double *vals = malloc(((size_t)nnz + 1) * sizeof *vals);
    v->fc = malloc(((size_t)nc + 1) * sizeof *v->fc);
    v->lu = calloc((size_t)nc * nc, sizeof *v->lu);
    v->ipiv = malloc(((size_t)nc + 1) * sizeof *v->ipiv);
    if (!v->counts || !v->displs || !nnzs || !ndispl || !rc3 || !vals || !v->fc || !v->lu ||
        !v->ipiv)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory gathering the coarsest AMG level (%d rows)",
                      nc);
    MF_CALL_GOTO(rc, mf_hypre_agree("PCG_BoomerAMG", rc), out);
    int k = 0;
    for (int i = 0; i < n; i++) {
        for (HYPRE_Int e = I[i]; e < I[i + 1]; e++) {
            rc3[2 * k] = first + i;
            rc3[2 * k + 1] = first_col + J[e];
            vals[k++] = V[e];
        }
        if (has_offd)
            for (HYPRE_Int e = OI[i]; e < OI[i + 1]; e++) {
                rc3[2 * k] = first + i;
                rc3[2 * k + 1] = (int)cmap[OJ[e]];
                vals[k++] = OV[e];
            }
    }
    MPI_Allgather(&n, 1, MPI_INT, v->counts, 1, MPI_INT, MPI_COMM_WORLD);
    MPI_Allgather(&first, 1, MPI_INT, v->displs, 1, MPI_INT, MPI_COMM_WORLD);
    MPI_Allgather(&nnz, 1, MPI_INT, nnzs, 1, MPI_INT, MPI_COMM_WORLD);
    int total = 0;
    for (int p = 0; p < nprocs; p++) {
        ndispl[p] = total;
        total += nnzs[p];
    }
    int *all_rc = malloc(((size_t)total + 1) * 2 * sizeof *all_rc);
    double *all_v = malloc(((size_t)total + 1) * sizeof *all_v);
    rc = all_rc && all_v ? 0 : MF_ERROR(MF_ERR_MEMORY, "out of memory gathering %d entries", total);
    rc = mf_hypre_agree("PCG_BoomerAMG", rc);
    if (rc == 0) {
        MPI_Allgatherv(vals, nnz, MPI_DOUBLE, all_v, nnzs, ndispl, MPI_DOUBLE, MPI_COMM_WORLD);
        for (int p = 0; p < nprocs; p++) {
            nnzs[p] *= 2;
            ndispl[p] *= 2;
        }
        MPI_Allgatherv(rc3, 2 * nnz, MPI_INT, all_rc, nnzs, ndispl, MPI_INT, MPI_COMM_WORLD);
        for (int e = 0; e < total; e++) /* column-major: (row, col) */
            v->lu[(size_t)all_rc[2 * e + 1] * nc + all_rc[2 * e]] += all_v[e];
    }
    free(all_rc);
    free(all_v);
out:
    free(nnzs);
    free(ndispl);
    free(rc3);
    free(vals);
    return rc;
}

int mf_amg_par_take(HYPRE_Solver amg, mf_amg_par **out, const char **why)
{
    hypre_ParAMGData *d = (hypre_ParAMGData *)amg;
    *out = NULL;
    *why = NULL;
    int nprocs = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
    /* The same settings and hierarchy sizes on every rank: one answer. */
    const int nlevels = hypre_ParAMGDataNumLevels(d);
    if (nlevels < 2) {
        *why = "a hierarchy of one level";
        return 0;
    }
    if (!mf_amg_cycle_is_ours(amg)) {
        const HYPRE_Int *type = hypre_ParAMGDataGridRelaxType(d);
        *why = type && type[1] == 3 && type[2] == 4 && type[3] != 9
                   ? "hypre relaxes the coarsest level instead of Gaussian elimination"
                   : "the settings make another cycle than relaxType 3 down, 4 up";
        return 0;
    }
    hypre_ParCSRMatrix **A = hypre_ParAMGDataAArray(d), **P = hypre_ParAMGDataPArray(d);
    const HYPRE_BigInt nc = hypre_ParCSRMatrixGlobalNumRows(A[nlevels - 1]);
    if (nc < 1 || nc > MF_AMG_MAX_COARSEST) {
        *why = "a coarsest level too large to gather";
        return 0;
    }

    int rc = 0;
    mf_amg_par *v = calloc(1, sizeof *v);
    if (v && !(v->lev = calloc((size_t)nlevels, sizeof *v->lev))) {
        free(v);
        v = NULL;
    }
    rc = v ? 0 : MF_ERROR(MF_ERR_MEMORY, "out of memory for an AMG hierarchy");
    rc = mf_hypre_agree("PCG_BoomerAMG", rc);
    if (rc != 0) {
        mf_amg_par_free(v);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    v->nlevels = nlevels;
    v->nc = (int)nc;
    for (int l = 0; l < nlevels && rc == 0; l++) {
        par_level *L = &v->lev[l];
        if (l + 1 < nlevels)
            rc = block_set(&L->P, P[l], false);
        if (rc == 0 && l > 0 && l + 1 < nlevels)
            rc = block_set(&L->A, A[l], true);
        /* (level 0 uses its residual only) */
        if (rc == 0)
            rc = alloc_vectors(L,
                               hypre_CSRMatrixNumRows(hypre_ParCSRMatrixDiag(l > 0 ? A[l] : P[0])));
    }
    MF_CALL_GOTO(rc, mf_hypre_agree("PCG_BoomerAMG", rc), fail);
    bool positive = true;
    for (int l = 1; l + 1 < nlevels; l++)
        positive = positive && diag_positive(&v->lev[l].A.D);
    if (!positive) {
        *why = "a coarse level's diagonal is not positive";
        mf_amg_par_free(v);
        return 0;
    }
    MF_CALL_GOTO(rc, gather_coarsest(v, A[nlevels - 1], nprocs), fail);
    int info = 0;
    dgetrf_(&v->nc, &v->nc, v->lu, &v->nc, v->ipiv, &info); /* the same on every rank */
    if (info != 0) {
        *why = "the coarsest level is singular";
        mf_amg_par_free(v);
        return 0;
    }
    *out = v;
    return 0;
fail:
    mf_amg_par_free(v);
    return rc;
}

/* ---- the cycle ---------------------------------------------------------------- */

/* Forward Gauss-Seidel from u = 0 within the block (the offd values are 0). */
static void sweep_down_from_zero(const mf_split_csr *A, const double *f, double *u)
{
    for (int32_t i = 0; i < A->n; i++) {
        const int32_t k = A->ptr[i];
        u[i] = (f[i] - mf_row_dot(A->col + k, A->val + k, (size_t)(A->mid[i] - k), u)) *
               A->dinv[i];
    }
}

/* f_{l+1} = P^T (f - A u) after sweep_down_from_zero: f - A u = -U u - O u_halo. */
static void restrict_residual(par_level *L, par_level *C, const double *u)
{
    par_block *A = &L->A, *P = &L->P;
    const mf_split_csr *D = &A->D;
    halo_fetch(A, u);
    for (int32_t i = 0; i < D->n; i++) {
        const int32_t m = D->mid[i];
        L->res[i] = -mf_row_dot(D->col + m, D->val + m, (size_t)(mf_split_end(D, i) - m), u) -
                    offd_dot(A, i);
    }
    double *fc = C->f;
    memset(fc, 0, (size_t)C->n * sizeof *fc);
    memset(P->halo, 0, (size_t)P->ncols_offd * sizeof *P->halo);
    for (int32_t i = 0; i < P->n; i++) {
        const double res = L->res[i];
        for (int32_t k = P->di[i]; k < P->di[i + 1]; k++)
            fc[P->dj[k]] += P->dv[k] * res;
        if (P->oi)
            for (int32_t k = P->oi[i]; k < P->oi[i + 1]; k++)
                P->halo[P->oj[k]] += P->ov[k] * res;
    }
    halo_return(P, fc);
}

/* u += P u_c. */
static void interpolate(par_level *L, const double *uc, double *u)
{
    par_block *P = &L->P;
    halo_fetch(P, uc);
    for (int32_t i = 0; i < P->n; i++) {
        const int32_t k = P->di[i];
        u[i] += mf_row_dot(P->dj + k, P->dv + k, (size_t)(P->di[i + 1] - k), uc) +
                offd_dot(P, i);
    }
}

/* Backward Gauss-Seidel within the block, the offd values of before it. */
static void sweep_up(par_block *A, const double *f, double *u)
{
    const mf_split_csr *D = &A->D;
    halo_fetch(A, u);
    for (int32_t i = D->n - 1; i >= 0; i--) {
        const int32_t k = D->ptr[i];
        const double res = f[i] - D->diag[i] * u[i] -
                           mf_row_dot(D->col + k, D->val + k, (size_t)(mf_split_end(D, i) - k), u) -
                           offd_dot(A, i);
        u[i] += res * D->dinv[i];
    }
}

/* z = M r with the fine level set (v->lev[0].A). */
static void cycle(mf_amg_par *v, const double *r, double *z)
{
    const int nl = v->nlevels;
    for (int l = 0; l + 1 < nl; l++) {
        par_level *L = &v->lev[l];
        const double *f = l == 0 ? r : L->f;
        double *u = l == 0 ? z : L->u;
        sweep_down_from_zero(&L->A.D, f, u);
        restrict_residual(L, &v->lev[l + 1], u);
    }
    par_level *C = &v->lev[nl - 1];
    MPI_Allgatherv(C->f, v->c_n, MPI_DOUBLE, v->fc, v->counts, v->displs, MPI_DOUBLE,
                   MPI_COMM_WORLD);
    const int one = 1;
    int info = 0;
    dgetrs_("N", &v->nc, &one, v->lu, &v->nc, v->ipiv, v->fc, &v->nc, &info);
    memcpy(C->u, v->fc + v->c_first, (size_t)v->c_n * sizeof *C->u);
    for (int l = nl - 2; l >= 0; l--) {
        par_level *L = &v->lev[l];
        const double *f = l == 0 ? r : L->f;
        double *u = l == 0 ? z : L->u;
        interpolate(L, v->lev[l + 1].u, u);
        sweep_up(&L->A, f, u);
    }
}

/* Collective: the fine level from A; *why when it is not one the cycle
 * runs on some rank. */
static int set_fine(mf_amg_par *v, hypre_ParCSRMatrix *A, const char **why)
{
    block_free(&v->lev[0].A);
    const int rc = block_set(&v->lev[0].A, A, true);
    MF_CALL(mf_hypre_agree("PCG_BoomerAMG", rc));
    const bool fits = mf_hypre_all(v->lev[0].A.n == v->lev[0].P.n);
    *why = !fits ? "a system of other rows than the hierarchy's"
           : !diag_positive(&v->lev[0].A.D) ? "a diagonal entry of the matrix is not positive"
                                            : NULL;
    return 0;
}

/* ---- the fine level from the caller's rows ------------------------------------ */

/* This rank's rows of A in slot space as hypre_common.c's assembly makes
 * them (a slot no row names: d x = 0, d the rows' mean |diagonal|), the
 * columns this rank's slots (diag) or other ranks' rows (offd), and the comm
 * package that moves the offd values: the solve's halo of columns
 * (halo_columns.h), whose plan says which of this rank's rows each rank
 * reads (sent from their slots here) and whose order numbers the offd
 * columns (a non-zero's offd column is its column's place in the halo).
 * hypre numbers them by ascending global slot instead; a row's offd sum
 * reads the same values in the same order either way, so the cycle's
 * results are the same bit for bit. No value a global row: O(local rows
 * and halo) memory, no exchange of its own. */
static int build_rows_block(par_block *F, const mf_csr *A, const mf_par_slots *ps)
{
    const mf_halo_columns *h = ps->halo;
    const int nprocs = h->nprocs;
    const int32_t n = (int32_t)ps->nslots, nrows = (int32_t)A->nrows;
    const size_t k0 = nrows > 0 ? A->rowptr[0] : 0;
    const size_t nnz = nrows > 0 ? A->rowptr[nrows] - k0 : 0;
    int rc = 0;
    int32_t *row_of = malloc(((size_t)n + 1) * sizeof *row_of);
    F->own_oi = malloc(((size_t)n + 1) * sizeof *F->own_oi);
    F->own_oj = malloc((nnz + 1) * sizeof *F->own_oj);
    F->own_ov = malloc((nnz + 1) * sizeof *F->own_ov);
    if (!row_of || !F->own_oi || !F->own_oj || !F->own_ov)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for the fine level (%d slots)", n);
    if (rc == 0)
        rc = mf_split_csr_reserve(&F->D, (size_t)n, nnz);
    MF_CALL_GOTO(rc, mf_hypre_agree("PCG_BoomerAMG", rc), out);

    for (int32_t s = 0; s < n; s++)
        row_of[s] = -1;
    double dsum = 0.0;
    for (int32_t r = 0; r < nrows; r++) {
        row_of[ps->slot[r]] = r;
        for (size_t k = A->rowptr[r]; k < A->rowptr[r + 1]; k++)
            if (A->col[k] == A->row_offset + r)
                dsum += fabs(A->val[k]);
    }
    const double dfree = nrows > 0 && dsum > 0 ? dsum / nrows : 1.0;

    /* The rows by slot: the diag block (local columns) straight into the
     * split layout, in one pass over the row for the lower part, the
     * diagonal and the offd block, one more for the upper part: the layout
     * and the bits mf_split_csr_set makes of the diag block's CSR. A
     * column's place in [rows | halo] (h->ext) says which it is. */
    mf_split_csr *S = &F->D;
    int32_t kd = 0, ko = 0;
    S->ptr[0] = 0;
    for (int32_t s = 0; s < n; s++) {
        F->own_oi[s] = ko;
        const int32_t r = row_of[s];
        double d = 0.0;
        if (r < 0)
            d += dfree;
        else {
            for (size_t k = A->rowptr[r]; k < A->rowptr[r + 1]; k++) {
                const int32_t e = h->ext[k - k0];
                if (e < nrows) {
                    const int32_t c = (int32_t)ps->slot[e];
                    if (c == s)
                        d += A->val[k];
                    else if (c < s) {
                        S->col_buf[kd] = c;
                        S->val_buf[kd++] = A->val[k];
                    }
                } else {
                    F->own_oj[ko] = e - nrows;
                    F->own_ov[ko++] = A->val[k];
                }
            }
        }
        S->mid[s] = kd;
        for (size_t k = r < 0 ? 0 : A->rowptr[r]; r >= 0 && k < A->rowptr[r + 1]; k++) {
            const int32_t e = h->ext[k - k0];
            if (e < nrows && (int32_t)ps->slot[e] > s) {
                S->col_buf[kd] = (int32_t)ps->slot[e];
                S->val_buf[kd++] = A->val[k];
            }
        }
        S->ptr[s + 1] = kd;
        S->diag[s] = d;
        S->dinv[s] = d != 0.0 ? 1.0 / d : 0.0;
    }
    F->own_oi[n] = ko;
    F->n = n;
    F->ncols_offd = h->n;
    F->oi = ko > 0 ? F->own_oi : NULL;
    F->oj = F->own_oj;
    F->ov = F->own_ov;

    /* The comm package from the halo's plan: the ranks this one reads from
     * (its halo, grouped by owner) and those that read from it. */
    int nrecv = 0, nsend = 0;
    for (int p = 0; p < nprocs; p++) {
        nrecv += h->recv_counts[p] > 0;
        nsend += h->send_counts[p] > 0;
    }
    HYPRE_Int *recv_procs = hypre_CTAlloc(HYPRE_Int, nrecv + 1, HYPRE_MEMORY_HOST);
    HYPRE_Int *recv_starts = hypre_CTAlloc(HYPRE_Int, nrecv + 1, HYPRE_MEMORY_HOST);
    HYPRE_Int *send_procs = hypre_CTAlloc(HYPRE_Int, nsend + 1, HYPRE_MEMORY_HOST);
    HYPRE_Int *send_starts = hypre_CTAlloc(HYPRE_Int, nsend + 1, HYPRE_MEMORY_HOST);
    HYPRE_Int *send_elmts = hypre_CTAlloc(HYPRE_Int, h->nsend + 1, HYPRE_MEMORY_HOST);
    if (!recv_procs || !recv_starts || !send_procs || !send_starts || !send_elmts)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for the fine level's halo (%d values)",
                      (int)h->nsend);
    if (mf_hypre_agree("PCG_BoomerAMG", rc) == 0) {
        int q = 0;
        for (int p = 0; p < nprocs; p++)
            if (h->recv_counts[p] > 0) {
                recv_procs[q] = p;
                recv_starts[++q] = h->recv_displs[p] + h->recv_counts[p];
            }
        q = 0;
        for (int p = 0; p < nprocs; p++)
            if (h->send_counts[p] > 0) {
                send_procs[q] = p;
                send_starts[++q] = h->send_displs[p] + h->send_counts[p];
            }
        for (int32_t k = 0; k < h->nsend; k++)
            send_elmts[k] = (HYPRE_Int)ps->slot[h->send_rows[k]];
        hypre_ParCSRCommPkgCreateAndFill(MPI_COMM_WORLD, nrecv, recv_procs, recv_starts, nsend,
                                         send_procs, send_starts, send_elmts, &F->pkg);
        F->own_pkg = true;
        F->nsend = h->nsend;
        F->send = malloc(((size_t)h->nsend + 1) * sizeof *F->send);
        F->halo = calloc((size_t)h->n + 1, sizeof *F->halo);
        if (!F->send || !F->halo)
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for a halo of %d values", (int)h->n);
    } else {
        hypre_TFree(recv_procs, HYPRE_MEMORY_HOST);
        hypre_TFree(recv_starts, HYPRE_MEMORY_HOST);
        hypre_TFree(send_procs, HYPRE_MEMORY_HOST);
        hypre_TFree(send_starts, HYPRE_MEMORY_HOST);
        hypre_TFree(send_elmts, HYPRE_MEMORY_HOST);
    }
    rc = mf_hypre_agree("PCG_BoomerAMG", rc);
out:
    free(row_of);
    return rc;
}

static double global_sum(double local)
{
    double sum = 0.0;
    MPI_Allreduce(&local, &sum, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    return sum;
}

/* q = A p on the fine level; returns p . q over the ranks. */
static double matvec_dot(par_block *A, const double *p, double *q)
{
    halo_fetch(A, p);
    double pq = 0.0;
    for (int32_t i = 0; i < A->n; i++) {
        const double qi = mf_split_csr_matvec_dot_row(&A->D, i, p) + offd_dot(A, i);
        q[i] = qi;
        pq += p[i] * qi;
    }
    return global_sum(pq);
}

/* r = b - A x; returns ||r|| over the ranks. */
static double residual(par_block *A, const double *b, const double *x, double *r)
{
    halo_fetch(A, x);
    double rr = 0.0;
    for (int32_t i = 0; i < A->n; i++) {
        r[i] = b[i] - mf_split_csr_matvec_dot_row(&A->D, i, x) - offd_dot(A, i);
        rr += r[i] * r[i];
    }
    return sqrt(global_sum(rr));
}

static double *local_data(HYPRE_ParVector x)
{
    return hypre_VectorData(hypre_ParVectorLocalVector((hypre_ParVector *)x));
}

static int reserve_work(mf_amg_par *v, size_t n)
{
    if (n <= v->work_n && v->work[0])
        return 0;
    for (int k = 0; k < 4; k++) {
        free(v->work[k]);
        v->work[k] = malloc((n + 1) * sizeof(double));
    }
    v->work_n = n;
    if (!v->work[0] || !v->work[1] || !v->work[2] || !v->work[3]) {
        v->work_n = 0;
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the PCG vectors (%zu rows)", n);
    }
    return 0;
}

int mf_amg_par_apply(mf_amg_par *v, HYPRE_ParCSRMatrix A, HYPRE_ParVector r, HYPRE_ParVector z)
{
    const char *why = NULL;
    MF_CALL(set_fine(v, (hypre_ParCSRMatrix *)A, &why));
    if (why)
        return MF_ERROR(MF_ERR_INPUT, "PCG_BoomerAMG: %s", why);
    cycle(v, local_data(r), local_data(z));
    block_free(&v->lev[0].A);
    return 0;
}

static int pcg_run(mf_amg_par *v, const double *b, double *x, double bnorm, double tol,
                   long max_iter, int *iterations, double *rel)
{
    par_block *A = &v->lev[0].A;
    const size_t n = (size_t)A->n;
    MF_CALL(mf_hypre_agree("PCG_BoomerAMG", reserve_work(v, n)));
    double *r = v->work[0], *z = v->work[1], *p = v->work[2], *q = v->work[3];
    const double stop = tol * bnorm, stop2 = stop * stop;
    residual(A, b, x, r);
    cycle(v, r, z);
    double gamma = 0.0;
    for (size_t i = 0; i < n; i++) {
        p[i] = z[i];
        gamma += r[i] * z[i];
    }
    gamma = global_sum(gamma);
    for (long it = 1; it <= max_iter; it++) {
        *iterations = (int)it;
        const double pq = matvec_dot(A, p, q);
        if (!(pq > 0.0) || !(gamma > 0.0))
            break; /* A or M not positive definite (or NaN), the same on every rank */
        const double alpha = gamma / pq;
        double rr = 0.0;
        for (size_t i = 0; i < n; i++) {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
            rr += r[i] * r[i];
        }
        if (global_sum(rr) <= stop2) {
            /* Tentatively converged: the true residual decides. */
            const double t = residual(A, b, x, r);
            if (t <= stop) {
                *rel = t / bnorm;
                return 0;
            }
        }
        cycle(v, r, z);
        double g = 0.0;
        for (size_t i = 0; i < n; i++)
            g += r[i] * z[i];
        g = global_sum(g);
        const double beta = g / gamma;
        gamma = g;
        for (size_t i = 0; i < n; i++)
            p[i] = z[i] + beta * p[i];
    }
    *rel = residual(A, b, x, r) / bnorm;
    return MF_RETRY;
}

int mf_amg_par_pcg_rows(mf_amg_par *v, const mf_csr *A, const mf_par_slots *ps, const double *b,
                        double *x, double bnorm, double tol, long max_iter, int *iterations,
                        double *rel, const char **why)
{
    *iterations = 0;
    *rel = NAN;
    par_block *F = &v->lev[0].A;
    block_free(F);
    MF_CALL(build_rows_block(F, A, ps));
    const bool fits = mf_hypre_all(F->n == v->lev[0].P.n);
    *why = !fits ? "a system of other rows than the hierarchy's"
           : !diag_positive(&F->D) ? "a diagonal entry of the matrix is not positive"
                                   : NULL;
    int rc = 0;
    if (*why == NULL) {
        const size_t n = (size_t)F->n;
        double *bs = calloc(n + 1, sizeof *bs), *xs = calloc(n + 1, sizeof *xs);
        rc = bs && xs ? 0 : MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu slots", n);
        rc = mf_hypre_agree("PCG_BoomerAMG", rc);
        if (rc == 0) {
            for (size_t r = 0; r < A->nrows; r++) {
                bs[ps->slot[r]] = b[r];
                xs[ps->slot[r]] = x[r];
            }
            rc = pcg_run(v, bs, xs, bnorm, tol, max_iter, iterations, rel);
            for (size_t r = 0; r < A->nrows; r++)
                x[r] = xs[ps->slot[r]];
        }
        free(bs);
        free(xs);
    }
    block_free(F);
    return rc;
}

int mf_amg_par_pcg(mf_amg_par *v, HYPRE_ParCSRMatrix A, HYPRE_ParVector b, HYPRE_ParVector x,
                   double bnorm, double tol, long max_iter, int *iterations, double *rel,
                   const char **why)
{
    *iterations = 0;
    *rel = NAN;
    MF_CALL(set_fine(v, (hypre_ParCSRMatrix *)A, why));
    int rc = 0;
    if (*why == NULL)
        rc = pcg_run(v, local_data(b), local_data(x), bnorm, tol, max_iter, iterations, rel);
    /* The fine level goes with the solve (its matrix does). */
    block_free(&v->lev[0].A);
    return rc;
}
