/* pcg_boomeramg.c: PCG_BoomerAMG, conjugate gradients preconditioned by one
 * BoomerAMG V-cycle per iteration (hypre).
 *
 * The defaults are those that work well for MPS pressure matrices (about
 * 30 non-zeros per row in 3-D): HMIS coarsening, extended+i interpolation
 * (in hypre's matrix-matrix form, 17: the same weights as 6, set up in half
 * the time) truncated to 4 weights per row, hybrid Gauss-Seidel forward on
 * the way down and backward on the way up (relaxType 3: the V-cycle is
 * symmetric with half the sweeps of the symmetric smoothers 6 and 8; on
 * the 2-D and 3-D bench cases a few more iterations, a quarter to a third
 * fewer instructions in the solve), one level of aggressive coarsening (measured faster when the hierarchy is
 * built for each solve: a cheaper set-up outweighs a few more iterations;
 * the MPS solver asks for none in 2-D, where the hierarchy is kept across
 * steps, mps_module.c). PCG needs a symmetric positive definite
 * preconditioner, hence a symmetric smoother and a fixed cycle (one V-cycle,
 * tolerance 0, so BoomerAMG never stops early or flags non-convergence).
 *
 * Keeping a hierarchy. BoomerAMG's solve takes the fine-level matrix it is
 * given (hypre_BoomerAMGSolve sets A_array[0] = A), so a hierarchy set up
 * for one matrix preconditions another of the same size: coarse levels and
 * interpolation are the old matrix's, PCG works on the new one, and the
 * answer is as accurate as ever (only the iteration count can suffer).
 *  - reuseHierarchy (default yes): when the caller names the rows (mf_row_names,
 *    the MPS pressure equation: one slot per particle), the system is
 *    assembled in slot space (hypre_common.c), so its size and the meaning
 *    of each row stay fixed while the free surface and the neighbour pairs
 *    change, and one hierarchy serves step after step. It is rebuilt when
 *    the slots change meaning (a new epoch: the particles were reordered,
 *    added or removed) and when a solve took more than rebuildRatio times
 *    the iterations of the hierarchy's first solve (at least two more).
 *    Without the rebuild a kept hierarchy ages: on the 2-D bench dam break
 *    the iterations grow from 5 to 8 over 25 steps and to 49 over 1000
 *    (docs/validation-and-performance.md). On several ranks each rank's
 *    slots are a block of hypre's rows (hypre_common.c), and the decision
 *    is one for all (may_keep): a rank whose particles changed (migration,
 *    reordering) makes every rank set a new hierarchy up, since hypre's
 *    set-up is collective and the hierarchy's row partition is the ranks'
 *    slot counts.
 *  - reuseSetup > 0 keeps the hierarchy for that many further solves as
 *    long as the matrix size and sparsity pattern do not change (the
 *    implicit viscosity: one matrix, a solve per velocity component).
 * A kept hierarchy that fails to converge is rebuilt and the solve repeated
 * once from the same initial guess.
 *
 * ownCycle (default yes) with relaxType 3: hypre sets the hierarchy up, our
 * PCG and V-cycle run it (amg_vcycle.h): on one rank a copy of it, on
 * several hypre's levels read in place with their comm packages
 * (amg_vcycle_par.c; hypre's solver is kept, its own PCG and cycle the
 * fallback when ours cannot run, the reason printed once). no: hypre's PCG
 * and V-cycle.
 */
#define MF_PRESSURE_HYPRE_INTERNAL
#include "pressure_hypre.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "amg_vcycle.h"
#include "mf_error.h"

static const char module_name[] = "PCG_BoomerAMG";

typedef struct pcg_boomeramg {
    mf_pcg_boomeramg_settings s;
    /* The hierarchy, between solves only when it may serve again: hypre's
     * (amg), or on one rank the copy our V-cycle runs (cycle). */
    HYPRE_Solver amg;
    mf_amg_vcycle *cycle;
    /* On several ranks: our V-cycle over amg's hierarchy (NULL: hypre's
     * cycle serves), and whether the reason it did not was printed. */
    mf_amg_par *par;
    bool told;
    bool reused;       /* the current solve reuses amg */
    long setups;       /* hierarchies set up so far (mf_solve_report.setups) */
    /* reuseSetup: the pattern amg was set up with, the solves it may serve. */
    uint64_t pattern;
    long reuses_left;
    /* reuseHierarchy: amg was set up in slot space (nslots, epoch), its
     * first solve took first_iterations (-1: not yet), the last one last. */
    bool slot_space;
    int64_t nslots;
    uint64_t epoch;
    int first_iterations, last_iterations;
} pcg_boomeramg;

#define P(field) offsetof(mf_pcg_boomeramg_settings, field)
static const mf_param params[] = {
    {"tolerance", MF_PARAM_SCALAR, "1e-8", 1e-16, 1.0, NULL, P(tolerance),
     "relative residual ||b - A x|| / ||b|| to reach"},
    {"maxIter", MF_PARAM_INT, "500", 1, 1e7, NULL, P(max_iter),
     "PCG iteration limit (not converged by then: the step is retried)"},
    {"strongThreshold", MF_PARAM_SCALAR, "0.25", 0.0, 0.99, NULL, P(strong_threshold),
     "AMG strength-of-connection threshold (0.25 for 2-D, 0.5 for 3-D cases)"},
    {"aggressiveLevels", MF_PARAM_INT, "1", 0, 25, NULL, P(aggressive_levels),
     "levels of aggressive coarsening from the finest (0 = none)"},
    {"coarsenType", MF_PARAM_INT, "10", 0, 22, NULL, P(coarsen_type),
     "hypre coarsening: 10 HMIS, 8 PMIS, 6 Falgout, 0 CLJP, 3 RS (1, 21, 22 also)"},
    {"interpType", MF_PARAM_INT, "17", 0, 18, NULL, P(interp_type),
     "hypre interpolation: 17 extended+i (matrix-matrix form), 6 extended+i, 0 classical, "
     "8 standard, 14 extended"},
    {"pMaxElmts", MF_PARAM_INT, "4", 0, 100, NULL, P(p_max_elmts),
     "most interpolation weights per row (0 = no limit)"},
    {"relaxType", MF_PARAM_INT, "3", 0, 18, NULL, P(relax_type),
     "smoother, a symmetric V-cycle for PCG: 3 hybrid GS forward down, backward up; 13 the same "
     "l1-scaled; symmetric on each sweep: 8 l1 symmetric GS, 6 symmetric GS, 0 Jacobi, "
     "16 Chebyshev, 18 l1 Jacobi"},
    {"reuseSetup", MF_PARAM_INT, "0", 0, 1000, NULL, P(reuse_setup),
     "further solves that may reuse the AMG hierarchy while the pattern is unchanged (0 = never)"},
    {"ownCycle", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL, P(own_cycle),
     "relaxType 3: run our own PCG and V-cycle over the hierarchy hypre set up (on one rank "
     "and on several; no: hypre's PCG and V-cycle)"},
    {"reuseHierarchy", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL, P(reuse_hierarchy),
     "keep the AMG hierarchy across solves whose rows the caller names (the MPS pressure "
     "equation), rebuilding it when the rows change meaning or the iterations grow"},
    {"rebuildRatio", MF_PARAM_SCALAR, "2", 1, 100, NULL, P(rebuild_ratio),
     "rebuild a kept hierarchy after a solve that took more than this many times the "
     "iterations of its first solve"},
};
#undef P

static int check_settings(const mf_pcg_boomeramg_settings *s)
{
    static const long coarsen_types[] = {0, 1, 3, 6, 8, 10, 21, 22};
    /* Smoothers that make the V-cycle symmetric when used both down and up. */
    static const long relax_types[] = {0, 3, 6, 8, 13, 16, 18};
    bool ok;

    MF_CALL(mf_hypre_check_pcg_settings(module_name, s->tolerance, s->max_iter));
    if (!(s->strong_threshold >= 0.0 && s->strong_threshold < 1.0))
        return MF_ERROR(MF_ERR_INPUT, "%s: strongThreshold %g is not in [0, 1)", module_name,
                        s->strong_threshold);
    if (s->aggressive_levels < 0 || s->aggressive_levels > 25)
        return MF_ERROR(MF_ERR_INPUT, "%s: aggressiveLevels %ld is not in [0, 25]", module_name,
                        s->aggressive_levels);
    if (!(s->rebuild_ratio >= 1 && s->rebuild_ratio <= 100))
        return MF_ERROR(MF_ERR_INPUT, "%s: rebuildRatio %g is not in [1, 100]", module_name,
                        s->rebuild_ratio);
    ok = false;
    for (size_t i = 0; i < sizeof coarsen_types / sizeof *coarsen_types; i++)
        ok = ok || s->coarsen_type == coarsen_types[i];
    if (!ok)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: coarsenType %ld is not one of 0, 1, 3, 6, 8, 10, 21, 22",
                        module_name, s->coarsen_type);
    if (s->interp_type < 0 || s->interp_type > 18)
        return MF_ERROR(MF_ERR_INPUT, "%s: interpType %ld is not in [0, 18]", module_name,
                        s->interp_type);
    if (s->p_max_elmts < 0 || s->p_max_elmts > 100)
        return MF_ERROR(MF_ERR_INPUT, "%s: pMaxElmts %ld is not in [0, 100]", module_name,
                        s->p_max_elmts);
    ok = false;
    for (size_t i = 0; i < sizeof relax_types / sizeof *relax_types; i++)
        ok = ok || s->relax_type == relax_types[i];
    if (!ok)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: relaxType %ld does not make a symmetric V-cycle (PCG needs one): "
                        "use 3, 13, 8, 6, 0, 16 or 18",
                        module_name, s->relax_type);
    if (s->reuse_setup < 0 || s->reuse_setup > 1000)
        return MF_ERROR(MF_ERR_INPUT, "%s: reuseSetup %ld is not in [0, 1000]", module_name,
                        s->reuse_setup);
    return 0;
}

static int pcg_boomeramg_create(const void *settings, void **data)
{
    const mf_pcg_boomeramg_settings *s = settings;
    *data = NULL;
    if (s == NULL)
        return MF_ERROR(MF_ERR_INPUT, "%s: no settings", module_name);
    MF_CALL(check_settings(s));
    pcg_boomeramg *d = calloc(1, sizeof *d);
    if (d == NULL)
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory", module_name);
    d->s = *s;
    *data = d;
    return 0;
}

static void discard_hierarchy(pcg_boomeramg *d)
{
    mf_amg_par_free(d->par); /* reads amg's levels: first */
    d->par = NULL;
    if (d->amg)
        HYPRE_BoomerAMGDestroy(d->amg);
    d->amg = NULL;
    mf_amg_vcycle_free(d->cycle);
    d->cycle = NULL;
    d->reuses_left = 0;
    d->slot_space = false;
}

int mf_boomeramg_create(const mf_pcg_boomeramg_settings *s, HYPRE_Solver *out)
{
    HYPRE_Solver amg = NULL;
    int rc = 0;
    *out = NULL;
    MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGCreate, (&amg));
    MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGSetPrintLevel, (amg, 0));
    MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGSetCoarsenType,
                  (amg, (HYPRE_Int)s->coarsen_type));
    MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGSetInterpType,
                  (amg, (HYPRE_Int)s->interp_type));
    MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGSetPMaxElmts,
                  (amg, (HYPRE_Int)s->p_max_elmts));
    /* Sets the down and up sweeps (the coarsest level keeps Gaussian
     * elimination); types 6 and 8 are symmetric on their own (forward then
     * backward); a forward type 3 or 13 on the way down takes its backward
     * 4 or 14 on the way up, which makes the cycle symmetric. */
    MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGSetRelaxType,
                  (amg, (HYPRE_Int)s->relax_type));
    if (s->relax_type == 3 || s->relax_type == 13)
        MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGSetCycleRelaxType,
                      (amg, (HYPRE_Int)s->relax_type + 1, 2));
    MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGSetNumSweeps, (amg, 1));
    MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGSetStrongThreshold,
                  (amg, s->strong_threshold));
    MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGSetAggNumLevels,
                  (amg, (HYPRE_Int)s->aggressive_levels));
    /* A preconditioner: exactly one V-cycle per application. */
    MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGSetMaxIter, (amg, 1));
    MF_HYPRE_CALL(module_name, rc, fail, HYPRE_BoomerAMGSetTol, (amg, 0.0));
    *out = amg;
    return 0;
fail:
    if (amg)
        HYPRE_BoomerAMGDestroy(amg);
    return rc;
}

/* reuseHierarchy: whether the kept hierarchy may serve this solve in slot
 * space (same slots, same epoch, its iterations not grown too far) on this
 * rank. */
static bool may_keep_here(const pcg_boomeramg *d, const mf_row_names *rows)
{
    if (!(d->amg || d->cycle) || !d->slot_space || rows->nslots != d->nslots ||
        rows->epoch != d->epoch)
        return false;
    const int first = d->first_iterations;
    if (first < 0)
        return true;
    const double bound = fmax(d->s.rebuild_ratio * first, first + 2.0);
    return d->last_iterations <= bound;
}

/* Collective: ... on every rank (hypre's set-up is collective, and a
 * hierarchy's row partition is every rank's slots: one rank whose particles
 * changed, by migration or reordering, needs a new one for all). The
 * iteration counts are the same on every rank; the slots and epochs are each
 * rank's own. */
static bool may_keep(const pcg_boomeramg *d, const mf_row_names *rows)
{
    return mf_hypre_all(may_keep_here(d, rows));
}

static int prepare_hypre(pcg_boomeramg *d, const mf_csr *A, const mf_row_names *rows,
                         mf_hypre_precond *pc)
{
    d->reused = false;
    if (d->cycle) /* kept for our V-cycle: of no use to hypre's */
        discard_hierarchy(d);
    if (rows && d->s.reuse_hierarchy) {
        if (may_keep(d, rows)) {
            d->reused = true;
            *pc = (mf_hypre_precond){HYPRE_BoomerAMGSolve, mf_hypre_keep_hierarchy, d->amg, NULL, NULL};
            return 0;
        }
        discard_hierarchy(d);
        MF_CALL(mf_boomeramg_create(&d->s, &d->amg));
        d->setups++;
        d->slot_space = true;
        d->nslots = rows->nslots;
        d->epoch = rows->epoch;
        d->first_iterations = -1;
        *pc = (mf_hypre_precond){HYPRE_BoomerAMGSolve, HYPRE_BoomerAMGSetup, d->amg, NULL, NULL};
        return 0;
    }
    if (d->slot_space) /* set up in slot space: of no use to a system in rows */
        discard_hierarchy(d);
    if (d->s.reuse_setup > 0) {
        uint64_t pattern = 0;
        MF_CALL(mf_hypre_pattern_hash(A, &pattern));
        if (d->amg && d->reuses_left > 0 && pattern == d->pattern) {
            d->reuses_left--;
            d->reused = true;
            *pc = (mf_hypre_precond){HYPRE_BoomerAMGSolve, mf_hypre_keep_hierarchy, d->amg, NULL, NULL};
            return 0;
        }
        discard_hierarchy(d);
        d->pattern = pattern;
    }
    MF_CALL(mf_boomeramg_create(&d->s, &d->amg));
    d->setups++;
    d->reuses_left = d->s.reuse_setup;
    *pc = (mf_hypre_precond){HYPRE_BoomerAMGSolve, HYPRE_BoomerAMGSetup, d->amg, NULL, NULL};
    return 0;
}

/* hypre's hierarchy for this solve (kept or new, under reuseHierarchy's and
 * reuseSetup's rules); on several ranks with relaxType 3 and ownCycle, run
 * by our PCG and V-cycle (hypre_common.c takes it after the set-up). */
static int precond_prepare(void *ctx, const mf_csr *A, const mf_row_names *rows,
                           mf_hypre_precond *pc)
{
    pcg_boomeramg *d = ctx;
    MF_CALL(prepare_hypre(d, A, rows, pc));
    int nprocs = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
    if (nprocs > 1 && d->s.own_cycle && d->s.relax_type == 3) {
        pc->par = &d->par;
        pc->told = &d->told;
    }
    return 0;
}

/* One rank: our V-cycle over the hierarchy hypre sets up, kept under the
 * same rules as precond_prepare's (amg_vcycle.h says why). *cycle NULL: the
 * smoother is not relaxType 3, or hypre's hierarchy is not one the cycle
 * runs (a single level, a large coarsest level): hypre's PCG then runs. */
static int cycle_prepare(void *ctx, const mf_csr *A, const mf_row_names *rows,
                         mf_amg_vcycle **cycle)
{
    pcg_boomeramg *d = ctx;
    *cycle = NULL;
    d->reused = false;
    /* hypre's own cycle asked for, or a hierarchy of hypre's kept */
    if (d->s.relax_type != 3 || !d->s.own_cycle || d->amg != NULL)
        return 0;
    if (rows && d->s.reuse_hierarchy) {
        if (d->cycle && may_keep(d, rows)) {
            d->reused = true;
            *cycle = d->cycle;
            return 0;
        }
    }
    uint64_t pattern = 0;
    const bool by_pattern = !(rows && d->s.reuse_hierarchy) && d->s.reuse_setup > 0;
    if (by_pattern) {
        MF_CALL(mf_hypre_pattern_hash(A, &pattern));
        if (d->cycle && !d->slot_space && d->reuses_left > 0 && pattern == d->pattern) {
            d->reuses_left--;
            d->reused = true;
            *cycle = d->cycle;
            return 0;
        }
    }
    discard_hierarchy(d);
    d->pattern = pattern;
    HYPRE_Solver amg = NULL;
    MF_CALL(mf_boomeramg_create(&d->s, &amg));
    const mf_row_names *slots = rows && d->s.reuse_hierarchy ? rows : NULL;
    d->setups++;
    MF_CALL(mf_hypre_setup_cycle(module_name, amg, A, slots, &d->cycle));
    if (d->cycle == NULL)
        return 0;
    d->slot_space = slots != NULL;
    if (slots) {
        d->nslots = rows->nslots;
        d->epoch = rows->epoch;
        d->first_iterations = -1;
    } else
        d->reuses_left = d->s.reuse_setup;
    *cycle = d->cycle;
    return 0;
}

static void precond_release(void *ctx, const mf_solve_report *rep, bool converged)
{
    pcg_boomeramg *d = ctx;
    if (!converged) { /* the retry (pcg_boomeramg_solve) starts from a fresh one */
        discard_hierarchy(d);
        return;
    }
    if (d->slot_space) {
        if (d->first_iterations < 0)
            d->first_iterations = rep->iterations;
        d->last_iterations = rep->iterations;
        return;
    }
    /* Keep the hierarchy only if it may serve again. */
    if (d->s.reuse_setup == 0)
        discard_hierarchy(d);
}

static int solve_impl(pcg_boomeramg *d, const mf_csr *A, const mf_row_names *rows, const double *b,
                      double *x, mf_solve_report *rep)
{
    const mf_hypre_pcg pcg = {
        .name = module_name,
        .tolerance = d->s.tolerance,
        .max_iter = d->s.max_iter,
        .rows = d->s.reuse_hierarchy ? rows : NULL,
        .precond_prepare = precond_prepare,
        .cycle_prepare = cycle_prepare,
        .precond_release = precond_release,
        .ctx = d,
    };
    mf_solve_report local;
    if (rep == NULL)
        rep = &local;
    d->reused = false;
    const long setups_before = d->setups;
    if ((d->amg == NULL && d->cycle == NULL) || A == NULL || x == NULL) {
        int rc = mf_hypre_pcg_solve(&pcg, A, b, x, rep);
        rep->setups = (int)(d->setups - setups_before);
        MF_CALL(rc);
        return 0;
    }

    /* A hierarchy may be reused: keep the initial guess, in case the stale
     * hierarchy fails and the solve is repeated with a fresh one. */
    double *x0 = malloc((A->nrows + 1) * sizeof *x0);
    if (x0 == NULL)
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory saving the initial guess", module_name);
    memcpy(x0, x, A->nrows * sizeof *x0);
    int rc = mf_hypre_pcg_solve(&pcg, A, b, x, rep);
    if (rc == MF_RETRY && d->reused) {
        /* precond_release has discarded the hierarchy: this builds a new one. */
        const mf_solve_report first = *rep;
        mf_error_clear();
        memcpy(x, x0, A->nrows * sizeof *x0);
        rc = mf_hypre_pcg_solve(&pcg, A, b, x, rep);
        rep->iterations += first.iterations;
        rep->setup_seconds += first.setup_seconds;
        rep->solve_seconds += first.solve_seconds;
    }
    free(x0);
    rep->setups = (int)(d->setups - setups_before);
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    return 0;
}

static int pcg_boomeramg_solve(void *data, const mf_csr *A, const double *b, double *x,
                               mf_solve_report *rep)
{
    return solve_impl(data, A, NULL, b, x, rep);
}

static int pcg_boomeramg_solve_rows(void *data, const mf_csr *A, const mf_row_names *rows,
                                    const double *b, double *x, mf_solve_report *rep)
{
    return solve_impl(data, A, rows, b, x, rep);
}

static void pcg_boomeramg_destroy(void *data)
{
    pcg_boomeramg *d = data;
    if (d == NULL)
        return;
    discard_hierarchy(d);
    free(d);
}

const mf_pressure_ops mf_pressure_PCG_BoomerAMG = {
    .info = {MF_ABI_VERSION, MF_KIND_PRESSURE, "PCG_BoomerAMG",
             "conjugate gradients preconditioned by one BoomerAMG V-cycle (hypre)", params,
             sizeof params / sizeof *params, sizeof(mf_pcg_boomeramg_settings)},
    .create = pcg_boomeramg_create,
    .solve = pcg_boomeramg_solve,
    .destroy = pcg_boomeramg_destroy,
    .solve_rows = pcg_boomeramg_solve_rows,
};
