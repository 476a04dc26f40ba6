/* pressure_hypre.h: the pressure-solver modules backed by hypre.
 *
 *   PCG_BoomerAMG  conjugate gradients preconditioned by one BoomerAMG
 *                  V-cycle per iteration (the default choice);
 *   PCG_diagonal   conjugate gradients with diagonal (Jacobi) scaling
 *                  (cheap per iteration, many iterations; for comparison).
 *
 * Both take the matrix as this rank's rows of an mf_csr, copy it into hypre
 * IJ/ParCSR objects (rebuilt on every solve: particles move, so the pattern
 * changes every step; in slot space when the caller names the rows, on one
 * rank or several, see mf_hypre_pcg.rows), solve, and report iterations,
 * set-ups and the true relative
 * residuals ||b - A x|| / ||b|| computed from the caller's CSR. PCG_BoomerAMG
 * may keep its AMG hierarchy across solves (pcg_boomeramg.c).
 *
 * The caller owns MPI and hypre: MPI_Init and HYPRE_Init() before the first
 * create, HYPRE_Finalize and MPI_Finalize after the last destroy. The
 * communicator is MPI_COMM_WORLD; every rank calls solve together.
 */
#ifndef MF_PRESSURE_HYPRE_H
#define MF_PRESSURE_HYPRE_H

#include "mf_modules.h"

/* Settings of PCG_BoomerAMG (filled from its parameter table). */
typedef struct mf_pcg_boomeramg_settings {
    double tolerance;        /* relative residual ||b - A x|| / ||b|| */
    long max_iter;           /* PCG iteration limit */
    double strong_threshold; /* AMG strength of connection (0.25 in 2-D, 0.5 in 3-D) */
    long aggressive_levels;  /* levels of aggressive coarsening, from the finest */
    long coarsen_type;       /* hypre coarsening algorithm (10 = HMIS) */
    long interp_type;        /* hypre interpolation (6 = extended+i) */
    long p_max_elmts;        /* max interpolation weights per row (0 = no limit) */
    long relax_type;         /* smoother, must be symmetric (8 = l1 symmetric Gauss-Seidel) */
    long reuse_setup;        /* solves that may reuse one AMG hierarchy while the pattern is
                                unchanged (0 = rebuild each) */
    bool own_cycle;          /* relaxType 3: our V-cycle and PCG over hypre's hierarchy */
    bool reuse_hierarchy;    /* named rows (mf_row_names): keep the hierarchy across solves */
    double rebuild_ratio;    /* ... until a solve takes this many times the iterations of the
                                hierarchy's first */
} mf_pcg_boomeramg_settings;

/* Settings of PCG_diagonal. */
typedef struct mf_pcg_diagonal_settings {
    double tolerance;
    long max_iter;
} mf_pcg_diagonal_settings;

extern const mf_pressure_ops mf_pressure_PCG_BoomerAMG;
extern const mf_pressure_ops mf_pressure_PCG_diagonal;

/* ---- Internal: shared by hypre_common.c and the two modules only. ------
 * Kept behind a macro so that including this header elsewhere (the module
 * registration) does not pull in hypre's headers and macros. */
#ifdef MF_PRESSURE_HYPRE_INTERNAL

#include <stdbool.h>
#include <stdint.h>

#include <HYPRE.h>
#include <HYPRE_krylov.h>
#include <HYPRE_parcsr_ls.h>

/* Our V-cycle over a hierarchy of hypre's (amg_vcycle.h). */
typedef struct mf_amg_vcycle mf_amg_vcycle;
typedef struct mf_amg_par mf_amg_par;

/* The preconditioner PCG uses: hypre's (solve, setup, data) triple. */
typedef struct mf_hypre_precond {
    HYPRE_PtrToParSolverFcn solve;
    HYPRE_PtrToParSolverFcn setup;
    HYPRE_Solver solver; /* may be NULL (diagonal scaling needs no data) */
    /* Optional, several ranks (NULL: hypre's PCG): where the module keeps
     * our V-cycle over solver's hierarchy (amg_vcycle.h, mf_amg_par), which
     * then runs in our PCG. setup HYPRE_BoomerAMGSetup: a new hierarchy,
     * set up and taken (*par) before the solve; else *par is the kept one's
     * (NULL: hypre's PCG). told: whether the reason for falling back on
     * hypre's PCG was printed (once a module). */
    mf_amg_par **par;
    bool *told;
} mf_hypre_precond;

/* One PCG solve as a module describes it. */
typedef struct mf_hypre_pcg {
    const char *name; /* module name, for messages */
    double tolerance;
    long max_iter;
    /* Optional (NULL: row space): the rows' names. The system is then
     * assembled in slot space: slot[r] of this rank holds row r (rank p's
     * slots are hypre's rows from the sum of the slots of ranks before p),
     * and a slot no row names is a decoupled row d x = 0 (d the mean
     * diagonal, b = x = 0), so that a preconditioner set up for one solve
     * can serve a later one whose rows differ (a free-surface particle is a
     * Dirichlet value in one step and an unknown in the next). */
    const mf_row_names *rows;
    /* Fill *pc once the matrix is known (called after the cheap exits, so
     * not at all for b = 0 or an initial guess that already converged).
     * rows: the slots the system is assembled in (NULL: row space). */
    int (*precond_prepare)(void *ctx, const mf_csr *A, const mf_row_names *rows, mf_hypre_precond *pc);
    /* Optional, one rank: the module's own V-cycle for this solve
     * (amg_vcycle.h), which then runs in our PCG; *cycle NULL: hypre's PCG
     * with precond_prepare. Called after the cheap exits; may set a
     * hierarchy up with mf_hypre_setup_cycle. */
    int (*cycle_prepare)(void *ctx, const mf_csr *A, const mf_row_names *rows,
                         mf_amg_vcycle **cycle);
    /* Called after every prepare that succeeded (precond_prepare, or a
     * cycle_prepare that gave a cycle), whatever happened next;
     * converged tells whether this solve reached the tolerance, rep how. */
    void (*precond_release)(void *ctx, const mf_solve_report *rep, bool converged);
    void *ctx;
} mf_hypre_pcg;

/* The whole solve: checks, cheap exits, assembly, PCG, report. Returns 0,
 * MF_RETRY when not converged (report filled), or a negative error. */
int mf_hypre_pcg_solve(const mf_hypre_pcg *pcg, const mf_csr *A, const double *b, double *x,
                       mf_solve_report *rep);

/* A BoomerAMG solver with PCG_BoomerAMG's settings s, as one V-cycle a
 * call (a preconditioner), not yet set up. */
int mf_boomeramg_create(const mf_pcg_boomeramg_settings *s, HYPRE_Solver *out);

/* One rank: assemble A as hypre's (in slot space when rows), set the AMG
 * solver amg up on it, take the hierarchy for our V-cycle (*cycle; NULL when
 * it is not one the cycle runs), and destroy hypre's matrix and amg. */
int mf_hypre_setup_cycle(const char *who, HYPRE_Solver amg, const mf_csr *A,
                         const mf_row_names *rows, mf_amg_vcycle **cycle);

/* One rank: set amg up on A in slot space made in A's own arrays when A
 * lends them (mf_csr.lent_capacity) and its rows allow it (fine_in_place.c);
 * A is as it was on return. *done false (and 0): not possible, nothing done. */
int mf_hypre_setup_in_place(const char *who, HYPRE_Solver amg, const mf_csr *A,
                            const mf_row_names *rows, bool *done);

/* A 64-bit fingerprint of the sizes, row range and sparsity pattern of this
 * rank's rows, agreed over all ranks (the same value everywhere). */
int mf_hypre_pattern_hash(const mf_csr *A, uint64_t *hash);
/* The preconditioner set-up PCGSetup calls when the hierarchy is set up
 * already (kept from an earlier solve, or our own cycle's): it leaves it
 * as it is. */
HYPRE_Int mf_hypre_keep_hierarchy(HYPRE_Solver amg, HYPRE_ParCSRMatrix A, HYPRE_ParVector b,
                                  HYPRE_ParVector x);

/* Check the settings both modules share; MF_ERR_INPUT naming the bad one. */
int mf_hypre_check_pcg_settings(const char *who, double tolerance, long max_iter);

/* Collective: 0 if every rank passes rc == 0; else this rank's rc (its
 * message already recorded) or MF_ERR_INPUT saying another rank failed.
 * Keeps all ranks on the same path, so none waits in a collective call. */
int mf_hypre_agree(const char *who, int rc);

/* Collective: whether local holds on every rank (one decision for all). */
bool mf_hypre_all(bool local);

/* Record a failed hypre call as MF_ERR_LIBRARY naming the function, and
 * clear hypre's error flag (global and sticky: it would make every later
 * hypre call report the same failure). */
int mf_hypre_error(const char *who, const char *hypre_func, HYPRE_Int code, const char *file,
                   int line, const char *func);

/* Call a hypre function; on a non-zero error code set rc and jump to label.
 * Usage: MF_HYPRE_CALL(name, rc, fail, HYPRE_BoomerAMGSetTol, (amg, 0.0)); */
#define MF_HYPRE_CALL(who, rc, label, func, args)                                   \
    do {                                                                            \
        HYPRE_Int mf_hypre_ierr_ = func args;                                       \
        if (mf_hypre_ierr_ != 0) {                                                  \
            (rc) = mf_hypre_error((who), #func, mf_hypre_ierr_, __FILE__, __LINE__, \
                                  __func__);                                        \
            goto label;                                                             \
        }                                                                           \
    } while (0)

#endif /* MF_PRESSURE_HYPRE_INTERNAL */

#endif
