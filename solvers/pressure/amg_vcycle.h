/* amg_vcycle.h: a V-cycle of our own over a hierarchy that hypre's BoomerAMG
 * set up, and the PCG around it, for a solve on one MPI rank (amg_vcycle.c)
 * and on several (amg_vcycle_par.c, declared at the end).
 *
 * Why: on one rank the solve phase of hypre's PCG + BoomerAMG spends its time
 * in loops that add one product at a time into one sum (the matrix-vector
 * product, the Gauss-Seidel sweeps), so every non-zero waits for the addition
 * before it; it visits the fine matrix four times an iteration (the PCG
 * product, the sweep down, the residual, the sweep up) and applies the
 * preconditioner once more after the last iteration. Here the set-up stays
 * hypre's (coarsening, interpolation, the Galerkin products, everything that
 * makes AMG work) and the cycle is the same operator in exact arithmetic:
 *
 *  - the smoother of relaxType 3 on one rank: Gauss-Seidel, forward on the
 *    way down (from a zero guess, as a V-cycle correction starts), backward
 *    on the way up; Gaussian elimination (LAPACK's LU) on the coarsest level;
 *  - a forward sweep from zero leaves (D + L) u = f, so its residual is
 *    f - A u = -U u: the sweep reads the entries left of the diagonal, the
 *    residual those right of it, one pass over the matrix for both (Briggs,
 *    Henson and McCormick, "A Multigrid Tutorial", 2nd ed., SIAM 2000, on
 *    the residual after a Gauss-Seidel sweep);
 *  - the rows' sums use four partial sums, so the additions overlap.
 *
 * The fine level is the caller's matrix of this solve (rows in row space,
 * each mapped to its row of the first interpolation by its slot), copied
 * into the split layout for the solve and freed after it (or, when its rows
 * are already split, the diagonal first, read in place: mf_split_csr_fine);
 * the coarse levels and interpolations
 * are copies of hypre's, taken right after the set-up, hypre's freed as
 * they are copied.
 */
#ifndef MF_AMG_VCYCLE_H
#define MF_AMG_VCYCLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mf_modules.h"

/* LAPACK (Fortran interface): LU with partial pivoting of the coarsest
 * level, on one rank and (the same matrix on every rank) on N. */
extern void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv, int *info);
extern void dgetrs_(const char *trans, const int *n, const int *nrhs, const double *a,
                    const int *lda, const int *ipiv, double *b, const int *ldb, int *info);
#include "row_dot.h"

/* A square matrix by rows, the diagonal apart: the off-diagonal entries of
 * row i are [ptr[i], ptr[i + 1] - gap), those of columns below i first
 * ([ptr[i], mid[i])), then those above. A copy (mf_split_csr_set) owns
 * col and val and has gap 0; a view of a CSR whose rows are already split
 * (mf_split_csr_fine) reads the CSR's own arrays, each row's leading
 * diagonal entry the gap between one row's entries and the next's. */
typedef struct mf_split_csr {
    int32_t n;
    int32_t gap;
    int32_t *ptr, *mid;
    const int32_t *col;
    const double *val;
    double *diag, *dinv; /* dinv[i] = 1 / diag[i] (0 for a zero diagonal) */
    int32_t *col_buf;    /* a copy's own entries (col and val point here) */
    double *val_buf;
    size_t cap_rows, cap_nnz;
    /* Split in the lent arrays of a CSR (mf_csr.lent_capacity): bit k of
     * upper (one per off-diagonal entry, in the CSR's order) says whether
     * it lies above the diagonal, which is all mf_split_csr_restore needs
     * to put the rows back in their order. */
    const mf_csr *lent;
    uint64_t *upper;
    int32_t *row_buf;
    double *row_val;
    size_t cap_upper, cap_row;
} mf_split_csr;

/* End of row i's off-diagonal entries. */
static inline int32_t mf_split_end(const mf_split_csr *s, int32_t i)
{
    return s->ptr[i + 1] - s->gap;
}

/* Copy a CSR of one rank (columns in [0, n), any order, the diagonal
 * anywhere in its row, duplicates summed into it) into the split layout,
 * growing s's arrays as needed. */
int mf_split_csr_set(mf_split_csr *s, const mf_csr *A);
/* s as an empty copy of n rows with room for nnz off-diagonal entries, for
 * a caller that writes the split layout itself (ptr, mid, diag, dinv, and
 * the entries at col_buf, val_buf), as mf_split_csr_set would have: s->n
 * = n on return. */
int mf_split_csr_reserve(mf_split_csr *s, size_t n, size_t nnz);
/* The same layout without a copy when every row of A starts with its
 * diagonal (and has it once): when the rows are already split (lower
 * columns, then upper ones) s reads A's col and val; when A lends them
 * (mf_csr.lent_capacity, the MPS pressure matrix) each row is split in
 * them, to be put back by mf_split_csr_restore. Otherwise a copy
 * (mf_split_csr_set). The values and their order are the copy's either
 * way; A must outlive s. */
int mf_split_csr_fine(mf_split_csr *s, const mf_csr *A);
/* A split in place (mf_split_csr_fine) back to A's own order, bit for bit;
 * nothing for a copy or a view. s is then no longer good for a cycle until
 * split again. */
void mf_split_csr_restore(mf_split_csr *s);
void mf_split_csr_free(mf_split_csr *s);

/* Row i of A times p (the diagonal included). */
static inline double mf_split_csr_matvec_dot_row(const mf_split_csr *A, int32_t i, const double *p)
{
    const int32_t k = A->ptr[i];
    return A->diag[i] * p[i] +
           mf_row_dot(A->col + k, A->val + k, (size_t)(mf_split_end(A, i) - k), p);
}

/* q = A p; returns p . q. */
double mf_split_csr_matvec_dot(const mf_split_csr *A, const double *p, double *q);

typedef struct mf_amg_vcycle mf_amg_vcycle;

#ifdef MF_PRESSURE_HYPRE_INTERNAL
/* Take the hierarchy of an AMG solver hypre has set up (one rank, at least
 * two levels, a coarsest level of at most MF_AMG_MAX_COARSEST rows): copy
 * it, freeing hypre's coarse levels and interpolations as they are copied,
 * so that amg is then good for HYPRE_BoomerAMGDestroy only (the finest
 * level, the caller's matrix, is not read: it may be freed already).
 * Returns 0 with *out, or 0 with *out NULL when the hierarchy is not one
 * this cycle runs (the caller then uses hypre's cycle, set up again);
 * negative on a failure. The hierarchy's first interpolation has one row
 * per unknown of the set-up's matrix (a slot). */
int mf_amg_vcycle_take(HYPRE_Solver amg, mf_amg_vcycle **out);

/* Shared by the cycle on one rank and on N (amg_vcycle_par.c): whether the
 * cycle hypre set up is the one written here (relaxType 3 down, 4 up,
 * Gaussian elimination on the coarsest level, weights 1, R = P^T, ...);
 * and the copy of a level's diag part (hypre_ParCSRMatrixDiag: this rank's
 * rows and columns) into the split layout. */
bool mf_amg_cycle_is_ours(HYPRE_Solver amg);
int mf_amg_copy_diag(mf_split_csr *s, HYPRE_ParCSRMatrix A);

/* ---- the same cycle and PCG on N ranks (amg_vcycle_par.c) ----------------
 * Each level's matrix and interpolation as hypre holds them on this rank:
 * the diag block (split as above for the levels' matrices), the offd block
 * (columns of other ranks, col_map_offd) and the comm package that moves
 * their values (hypre_ParCSRMatrixCommPkg). The smoother is relaxType 3 on
 * N ranks: Gauss-Seidel within the rank's block, Jacobi across ranks (the
 * offd values exchanged before each sweep), forward from zero down,
 * backward up (a symmetric cycle); the residual after the down sweep is
 * -U u - A_offd u_halo; restriction P^T sends the offd contributions back
 * to their owners (the comm package's transpose, job 2); the coarsest level
 * is gathered on every rank (LU once a set-up, MPI_Allgatherv of its
 * right-hand side a cycle). The coarse levels and the interpolations are
 * read in hypre's hierarchy, which must outlive the cycle (it is kept
 * whole: the module keeps hypre's solver, whose solve is the fallback). */
typedef struct mf_amg_par mf_amg_par;

/* Collective: the cycle over amg's hierarchy, set up by hypre on every
 * rank. *out NULL and *why a reason (the same on every rank) when it is not
 * one this cycle runs; negative on a failure (agreed over the ranks). */
int mf_amg_par_take(HYPRE_Solver amg, mf_amg_par **out, const char **why);
void mf_amg_par_free(mf_amg_par *v);

/* Collective: PCG preconditioned by the cycle for the ParCSR matrix A of
 * this solve (the fine level: its row partition the first interpolation's),
 * b and x hypre's vectors of it (x: the initial guess in, the solution
 * out). Stops as mf_amg_pcg does: the recursion's residual says when to
 * look, the true ||b - A x|| <= tol * bnorm decides; MF_RETRY (no message)
 * when max_iter passed or the recursion broke down. *why non-NULL (and 0,
 * nothing done) when A's diagonal is not positive on some rank: the caller
 * then runs hypre's PCG. */
int mf_amg_par_pcg(mf_amg_par *v, HYPRE_ParCSRMatrix A, HYPRE_ParVector b, HYPRE_ParVector x,
                   double bnorm, double tol, long max_iter, int *iterations, double *rel,
                   const char **why);
/* The rows' slots over the ranks (hypre_common.c's slot space): this rank's
 * slot of each row, its slots [first, first + nslots) of hypre's rows, and
 * the other ranks' rows its rows read (the halo of columns, halo_columns.h:
 * the fine level's offd columns, in the halo's order, and its exchange
 * plan). */
typedef struct mf_par_slots {
    const int64_t *slot;
    int64_t nslots, first;
    const struct mf_halo_columns *halo;
} mf_par_slots;
/* Collective: mf_amg_par_pcg for the caller's rows A in slot space, the
 * fine level built from them without a hypre matrix (a kept hierarchy's
 * solve); b, x in the rows' order. */
int mf_amg_par_pcg_rows(mf_amg_par *v, const mf_csr *A, const mf_par_slots *ps, const double *b,
                        double *x, double bnorm, double tol, long max_iter, int *iterations,
                        double *rel, const char **why);
/* Collective: z = M r, one cycle (for the tests), with A as in mf_amg_par_pcg. */
int mf_amg_par_apply(mf_amg_par *v, HYPRE_ParCSRMatrix A, HYPRE_ParVector r, HYPRE_ParVector z);
#endif
#define MF_AMG_MAX_COARSEST 2000

void mf_amg_vcycle_free(mf_amg_vcycle *v);

/* z = M r, one V-cycle with the fine matrix A0, whose row i is row
 * prow[i] of the first interpolation (NULL: row i). */
void mf_amg_vcycle_apply(mf_amg_vcycle *v, const mf_split_csr *A0, const int64_t *prow,
                         const double *r, double *z);

/* PCG on one rank preconditioned by the V-cycle, for the matrix A of this
 * solve (one rank's CSR: columns in [0, nrows)), whose row i is row prow[i]
 * of the first interpolation (NULL: row i; prow's values distinct, inside
 * [0, the first interpolation's rows)). x holds the initial guess and
 * returns the solution, r holds r0 = b - A x0 on entry (the caller has it from the
 * initial residual) and is overwritten. The recursion's residual says when
 * to look; the true one, resid(ctx, x, r) = ||b - A x|| (also writing r,
 * from the caller's matrix), decides: 0 when it is at most tol ||b||,
 * MF_RETRY (no message) when max_iter passed or the recursion broke down
 * (A or the cycle not positive definite). *iterations and *rel = the true
 * ||b - A x|| / ||b|| in both cases. */
typedef double (*mf_residual_fn)(const void *ctx, const double *x, double *r);
int mf_amg_pcg(mf_amg_vcycle *v, const mf_csr *A, const int64_t *prow, double *x, double *r,
               double bnorm, double tol, long max_iter, mf_residual_fn resid, const void *ctx,
               int *iterations, double *rel);

#endif
