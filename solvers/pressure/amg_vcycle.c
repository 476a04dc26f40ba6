/* amg_vcycle.c: the V-cycle and the PCG of amg_vcycle.h (one rank). */
#define MF_PRESSURE_HYPRE_INTERNAL
#include "pressure_hypre.h"

#include "amg_vcycle.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* hypre's internal header (installed by libhypre-dev): the AMG data
 * structure whose levels the copy reads. Its inline helpers have unused
 * parameters. */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <_hypre_parcsr_ls.h>
#pragma GCC diagnostic pop

#include "mf_error.h"
#include "row_dot.h"

/* ---- the split matrix -------------------------------------------------- */

/* Columns and values with room for need + 1 entries: grown when *cap is
 * below need or nothing is there yet (*cap then need). False when out of
 * memory (what was there stays, *cap unchanged). */
static bool grow_entries(int32_t **col, double **val, size_t *cap, size_t need)
{
    if (need <= *cap && *col != NULL)
        return true;
    int32_t *c = realloc(*col, (need + 1) * sizeof *c);
    if (c)
        *col = c;
    double *v = realloc(*val, (need + 1) * sizeof *v);
    if (v)
        *val = v;
    if (!c || !v)
        return false;
    *cap = need;
    return true;
}

static int split_reserve(mf_split_csr *s, size_t n, size_t nnz)
{
    if (n > s->cap_rows) {
        int32_t *ptr = realloc(s->ptr, (n + 1) * sizeof *ptr);
        if (ptr)
            s->ptr = ptr;
        int32_t *mid = realloc(s->mid, (n + 1) * sizeof *mid);
        if (mid)
            s->mid = mid;
        double *diag = realloc(s->diag, (n + 1) * sizeof *diag);
        if (diag)
            s->diag = diag;
        double *dinv = realloc(s->dinv, (n + 1) * sizeof *dinv);
        if (dinv)
            s->dinv = dinv;
        if (!ptr || !mid || !diag || !dinv)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for a matrix of %zu rows", n);
        s->cap_rows = n;
    }
    if (!grow_entries(&s->col_buf, &s->val_buf, &s->cap_nnz, nnz))
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for a matrix of %zu non-zeros", nnz);
    return 0;
}

int mf_split_csr_reserve(mf_split_csr *s, size_t n, size_t nnz)
{
    if (n > INT32_MAX || nnz > INT32_MAX)
        return MF_ERROR(MF_ERR_INPUT, "a matrix of %zu rows and %zu non-zeros is too large for "
                        "32-bit indices", n, nnz);
    MF_CALL(split_reserve(s, n, nnz));
    s->col = s->col_buf;
    s->val = s->val_buf;
    s->gap = 0;
    s->lent = NULL;
    s->n = (int32_t)n;
    return 0;
}

int mf_split_csr_set(mf_split_csr *s, const mf_csr *A)
{
    const size_t n = A->nrows;
    const size_t nnz = n > 0 ? A->rowptr[n] - A->rowptr[0] : 0;
    if (n > INT32_MAX || nnz > INT32_MAX)
        return MF_ERROR(MF_ERR_INPUT, "a matrix of %zu rows and %zu non-zeros is too large for "
                        "32-bit indices", n, nnz);
    MF_CALL(split_reserve(s, n, nnz));
    int32_t *scol = s->col_buf;
    double *sval = s->val_buf;
    s->col = scol;
    s->val = sval;
    s->gap = 0;
    const size_t *rp = A->rowptr;
    const size_t k0 = n > 0 ? rp[0] : 0;
    const int32_t *col = A->col + k0;
    const double *val = A->val + k0;
    int32_t k = 0;
    s->ptr[0] = 0;
    for (int32_t i = 0; i < (int32_t)n; i++) {
        double d = 0.0;
        for (size_t e = rp[i] - k0; e < rp[i + 1] - k0; e++) {
            const int32_t c = col[e];
            if (c == i)
                d += val[e];
            else if (c < i) {
                scol[k] = c;
                sval[k++] = val[e];
            }
        }
        s->mid[i] = k;
        for (size_t e = rp[i] - k0; e < rp[i + 1] - k0; e++) {
            const int32_t c = col[e];
            if (c > i) {
                scol[k] = c;
                sval[k++] = val[e];
            }
        }
        s->ptr[i + 1] = k;
        s->diag[i] = d;
        s->dinv[i] = d != 0.0 ? 1.0 / d : 0.0;
    }
    s->n = (int32_t)n;
    return 0;
}

/* Row i of A as the view wants it (its diagonal first and only there, then
 * columns below i, then above): mid = where those above begin; -1 if not. */
static int64_t split_row_mid(const int32_t *col, size_t begin, size_t end, int32_t i)
{
    if (begin == end || col[begin] != i)
        return -1;
    size_t e = begin + 1;
    while (e < end && col[e] < i)
        e++;
    const size_t mid = e;
    while (e < end && col[e] > i)
        e++;
    return e == end ? (int64_t)mid : -1;
}

/* Room for the in-place split's bits and one row. */
static int split_reserve_lent(mf_split_csr *s, size_t nnz, size_t longest)
{
    const size_t words = nnz / 64 + 2;
    if (words > s->cap_upper) {
        uint64_t *u = realloc(s->upper, words * sizeof *u);
        if (u == NULL)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory splitting %zu non-zeros", nnz);
        s->upper = u;
        s->cap_upper = words;
    }
    if (!grow_entries(&s->row_buf, &s->row_val, &s->cap_row, longest + 1))
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for a row of %zu entries", longest);
    return 0;
}

/* Bit k of the upper marks (set: entry k, counted from the matrix's first,
 * is above the diagonal). */
static inline bool is_upper(const uint64_t *upper, size_t k)
{
    return (upper[k / 64] >> (k % 64)) & 1;
}

/* Row i's off-diagonal entries [b, e) of A (relative to col, val): lower
 * ones first, then upper ones, each in their order, the marks set. Returns
 * where the upper ones start; *twice set when the diagonal was among them. */
static int64_t split_row_in_place(mf_split_csr *s, int32_t *col, double *val, size_t b,
                                  size_t e, int32_t i, bool *twice)
{
    size_t w = b, nu = 0;
    for (size_t k = b; k < e; k++) {
        const int32_t c = col[k];
        *twice |= c == i;
        if (c < i) {
            s->upper[k / 64] &= ~(UINT64_C(1) << (k % 64));
            col[w] = c;
            val[w++] = val[k];
        } else {
            s->upper[k / 64] |= UINT64_C(1) << (k % 64);
            s->row_buf[nu] = c;
            s->row_val[nu++] = val[k];
        }
    }
    memcpy(col + w, s->row_buf, nu * sizeof *col);
    memcpy(val + w, s->row_val, nu * sizeof *val);
    return (int64_t)w;
}

/* split_row_in_place's inverse. */
static void merge_row_in_place(mf_split_csr *s, int32_t *col, double *val, size_t b, size_t mid,
                               size_t e)
{
    /* The upper ones aside, then lower ones moved back to their places from
     * the end (a lower entry only moves right), the upper ones between. */
    const size_t nu = e - mid;
    memcpy(s->row_buf, col + mid, nu * sizeof *col);
    memcpy(s->row_val, val + mid, nu * sizeof *val);
    size_t lo = mid, up = nu;
    for (size_t k = e; k-- > b;) {
        if (is_upper(s->upper, k)) {
            up--;
            col[k] = s->row_buf[up];
            val[k] = s->row_val[up];
        } else {
            lo--;
            col[k] = col[lo];
            val[k] = val[lo];
        }
    }
}

void mf_split_csr_restore(mf_split_csr *s)
{
    const mf_csr *A = s->lent;
    if (A == NULL)
        return;
    const size_t *rp = A->rowptr;
    const size_t k0 = rp[0];
    for (size_t i = 0; i < A->nrows; i++)
        merge_row_in_place(s, A->col + k0, A->val + k0, rp[i] + 1 - k0, (size_t)s->mid[i],
                           rp[i + 1] - k0);
    s->lent = NULL;
}

/* Split A's rows in its lent arrays; false (A as it was) when a row does
 * not lead with its diagonal or holds it twice. */
static bool split_lent(mf_split_csr *s, const mf_csr *A)
{
    const size_t *rp = A->rowptr;
    const size_t k0 = rp[0];
    int32_t *col = A->col + k0;
    double *val = A->val + k0;
    for (size_t i = 0; i < A->nrows; i++) {
        const size_t b = rp[i] - k0, e = rp[i + 1] - k0;
        bool twice = false;
        int64_t mid = b < e && col[b] == (int32_t)i
                          ? split_row_in_place(s, col, val, b + 1, e, (int32_t)i, &twice)
                          : -1;
        if (twice) { /* a second diagonal entry: this row back first */
            s->mid[i] = (int32_t)mid;
            merge_row_in_place(s, col, val, b + 1, (size_t)mid, e);
            mid = -1;
        }
        if (mid < 0) {
            for (size_t r = 0; r < i; r++)
                merge_row_in_place(s, col, val, rp[r] + 1 - k0, (size_t)s->mid[r],
                                   rp[r + 1] - k0);
            return false;
        }
        s->mid[i] = (int32_t)mid;
    }
    return true;
}

int mf_split_csr_fine(mf_split_csr *s, const mf_csr *A)
{
    const size_t n = A->nrows;
    const size_t nnz = n > 0 ? A->rowptr[n] - A->rowptr[0] : 0;
    s->lent = NULL;
    if (n == 0 || n > INT32_MAX || nnz >= INT32_MAX)
        return mf_split_csr_set(s, A);
    const size_t *rp = A->rowptr;
    const size_t k0 = rp[0];
    /* Split in the lent arrays; else a view when the rows are already
     * split, or a copy. */
    bool lent = false;
    if (A->lent_capacity > 0) {
        size_t longest = 0;
        for (size_t i = 0; i < n; i++)
            if (rp[i + 1] - rp[i] > longest)
                longest = rp[i + 1] - rp[i];
        MF_CALL(split_reserve_lent(s, nnz, longest));
        MF_CALL(split_reserve(s, n, 0));
        lent = split_lent(s, A);
    }
    if (!lent) {
        for (size_t i = 0; i < n; i++)
            if (split_row_mid(A->col, rp[i], rp[i + 1], (int32_t)i) < 0)
                return mf_split_csr_set(s, A);
        MF_CALL(split_reserve(s, n, 0));
        for (size_t i = 0; i < n; i++)
            s->mid[i] = (int32_t)(split_row_mid(A->col, rp[i], rp[i + 1], (int32_t)i) -
                                  (int64_t)k0);
    }
    s->lent = lent ? A : NULL;
    s->col = A->col + k0;
    s->val = A->val + k0;
    s->gap = 1;
    for (size_t i = 0; i < n; i++) {
        /* the copy's diagonal: 0 + the one entry (the same bits but for a -0) */
        const double d = 0.0 + A->val[rp[i]];
        s->ptr[i] = (int32_t)(rp[i] - k0 + 1);
        s->diag[i] = d;
        s->dinv[i] = d != 0.0 ? 1.0 / d : 0.0;
    }
    s->ptr[n] = (int32_t)(rp[n] - k0 + 1);
    s->n = (int32_t)n;
    return 0;
}

void mf_split_csr_free(mf_split_csr *s)
{
    mf_split_csr_restore(s);
    free(s->upper);
    free(s->row_buf);
    free(s->row_val);
    free(s->ptr);
    free(s->mid);
    free(s->col_buf);
    free(s->val_buf);
    free(s->diag);
    free(s->dinv);
    memset(s, 0, sizeof *s);
}

double mf_split_csr_matvec_dot(const mf_split_csr *A, const double *p, double *q)
{
    double pq = 0.0;
    for (int32_t i = 0; i < A->n; i++) {
        const int32_t k = A->ptr[i];
        const double qi =
            A->diag[i] * p[i] + mf_row_dot(A->col + k, A->val + k, (size_t)(mf_split_end(A, i) - k), p);
        q[i] = qi;
        pq += p[i] * qi;
    }
    return pq;
}

/* ---- the hierarchy ----------------------------------------------------- */

typedef struct amg_level {
    mf_split_csr A;             /* levels 1 .. nlevels - 1 (level 0: the solve's) */
    int32_t *pptr, *pcol;       /* interpolation to this level from the next coarser */
    double *pval;
    double *f, *u;              /* levels 1 .. nlevels - 1 */
    int32_t n;                  /* rows (level 0: the rows of the first interpolation) */
} amg_level;

struct mf_amg_vcycle {
    int nlevels;
    amg_level *lev;
    int nc;            /* rows of the coarsest level */
    double *lu;        /* its LU factors (column-major, nc x nc) */
    int *ipiv;
    mf_split_csr fine; /* the matrix of the current solve */
    double *work[3];   /* PCG vectors (z, p, q) */
    size_t work_n;
};

void mf_amg_vcycle_free(mf_amg_vcycle *v)
{
    if (v == NULL)
        return;
    for (int l = 0; l < v->nlevels; l++) {
        amg_level *L = &v->lev[l];
        mf_split_csr_free(&L->A);
        free(L->pptr);
        free(L->pcol);
        free(L->pval);
        free(L->f);
        free(L->u);
    }
    free(v->lev);
    mf_split_csr_free(&v->fine);
    free(v->lu);
    free(v->ipiv);
    for (int k = 0; k < 3; k++)
        free(v->work[k]);
    free(v);
}

/* The cycle hypre would run is the one written here: a V-cycle with one
 * sweep of relaxType 3 down and 4 up, Gaussian elimination on the coarsest
 * level, weights 1, all points relaxed in order, R = P^T, no additive or
 * smoother variants. */
bool mf_amg_cycle_is_ours(HYPRE_Solver amg)
{
    hypre_ParAMGData *d = (hypre_ParAMGData *)amg;
    const HYPRE_Int *type = hypre_ParAMGDataGridRelaxType(d);
    const HYPRE_Int *sweeps = hypre_ParAMGDataNumGridSweeps(d);
    if (type == NULL || sweeps == NULL || type[1] != 3 || type[2] != 4 || type[3] != 9 ||
        sweeps[1] != 1 || sweeps[2] != 1 || sweeps[3] != 1)
        return false;
    if (hypre_ParAMGDataCycleType(d) != 1 || hypre_ParAMGDataFCycle(d) != 0 ||
        hypre_ParAMGDataRelaxOrder(d) != 0 || hypre_ParAMGDataSmoothNumLevels(d) != 0 ||
        hypre_ParAMGDataRestriction(d) != 0 || hypre_ParAMGDataBlockMode(d) != 0 ||
        hypre_ParAMGDataAdditive(d) >= 0 || hypre_ParAMGDataMultAdditive(d) >= 0 ||
        hypre_ParAMGDataSimple(d) >= 0 || hypre_ParAMGDataSeqThreshold(d) > 0 ||
        hypre_ParAMGDataPartialCycleCoarsestLevel(d) >= 0)
        return false;
    HYPRE_Int **points = hypre_ParAMGDataGridRelaxPoints(d);
    if (points != NULL)
        for (int c = 1; c <= 3; c++)
            if (points[c] != NULL && points[c][0] != 0)
                return false;
    const HYPRE_Real *w = hypre_ParAMGDataRelaxWeight(d), *om = hypre_ParAMGDataOmega(d);
    for (int l = 0; l < hypre_ParAMGDataNumLevels(d); l++)
        if ((w && w[l] != 1.0) || (om && om[l] != 1.0))
            return false;
    return true;
}

static int copy_interp(amg_level *L, hypre_ParCSRMatrix *P)
{
    hypre_CSRMatrix *D = hypre_ParCSRMatrixDiag(P);
    const HYPRE_Int n = hypre_CSRMatrixNumRows(D);
    const HYPRE_Int *I = hypre_CSRMatrixI(D), *J = hypre_CSRMatrixJ(D);
    const HYPRE_Real *V = hypre_CSRMatrixData(D);
    const HYPRE_Int nnz = I[n];
    L->n = n;
    L->pptr = malloc(((size_t)n + 1) * sizeof *L->pptr);
    L->pcol = malloc(((size_t)nnz + 1) * sizeof *L->pcol);
    L->pval = malloc(((size_t)nnz + 1) * sizeof *L->pval);
    if (!L->pptr || !L->pcol || !L->pval)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory copying an interpolation of %d rows", n);
    for (HYPRE_Int i = 0; i <= n; i++)
        L->pptr[i] = I[i] - I[0];
    for (HYPRE_Int k = 0; k < nnz - I[0]; k++) {
        L->pcol[k] = J[I[0] + k];
        L->pval[k] = V[I[0] + k];
    }
    return 0;
}

int mf_amg_copy_diag(mf_split_csr *s, HYPRE_ParCSRMatrix par)
{
    hypre_ParCSRMatrix *A = (hypre_ParCSRMatrix *)par;
    hypre_CSRMatrix *D = hypre_ParCSRMatrixDiag(A);
    const HYPRE_Int n = hypre_CSRMatrixNumRows(D);
    const HYPRE_Int *I = hypre_CSRMatrixI(D);
    size_t *rp = malloc(((size_t)n + 1) * sizeof *rp);
    if (rp == NULL)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory copying a level of %d rows", n);
    for (HYPRE_Int i = 0; i <= n; i++)
        rp[i] = (size_t)I[i];
    const mf_csr c = {.nrows = (size_t)n, .nglobal = n, .rowptr = rp,
                      .col = hypre_CSRMatrixJ(D), .val = hypre_CSRMatrixData(D)};
    int rc = mf_split_csr_set(s, &c);
    free(rp);
    return rc;
}

int mf_amg_vcycle_take(HYPRE_Solver amg, mf_amg_vcycle **out)
{
    _Static_assert(sizeof(HYPRE_Int) == sizeof(int32_t) && sizeof(HYPRE_Real) == sizeof(double),
                   "the copy takes hypre's arrays as int32_t and double");
    hypre_ParAMGData *d = (hypre_ParAMGData *)amg;
    *out = NULL;
    const int nlevels = hypre_ParAMGDataNumLevels(d);
    if (nlevels < 2 || !mf_amg_cycle_is_ours(amg))
        return 0;
    hypre_ParCSRMatrix **A = hypre_ParAMGDataAArray(d), **P = hypre_ParAMGDataPArray(d);
    /* Level 0 is the caller's matrix (not read here: it may be gone). */
    for (int l = 0; l < nlevels; l++) {
        if ((l > 0 && hypre_CSRMatrixNumNonzeros(hypre_ParCSRMatrixOffd(A[l])) != 0) ||
            (l + 1 < nlevels && hypre_CSRMatrixNumNonzeros(hypre_ParCSRMatrixOffd(P[l])) != 0))
            return 0; /* several ranks */
    }
    const int nc = hypre_CSRMatrixNumRows(hypre_ParCSRMatrixDiag(A[nlevels - 1]));
    if (nc < 1 || nc > MF_AMG_MAX_COARSEST)
        return 0;

    int rc = 0;
    mf_amg_vcycle *v = calloc(1, sizeof *v);
    if (v == NULL || (v->lev = calloc((size_t)nlevels, sizeof *v->lev)) == NULL) {
        free(v);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory copying an AMG hierarchy");
    }
    v->nlevels = nlevels;
    for (int l = 0; l < nlevels; l++) {
        amg_level *L = &v->lev[l];
        if (l + 1 < nlevels) {
            MF_CALL_GOTO(rc, copy_interp(L, P[l]), fail);
            /* hypre's copy goes as soon as ours is made, so that the two
             * hierarchies are not held whole at once (hypre_BoomerAMGDestroy
             * skips the NULL entries). */
            hypre_ParCSRMatrixDestroy(P[l]);
            P[l] = NULL;
        }
        if (l > 0) {
            MF_CALL_GOTO(rc, mf_amg_copy_diag(&L->A, (HYPRE_ParCSRMatrix)A[l]), fail);
            hypre_ParCSRMatrixDestroy(A[l]);
            A[l] = NULL;
            L->n = L->A.n;
            L->f = malloc(((size_t)L->n + 1) * sizeof *L->f);
            L->u = malloc(((size_t)L->n + 1) * sizeof *L->u);
            if (!L->f || !L->u) {
                rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for the AMG work vectors");
                goto fail;
            }
        }
    }

    /* The coarsest level, dense, factorised once. */
    v->nc = nc;
    v->lu = calloc((size_t)nc * nc, sizeof *v->lu);
    v->ipiv = malloc((size_t)nc * sizeof *v->ipiv);
    if (!v->lu || !v->ipiv) {
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for the coarsest AMG level (%d rows)", nc);
        goto fail;
    }
    {
        const mf_split_csr *C = &v->lev[nlevels - 1].A;
        for (int i = 0; i < nc; i++) {
            v->lu[(size_t)i * nc + i] = C->diag[i];
            for (int32_t k = C->ptr[i]; k < C->ptr[i + 1]; k++)
                v->lu[(size_t)C->col[k] * nc + i] = C->val[k]; /* column-major: (i, col) */
        }
        int info = 0;
        dgetrf_(&nc, &nc, v->lu, &nc, v->ipiv, &info);
        if (info != 0) { /* singular: leave it to hypre's cycle */
            mf_amg_vcycle_free(v);
            return 0;
        }
    }
    *out = v;
    return 0;
fail:
    mf_amg_vcycle_free(v);
    return rc;
}

/* ---- the cycle ----------------------------------------------------------- */

/* Forward Gauss-Seidel from u = 0: u_i = (f_i - sum_{j<i} a_ij u_j) / a_ii
 * (the entries right of the diagonal meet zeros). */
static void sweep_down_from_zero(const mf_split_csr *A, const double *f, double *u)
{
    for (int32_t i = 0; i < A->n; i++) {
        const int32_t k = A->ptr[i];
        u[i] = (f[i] - mf_row_dot(A->col + k, A->val + k, (size_t)(A->mid[i] - k), u)) *
               A->dinv[i];
    }
}

/* fc = P^T (f - A u) after sweep_down_from_zero, where f - A u = -U u. */
static void restrict_residual(const mf_split_csr *A, const amg_level *L, const int64_t *prow,
                              const double *u, double *fc, int32_t nc)
{
    memset(fc, 0, (size_t)nc * sizeof *fc);
    for (int32_t i = 0; i < A->n; i++) {
        const int32_t m = A->mid[i];
        const double res = -mf_row_dot(A->col + m, A->val + m, (size_t)(mf_split_end(A, i) - m), u);
        const int64_t pr = prow ? prow[i] : i;
        for (int32_t k = L->pptr[pr]; k < L->pptr[pr + 1]; k++)
            fc[L->pcol[k]] += L->pval[k] * res;
    }
}

/* u += P uc. */
static void interpolate(const mf_split_csr *A, const amg_level *L, const int64_t *prow,
                        const double *uc, double *u)
{
    for (int32_t i = 0; i < A->n; i++) {
        const int64_t pr = prow ? prow[i] : i;
        const int32_t k = L->pptr[pr];
        u[i] += mf_row_dot(L->pcol + k, L->pval + k, (size_t)(L->pptr[pr + 1] - k), uc);
    }
}

/* Backward Gauss-Seidel: u_i += (f_i - sum_j a_ij u_j) / a_ii, i descending. */
static void sweep_up(const mf_split_csr *A, const double *f, double *u)
{
    for (int32_t i = A->n - 1; i >= 0; i--) {
        const int32_t k = A->ptr[i];
        const double res = f[i] - A->diag[i] * u[i] -
                           mf_row_dot(A->col + k, A->val + k, (size_t)(mf_split_end(A, i) - k), u);
        u[i] += res * A->dinv[i];
    }
}

void mf_amg_vcycle_apply(mf_amg_vcycle *v, const mf_split_csr *A0, const int64_t *prow,
                         const double *r, double *z)
{
    const int nl = v->nlevels;
    for (int l = 0; l + 1 < nl; l++) {
        const mf_split_csr *A = l == 0 ? A0 : &v->lev[l].A;
        const double *f = l == 0 ? r : v->lev[l].f;
        double *u = l == 0 ? z : v->lev[l].u;
        sweep_down_from_zero(A, f, u);
        restrict_residual(A, &v->lev[l], l == 0 ? prow : NULL, u, v->lev[l + 1].f,
                          v->lev[l + 1].n);
    }
    amg_level *C = &v->lev[nl - 1];
    memcpy(C->u, C->f, (size_t)v->nc * sizeof *C->u);
    const int one = 1;
    int info = 0;
    dgetrs_("N", &v->nc, &one, v->lu, &v->nc, v->ipiv, C->u, &v->nc, &info);
    for (int l = nl - 2; l >= 0; l--) {
        const mf_split_csr *A = l == 0 ? A0 : &v->lev[l].A;
        const double *f = l == 0 ? r : v->lev[l].f;
        double *u = l == 0 ? z : v->lev[l].u;
        interpolate(A, &v->lev[l], l == 0 ? prow : NULL, v->lev[l + 1].u, u);
        sweep_up(A, f, u);
    }
}

/* ---- PCG ------------------------------------------------------------------ */

static int pcg_run(mf_amg_vcycle *v, const mf_csr *A_in, const int64_t *prow, double *x,
                   double *r, double bnorm, double tol, long max_iter, mf_residual_fn resid,
                   const void *ctx, int *iterations, double *rel)
{
    const size_t n = A_in->nrows;
    *iterations = 0;
    *rel = NAN;
    if (prow == NULL ? (int64_t)n != v->lev[0].n : (int64_t)n > v->lev[0].n)
        return MF_ERROR(MF_ERR_INTERNAL,
                        "a system of %zu rows for an AMG hierarchy set up for %d", n,
                        (int)v->lev[0].n);
    MF_CALL(mf_split_csr_fine(&v->fine, A_in));
    const mf_split_csr *A = &v->fine;
    if (n > v->work_n) {
        for (int k = 0; k < 3; k++) {
            free(v->work[k]);
            v->work[k] = malloc((n + 1) * sizeof(double));
        }
        v->work_n = n;
        if (!v->work[0] || !v->work[1] || !v->work[2]) {
            v->work_n = 0;
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for the PCG vectors (%zu rows)", n);
        }
    }
    double *z = v->work[0], *p = v->work[1], *q = v->work[2];
    const double stop = tol * bnorm, stop2 = stop * stop;

    mf_amg_vcycle_apply(v, A, prow, r, z);
    double gamma = 0.0;
    for (size_t i = 0; i < n; i++) {
        p[i] = z[i];
        gamma += r[i] * z[i];
    }
    for (long it = 1; it <= max_iter; it++) {
        *iterations = (int)it;
        const double pq = mf_split_csr_matvec_dot(A, p, q);
        if (!(pq > 0.0) || !(gamma > 0.0))
            break; /* A or M not positive definite (or NaN): stop, say so below */
        const double alpha = gamma / pq;
        double rr = 0.0;
        for (size_t i = 0; i < n; i++) {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
            rr += r[i] * r[i];
        }
        if (rr <= stop2) {
            /* Tentatively converged: decide on the true residual (from
             * the caller's rows, in their order). */
            mf_split_csr_restore(&v->fine);
            const double t = resid(ctx, x, r);
            if (t <= stop) {
                *rel = t / bnorm;
                return 0;
            }
            MF_CALL(mf_split_csr_fine(&v->fine, A_in));
        }
        mf_amg_vcycle_apply(v, A, prow, r, z);
        double g = 0.0;
        for (size_t i = 0; i < n; i++)
            g += r[i] * z[i];
        const double beta = g / gamma;
        gamma = g;
        for (size_t i = 0; i < n; i++)
            p[i] = z[i] + beta * p[i];
    }
    mf_split_csr_restore(&v->fine);
    *rel = resid(ctx, x, r) / bnorm;
    return MF_RETRY;
}

int mf_amg_pcg(mf_amg_vcycle *v, const mf_csr *A, const int64_t *prow, double *x, double *r,
               double bnorm, double tol, long max_iter, mf_residual_fn resid, const void *ctx,
               int *iterations, double *rel)
{
    int rc = pcg_run(v, A, prow, x, r, bnorm, tol, max_iter, resid, ctx, iterations, rel);
    /* The fine level's copy goes with the solve: kept, it would sit beside
     * the next step's matrix while that is assembled (peak memory). A split
     * in the caller's arrays is undone first (mf_split_csr_free). */
    mf_split_csr_free(&v->fine);
    return rc;
}
