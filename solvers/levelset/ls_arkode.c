/* ls_arkode.c: pseudo-time integration of eq. 29 with SUNDIALS ARKODE 6.
 *
 * The state vector is phi at the active band points (N_VNew_Serial over
 * them). Two integrators, chosen in the case (levelSetCoeffs/integrator):
 *   explicit  ERKStep, Heun-Euler 2(1) pair, with a stability function that
 *             returns the advection and curvature limits (ls_rhs_stable_step):
 *             ARKODE takes min(accuracy step, stability step);
 *   imex      ARKStep: advection explicit, curvature implicit, solved by
 *             Newton with matrix-free SPGMR (ARKODE's difference-quotient
 *             Jacobian-vector products), right-preconditioned by Gauss-Seidel
 *             sweeps on the linearised curvature operator; forward-backward
 *             Euler ARS(1,1,1) at fixed steps at the advection limit (a step
 *             whose Newton iteration fails is redone with half the step).
 *             The explicit curvature limit is dtau ~ (h / l0) / beta, so the
 *             explicit step count grows as (l0/h)^2 and the IMEX one as l0/h:
 *             on fine grids IMEX needs fewer right-hand sides.
 * The integration runs in chunks of pseudo-time; after each chunk the
 * largest change of phi per unit pseudo-time at the points within a cell of
 * the zero level is the convergence measure ("the change per pseudo-time
 * step falls below a tolerance"). When the zero level has moved by more than
 * a cell since the band was built, the band is rebuilt around it and the
 * integrator restarted (its state is phi, so nothing else is lost). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_butcher.h>
#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_spgmr.h>

#include "levelset.h"

#define CHUNK 0.25
#define SPGMR_MAXL 20

typedef struct ark_err {
    char msg[512];
} ark_err;

static void on_error(int code, const char *module, const char *function, char *msg, void *data)
{
    ark_err *e = data;
    snprintf(e->msg, sizeof e->msg, "%s in %s/%s (code %d)", msg, module, function, code);
}

static int f_all(sunrealtype t, N_Vector y, N_Vector ydot, void *ud)
{
    (void)t;
    ls_rhs_eval(ud, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot), LS_RHS_ALL);
    return 0;
}

static int f_adv(sunrealtype t, N_Vector y, N_Vector ydot, void *ud)
{
    (void)t;
    ls_rhs_eval(ud, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot), LS_RHS_ADVECTION);
    return 0;
}

static int f_curv(sunrealtype t, N_Vector y, N_Vector ydot, void *ud)
{
    (void)t;
    ls_rhs_eval(ud, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot), LS_RHS_CURVATURE);
    return 0;
}

static int stab_all(N_Vector y, sunrealtype t, sunrealtype *hstab, void *ud)
{
    (void)y;
    (void)t;
    *hstab = ls_rhs_stable_step(ud, true);
    return 0;
}

static int stab_adv(N_Vector y, sunrealtype t, sunrealtype *hstab, void *ud)
{
    (void)y;
    (void)t;
    *hstab = ls_rhs_stable_step(ud, false);
    return 0;
}

static int psetup(sunrealtype t, N_Vector y, N_Vector fy, sunbooleantype jok,
                  sunbooleantype *jcur, sunrealtype gamma, void *ud)
{
    (void)t;
    (void)fy;
    (void)jok;
    *jcur = SUNTRUE;
    return ls_rhs_precond_setup(ud, N_VGetArrayPointer(y), gamma) == 0 ? 0 : -1;
}

static int psolve(sunrealtype t, N_Vector y, N_Vector fy, N_Vector rv, N_Vector z,
                  sunrealtype gamma, sunrealtype delta, int lr, void *ud)
{
    (void)t;
    (void)y;
    (void)fy;
    (void)gamma;
    (void)delta;
    (void)lr;
    ls_rhs_precond_solve(ud, N_VGetArrayPointer(rv), N_VGetArrayPointer(z));
    return 0;
}

typedef struct integrator {
    bool imex;
    bool fixed;            /* fixed steps, set before each chunk */
    void *mem;
    SUNLinearSolver ls;
} integrator;

#define ARK_CHECK(call, what)                                                               \
    do {                                                                                    \
        int flag_ = (call);                                                                 \
        if (flag_ < 0)                                                                      \
            return MF_ERROR(MF_ERR_LIBRARY, "ARKODE: %s failed (%d)%s%s", what, flag_,       \
                            err->msg[0] ? ": " : "", err->msg);                             \
    } while (0)

static int integrator_create(integrator *it, const ls_evolve_opts *o, ls_rhs *r, N_Vector y,
                             SUNContext ctx, ark_err *err)
{
    it->imex = o->imex;
    if (!o->imex) {
        it->mem = ERKStepCreate(f_all, 0.0, y, ctx);
        if (!it->mem)
            return MF_ERROR(MF_ERR_LIBRARY, "ARKODE: ERKStepCreate failed");
        ARK_CHECK(ERKStepSetErrHandlerFn(it->mem, on_error, err), "ERKStepSetErrHandlerFn");
        ARK_CHECK(ERKStepSStolerances(it->mem, o->rel_tol, o->abs_tol), "ERKStepSStolerances");
        ARK_CHECK(ERKStepSetTableNum(it->mem, ARKODE_HEUN_EULER_2_1_2), "ERKStepSetTableNum");
        ARK_CHECK(ERKStepSetStabilityFn(it->mem, stab_all, r), "ERKStepSetStabilityFn");
        /* 0.9 of the stability limit (ARKODE defaults to 0.5) */
        ARK_CHECK(ERKStepSetCFLFraction(it->mem, 0.9), "ERKStepSetCFLFraction");
        ARK_CHECK(ERKStepSetUserData(it->mem, r), "ERKStepSetUserData");
        ARK_CHECK(ERKStepSetMaxNumSteps(it->mem, o->max_steps), "ERKStepSetMaxNumSteps");
        return 0;
    }
    it->mem = ARKStepCreate(f_adv, f_curv, 0.0, y, ctx);
    if (!it->mem)
        return MF_ERROR(MF_ERR_LIBRARY, "ARKODE: ARKStepCreate failed");
    ARK_CHECK(ARKStepSetErrHandlerFn(it->mem, on_error, err), "ARKStepSetErrHandlerFn");
    ARK_CHECK(ARKStepSStolerances(it->mem, o->rel_tol, o->abs_tol), "ARKStepSStolerances");
    {
        /* Forward-backward (IMEX) Euler, ARS(1,1,1), at fixed steps at the
         * advection limit: only the steady state matters, and one implicit
         * stage per step is the cheapest way to it. ARKODE's adaptive
         * ARK3(2)4L[2]SA took 2 to 4 times more right-hand sides on the test
         * sphere: its steps were limited by accuracy, which a pseudo-time
         * does not need. */
        ARKodeButcherTable Bi = ARKodeButcherTable_Alloc(2, SUNFALSE),
                           Be = ARKodeButcherTable_Alloc(2, SUNFALSE);
        if (!Bi || !Be) {
            ARKodeButcherTable_Free(Bi);
            ARKodeButcherTable_Free(Be);
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for a Butcher table");
        }
        Bi->q = Be->q = 1;
        Bi->p = Be->p = 0;
        Bi->c[0] = Be->c[0] = 0;
        Bi->c[1] = Be->c[1] = 1;
        Bi->A[1][1] = 1;
        Bi->b[1] = 1;
        Be->A[1][0] = 1;
        Be->b[0] = 1;
        int flag = ARKStepSetTables(it->mem, 1, 0, Bi, Be);
        ARKodeButcherTable_Free(Bi);
        ARKodeButcherTable_Free(Be);
        ARK_CHECK(flag, "ARKStepSetTables");
        it->fixed = true;
    }
    it->ls = SUNLinSol_SPGMR(y, SUN_PREC_RIGHT, SPGMR_MAXL, ctx);
    if (!it->ls)
        return MF_ERROR(MF_ERR_LIBRARY, "SUNDIALS: SUNLinSol_SPGMR failed");
    /* No matrix, no Jacobian routine: ARKODE forms J v by difference quotients
     * of the implicit right-hand side. Right preconditioning by Gauss-Seidel
     * sweeps on the linearised curvature operator (ls_rhs.c). */
    ARK_CHECK(ARKStepSetLinearSolver(it->mem, it->ls, NULL), "ARKStepSetLinearSolver");
    ARK_CHECK(ARKStepSetPreconditioner(it->mem, psetup, psolve), "ARKStepSetPreconditioner");
    ARK_CHECK(ARKStepSetStabilityFn(it->mem, stab_adv, r), "ARKStepSetStabilityFn");
    ARK_CHECK(ARKStepSetCFLFraction(it->mem, 0.9), "ARKStepSetCFLFraction");
    ARK_CHECK(ARKStepSetUserData(it->mem, r), "ARKStepSetUserData");
    ARK_CHECK(ARKStepSetMaxNumSteps(it->mem, o->max_steps), "ARKStepSetMaxNumSteps");
    return 0;
}

static void integrator_stats(const integrator *it, ls_stats *st)
{
    long v[6] = {0};
    if (!it->mem)
        return;
    if (!it->imex) {
        ERKStepGetNumSteps(it->mem, &v[0]);
        ERKStepGetNumExpSteps(it->mem, &v[1]);
        ERKStepGetNumAccSteps(it->mem, &v[2]);
        ERKStepGetNumErrTestFails(it->mem, &v[3]);
        ERKStepGetNumRhsEvals(it->mem, &v[4]);
        st->steps += v[0];
        st->steps_stability += v[1];
        st->steps_accuracy += v[2];
        st->error_fails += v[3];
        st->rhs_explicit += v[4];
        return;
    }
    ARKStepGetNumSteps(it->mem, &v[0]);
    ARKStepGetNumExpSteps(it->mem, &v[1]);
    ARKStepGetNumAccSteps(it->mem, &v[2]);
    ARKStepGetNumErrTestFails(it->mem, &v[3]);
    st->steps += v[0];
    st->steps_stability += v[1];
    st->steps_accuracy += v[2];
    st->error_fails += v[3];
    long nfe = 0, nfi = 0, nfels = 0, nni = 0, nnf = 0, nli = 0, nlf = 0;
    ARKStepGetNumRhsEvals(it->mem, &nfe, &nfi);
    ARKStepGetNumLinRhsEvals(it->mem, &nfels);
    ARKStepGetNumNonlinSolvIters(it->mem, &nni);
    ARKStepGetNumNonlinSolvConvFails(it->mem, &nnf);
    ARKStepGetNumLinIters(it->mem, &nli);
    ARKStepGetNumLinConvFails(it->mem, &nlf);
    st->rhs_explicit += nfe;
    st->rhs_implicit += nfi;
    st->rhs_jtimes += nfels;
    st->newton_iters += nni;
    st->newton_fails += nnf;
    st->lin_iters += nli;
    st->lin_fails += nlf;
}

static void integrator_free(integrator *it)
{
    if (it->mem) {
        if (it->imex)
            ARKStepFree(&it->mem);
        else
            ERKStepFree(&it->mem);
    }
    if (it->ls)
        SUNLinSolFree(it->ls);
    it->mem = NULL;
    it->ls = NULL;
}

static int integrator_evolve(integrator *it, double tout, N_Vector y, double *tret)
{
    sunrealtype t = 0;
    int flag = it->imex ? ARKStepEvolve(it->mem, tout, y, &t, ARK_NORMAL)
                        : ERKStepEvolve(it->mem, tout, y, &t, ARK_NORMAL);
    *tret = t;
    return flag;
}

/* Rebuild the band around the current zero level: the interface points keep
 * their values, the rest is marched again; F is copied from the old band. */
static int rebuild(ls_band *band, const ls_field *f)
{
    ls_seed *seeds = NULL;
    size_t ns = 0;
    MF_CALL(ls_band_interface(band, &seeds, &ns));
    ls_band fresh;
    ls_band_init(&fresh, band->width, band->mem_limit);
    int rc = ls_band_from_seeds(&fresh, seeds, ns);
    free(seeds);
    if (rc == 0)
        rc = ls_band_fill_F(&fresh, f, &band->b, band->F);
    if (rc != 0) {
        ls_band_free(&fresh);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    ls_band_free(band);
    *band = fresh;
    return 0;
}

int ls_evolve(ls_band *band, const ls_field *f, const ls_evolve_opts *o, ls_stats *st)
{
    memset(st, 0, sizeof *st);
    SUNContext ctx = NULL;
    if (SUNContext_Create(NULL, &ctx) != 0)
        return MF_ERROR(MF_ERR_LIBRARY, "SUNDIALS: SUNContext_Create failed");
    ark_err err = {{0}};
    int rc = 0;
    bool done = false;
    while (rc == 0 && !done) {
        rc = ls_band_activate(band);
        if (rc != 0 || band->nact == 0)
            break;
        const size_t n = band->nact;
        ls_rhs r = {.band = band, .alpha = o->alpha, .beta_grid = o->beta_grid,
                    .far_F = f->offset};
        integrator it = {0};
        double *ybuild = malloc(n * sizeof *ybuild), *yprev = malloc(n * sizeof *yprev);
        N_Vector y = N_VNew_Serial((sunindextype)n, ctx);
        rc = ls_rhs_setup(&r);
        if (rc == 0 && (!ybuild || !yprev || !y))
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for a state of %zu band points", n);
        double *yv = y ? N_VGetArrayPointer(y) : NULL;
        if (rc == 0) {
            for (size_t k = 0; k < n; k++)
                yv[k] = ybuild[k] = yprev[k] = band->phi[band->act[k]];
            /* one evaluation for the speed bound the stability function uses */
            double *tmp = malloc(n * sizeof *tmp);
            if (tmp) {
                ls_rhs_eval(&r, yv, tmp, LS_RHS_ADVECTION);
                free(tmp);
            }
            rc = integrator_create(&it, o, &r, y, ctx, &err);
        }
        bool rebuild_now = false;
        double t = 0, step_factor = 1, best_rate = INFINITY;
        int stalled = 0;
        while (rc == 0 && !done && !rebuild_now) {
            double tret, tout = t + CHUNK;
            if (it.fixed) {
                /* the explicit part's stability limit (steps may span chunks:
                 * ARKODE interpolates at the chunk's end) */
                double hs = fmin(0.9 * step_factor * ls_rhs_stable_step(&r, false), 1.0);
                /* a chunk of whole steps, so that its end is a step's end and
                 * the change measured is that of real steps */
                tout = t + hs * fmax(1.0, round(CHUNK / hs));
                rc = ARKStepSetFixedStep(it.mem, hs);
                if (rc < 0) {
                    rc = MF_ERROR(MF_ERR_LIBRARY, "ARKODE: ARKStepSetFixedStep failed (%d)", rc);
                    break;
                }
            }
            int flag = integrator_evolve(&it, tout, y, &tret);
            if (it.fixed && (flag == ARK_CONV_FAILURE || flag == ARK_LSOLVE_FAIL) &&
                step_factor > 1.0 / 64) {
                /* Newton did not converge at a fixed step: redo the chunk with
                 * half the step */
                for (size_t k = 0; k < n; k++)
                    yv[k] = yprev[k];
                step_factor *= 0.5;
                if (ARKStepReset(it.mem, t, y) < 0) {
                    rc = MF_ERROR(MF_ERR_LIBRARY, "ARKODE: ARKStepReset failed");
                    break;
                }
                st->newton_fails++;
                continue;
            }
            if (flag < 0 && flag != ARK_TOO_MUCH_WORK) {
                rc = MF_ERROR(MF_ERR_LIBRARY,
                              "ARKODE %s failed at pseudo-time %g: %s (%s)",
                              o->imex ? "ARKStepEvolve" : "ERKStepEvolve",
                              st->pseudo_time + tret, err.msg,
                              o->imex ? ARKStepGetReturnFlagName(flag)
                                      : ERKStepGetReturnFlagName(flag));
                break;
            }
            const double dt = tret - t;
            double change = 0, drift = 0;
            for (size_t k = 0; k < n; k++) {
                if (fabs(yprev[k]) <= 1) {
                    double c = fabs(yv[k] - yprev[k]);
                    if (c > change)
                        change = c;
                }
                if (fabs(ybuild[k]) <= 2) {
                    double d = fabs(yv[k] - ybuild[k]);
                    if (d > drift)
                        drift = d;
                }
                yprev[k] = yv[k];
            }
            st->pseudo_time += dt;
            st->last_change = dt > 0 ? change / dt : INFINITY;
            t = tret;
            ls_stats now = *st;
            integrator_stats(&it, &now);
            /* Fixed steps near the advection limit can settle into a small
             * oscillation instead of the steady state: when the change stops
             * falling, halve the step. */
            if (it.fixed) {
                if (change / dt < 0.7 * best_rate) {
                    best_rate = change / dt;
                    stalled = 0;
                } else if (++stalled >= 4 && step_factor > 1.0 / 64) {
                    step_factor *= 0.5;
                    stalled = 0;
                    best_rate = change / dt;
                }
            }
            if (st->last_change < o->tolerance) {
                st->converged = true;
                done = true;
            } else if (flag == ARK_TOO_MUCH_WORK || now.steps >= o->max_steps ||
                       st->pseudo_time >= o->max_pseudo_time) {
                done = true;
            } else if (drift > 1.0) {
                rebuild_now = true;
            }
        }
        integrator_stats(&it, st);
        st->rhs_calls += r.evaluations;
        integrator_free(&it);
        if (rc == 0)
            for (size_t k = 0; k < n; k++)
                band->phi[band->act[k]] = yv[k];
        if (y)
            N_VDestroy(y);
        free(ybuild);
        free(yprev);
        ls_rhs_free(&r);
        if (rc == 0 && rebuild_now) {
            rc = rebuild(band, f);
            st->rebuilds++;
        }
    }
    SUNContext_Free(&ctx);
    return rc;
}
