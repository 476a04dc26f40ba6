/* ls_arkode.c: pseudo-time integration of eq. 29 with SUNDIALS ARKODE 6.
 *
 * The state vector is phi at the active band points (N_VNew_Serial over
 * them). Two integrators, chosen in the case (levelSetCoeffs/integrator):
 *   explicit  ERKStep with a damped Chebyshev table (first-order RKC of van
 *             der Houwen & Sommeijer, built here as a Butcher table and given
 *             to ERKStepSetTable) at fixed steps. Only the steady state
 *             matters, so the method is chosen for stability, not accuracy:
 *             s stages stretch the real stability interval to about 1.9 s^2
 *             (forward Euler: 2), where the curvature term's eigenvalues lie,
 *             while still holding the advection term's disk. For each band the
 *             pair (s, step) with the fewest right-hand sides per unit
 *             pseudo-time is found by testing the stability polynomial on the
 *             spectrum's bound (rkc_choose); a chunk whose change grows is
 *             redone with a smaller step;
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
 * LS_DRIFT_MAX cells since the band was built, the band is rebuilt around it
 * and the integrator restarted (its state is phi, so nothing else is lost). */
#include <complex.h>
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

/* ---- the explicit method: damped Chebyshev (RKC, first order) ----------- */

/* Damping: a wider stability region around the origin (the advection
 * term's disk) at a slightly shorter real interval; 0.3 gave the fewest
 * right-hand sides per unit pseudo-time for the spectra met here (bench and
 * tests: curvature bound 12 to 48, advection radius 0.2 to 2). */
#define RKC_EPS 0.3
#define RKC_SMAX 12
/* Steps at most this long (pseudo-time units): the closest-point speed and
 * the upwind switch change with phi, and the band may need a rebuild. */
#define RKC_DT_MAX 1.0
/* Fraction of the largest stable step taken. */
#define RKC_SAFETY 0.8
/* Rebuild the band when the zero level has moved this far (cells) from where
 * the band was built. The evolved band reaches bandWidth (3) cells, so the
 * level keeps a cell of evolved points beyond it; a rebuild re-marches the
 * band (serial) and restarts the transient: with 1 cell the bench's cold
 * frame rebuilt twice and took 57 right-hand sides instead of 42. */
#define LS_DRIFT_MAX 2.0

/* T_j(x) for j = 0..s (Chebyshev polynomials of the first kind). */
static void cheb_all(int s, double x, double *T)
{
    T[0] = 1;
    if (s >= 1)
        T[1] = x;
    for (int j = 2; j <= s; j++)
        T[j] = 2 * x * T[j - 1] - T[j - 2];
}

/* w0 = 1 + eps / s^2 and w1 = T_s(w0) / T_s'(w0), so R(z) = T_s(w0 + w1 z) /
 * T_s(w0) = 1 + z + O(z^2). */
static void rkc_w(int s, double *w0, double *w1)
{
    *w0 = 1 + RKC_EPS / (s * (double)s);
    double U[RKC_SMAX + 1]; /* U_j(w0), second kind: T_s' = s U_{s-1} */
    U[0] = 1;
    U[1] = 2 * *w0;
    for (int j = 2; j < s; j++)
        U[j] = 2 * *w0 * U[j - 1] - U[j - 2];
    double T[RKC_SMAX + 1];
    cheb_all(s, *w0, T);
    *w1 = T[s] / (s * U[s - 1]);
}

/* |R(z)| of the s-stage method. */
static double rkc_amp(int s, double w0, double w1, double Ts, double complex z)
{
    double complex x = w0 + w1 * z, a = 1, b = x;
    for (int j = 2; j <= s; j++) {
        double complex c = 2 * x * b - a;
        a = b;
        b = c;
    }
    return cabs(s == 0 ? a : b) / Ts;
}

/* Is the step dt stable for the spectrum bound of eq. 29's linearisation:
 * the curvature term's eigenvalues on [-lc, 0], the upwind advection term's
 * in the disk of radius ra through the origin (|z + ra| <= ra), and their
 * sums? */
static bool rkc_stable(int s, double lc, double ra, double dt)
{
    double w0, w1, T[RKC_SMAX + 1];
    rkc_w(s, &w0, &w1);
    cheb_all(s, w0, T);
    for (int i = 0; i <= 24; i++) {
        const double x = lc * dt * i / 24;
        for (int k = 0; k <= 36; k++) {
            const double th = M_PI * k / 36;
            double complex z = -x - ra * dt + ra * dt * cexp(I * th);
            if (rkc_amp(s, w0, w1, T[s], z) > 1 + 1e-9)
                return false;
        }
    }
    return true;
}

/* The stage count and step with the fewest right-hand sides per unit
 * pseudo-time for curvature bound lc and advection radius ra. */
static void rkc_choose(double lc, double ra, int *s_out, double *dt_out)
{
    double best = INFINITY;
    *s_out = 1;
    *dt_out = 1.0 / (lc / 2 + ra);
    for (int s = 1; s <= RKC_SMAX; s++) {
        double lo = 0, hi = 2 * RKC_DT_MAX / RKC_SAFETY;
        if (rkc_stable(s, lc, ra, hi))
            lo = hi;
        else
            for (int it = 0; it < 24; it++) {
                double m = 0.5 * (lo + hi);
                if (rkc_stable(s, lc, ra, m))
                    lo = m;
                else
                    hi = m;
            }
        const double dt = fmin(RKC_SAFETY * lo, RKC_DT_MAX);
        if (dt > 0 && s / dt < best * (1 - 1e-9)) {
            best = s / dt;
            *s_out = s;
            *dt_out = dt;
        }
    }
}

/* The s-stage method as a Butcher table. Its stages Y_0 = y,
 *   Y_1 = y + (w1/w0) h f(Y_0),
 *   Y_j = mu_j Y_{j-1} + nu_j Y_{j-2} + mut_j h f(Y_{j-1}),
 *   mu_j = 2 w0 T_{j-1}/T_j, nu_j = -T_{j-2}/T_j, mut_j = 2 w1 T_{j-1}/T_j
 * (T_j at w0; mu_j + nu_j = 1), are expanded into Y_j = y + h sum_k a_jk
 * f(Y_k); y_{n+1} = Y_s. No embedding: fixed steps. */
static ARKodeButcherTable rkc_table(int s)
{
    double w0, w1, T[RKC_SMAX + 1];
    rkc_w(s, &w0, &w1);
    cheb_all(s, w0, T);
    double a[RKC_SMAX + 1][RKC_SMAX];
    memset(a, 0, sizeof a);
    a[1][0] = w1 / w0;
    for (int j = 2; j <= s; j++) {
        const double mu = 2 * w0 * T[j - 1] / T[j], nu = -T[j - 2] / T[j],
                     mut = 2 * w1 * T[j - 1] / T[j];
        for (int k = 0; k < s; k++)
            a[j][k] = mu * a[j - 1][k] + nu * a[j - 2][k];
        a[j][j - 1] += mut;
    }
    ARKodeButcherTable B = ARKodeButcherTable_Alloc(s, SUNFALSE);
    if (!B)
        return NULL;
    B->q = 1;
    B->p = 0;
    for (int j = 0; j < s; j++) {
        double c = 0;
        for (int k = 0; k < s; k++) {
            B->A[j][k] = a[j][k];
            c += a[j][k];
        }
        B->c[j] = c;
        B->b[j] = a[s][j];
    }
    return B;
}

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
    int stages;            /* explicit: stages of the RKC table */
    double step;           /* explicit: its fixed step */
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

/* stages, step: the explicit method's (rkc_choose); unused for IMEX. */
static int integrator_create(integrator *it, const ls_evolve_opts *o, ls_rhs *r, N_Vector y,
                             SUNContext ctx, ark_err *err, int stages, double step)
{
    it->imex = o->imex;
    if (!o->imex) {
        it->stages = stages;
        it->step = step;
        it->mem = ERKStepCreate(f_all, 0.0, y, ctx);
        if (!it->mem)
            return MF_ERROR(MF_ERR_LIBRARY, "ARKODE: ERKStepCreate failed");
        ARK_CHECK(ERKStepSetErrHandlerFn(it->mem, on_error, err), "ERKStepSetErrHandlerFn");
        ARK_CHECK(ERKStepSStolerances(it->mem, o->rel_tol, o->abs_tol), "ERKStepSStolerances");
        ARKodeButcherTable B = rkc_table(stages);
        if (!B)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for a Butcher table");
        int flag = ERKStepSetTable(it->mem, B);
        ARKodeButcherTable_Free(B);
        ARK_CHECK(flag, "ERKStepSetTable");
        ARK_CHECK(ERKStepSetFixedStep(it->mem, step), "ERKStepSetFixedStep");
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
        st->stages = it->stages;
        st->step = it->step;
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

/* The explicit integrator for the current spectrum bound: the curvature
 * and advection bounds of ls_rhs_spectrum (the speed taken 1.25 times the
 * largest met so far, so that a growing speed does not force a new table
 * every chunk) divided by `factor` (< 1 after a chunk that grew). */
static int explicit_create(integrator *it, const ls_evolve_opts *o, ls_rhs *r, N_Vector y,
                           SUNContext ctx, ark_err *err, double factor, double *fmax_used)
{
    double lc, ra;
    *fmax_used = fmax(1.25 * r->fmax, *fmax_used);
    ls_rhs_spectrum(r, *fmax_used, &lc, &ra);
    int stages;
    double step;
    rkc_choose(lc / factor, ra / factor, &stages, &step);
    return integrator_create(it, o, r, y, ctx, err, stages, step);
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
        double fmax_used = 0;
        double *ybuild = malloc(n * sizeof *ybuild), *yprev = malloc(n * sizeof *yprev);
        N_Vector y = N_VNew_Serial((sunindextype)n, ctx);
        rc = ls_rhs_setup(&r);
        if (rc == 0 && (!ybuild || !yprev || !y))
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory for a state of %zu band points", n);
        double *yv = y ? N_VGetArrayPointer(y) : NULL;
        if (rc == 0) {
            for (size_t k = 0; k < n; k++)
                yv[k] = ybuild[k] = yprev[k] = band->phi[band->act[k]];
            /* one evaluation for the speed bound the step is chosen from */
            double *tmp = malloc(n * sizeof *tmp);
            if (tmp) {
                ls_rhs_eval(&r, yv, tmp, LS_RHS_ADVECTION);
                free(tmp);
            }
            rc = o->imex ? integrator_create(&it, o, &r, y, ctx, &err, 0, 0)
                         : explicit_create(&it, o, &r, y, ctx, &err, 1.0, &fmax_used);
        }
        bool rebuild_now = false;
        double t = 0, step_factor = 1, best_rate = INFINITY;
        int stalled = 0;
        while (rc == 0 && !done && !rebuild_now) {
            double tret = t, tout = t + CHUNK;
            int flag = 0;
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
                flag = ARKStepEvolve(it.mem, tout, y, &tret, ARK_NORMAL);
            } else {
                /* whole fixed steps, about CHUNK of pseudo-time */
                const int nsteps = (int)fmax(1.0, round(CHUNK / it.step));
                for (int q = 0; q < nsteps && flag >= 0; q++)
                    flag = ERKStepEvolve(it.mem, 1e12, y, &tret, ARK_ONE_STEP);
            }
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
            bool finite = true;
            for (size_t k = 0; k < n; k++) {
                finite = finite && isfinite(yv[k]);
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
            }
            const double rate = dt > 0 ? change / dt : INFINITY;
            if (!it.imex && (!finite || (rate > 2 * best_rate && change > 0.5)) &&
                step_factor > 1.0 / 64) {
                /* Growing: the spectrum bound was too small (the linearisation
                 * of the upwind switch and of the curvature clamp is only a
                 * guide). Redo the chunk with a bound twice as large. */
                for (size_t k = 0; k < n; k++)
                    yv[k] = yprev[k];
                step_factor *= 0.5;
                integrator_stats(&it, st);
                integrator_free(&it);
                rc = explicit_create(&it, o, &r, y, ctx, &err, step_factor, &fmax_used);
                t = 0;
                st->redone++;
                continue;
            }
            for (size_t k = 0; k < n; k++)
                yprev[k] = yv[k];
            st->pseudo_time += dt;
            st->last_change = rate;
            t = tret;
            ls_stats now = *st;
            integrator_stats(&it, &now);
            /* Fixed steps near the stability limit can settle into a small
             * oscillation instead of the steady state: when the change stops
             * falling, halve the step (IMEX) or double the spectrum bound
             * (explicit). */
            bool smaller = false;
            if (rate < 0.7 * best_rate) {
                best_rate = rate;
                stalled = 0;
            } else if (++stalled >= 4 && step_factor > 1.0 / 64) {
                step_factor *= 0.5;
                stalled = 0;
                best_rate = rate;
                smaller = !it.imex;
            }
            if (st->last_change < o->tolerance) {
                st->converged = true;
                done = true;
            } else if (flag == ARK_TOO_MUCH_WORK || now.steps >= o->max_steps ||
                       st->pseudo_time >= o->max_pseudo_time) {
                done = true;
            } else if (drift > LS_DRIFT_MAX) {
                rebuild_now = true;
            } else if (smaller || (!it.imex && r.fmax > fmax_used)) {
                /* a new table and step: the bound changed, or the speed grew
                 * past the one the step was chosen for */
                integrator_stats(&it, st);
                integrator_free(&it);
                rc = explicit_create(&it, o, &r, y, ctx, &err, step_factor, &fmax_used);
                t = 0;
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
