/* multifluid_pressure.c: the iterative two-step pressure of section 3.4,
 * for fluids of very different densities (water and air).
 *
 * The number density and the free surface are taken once at r*; then
 * rounds of two solves:
 *   1. light solve: round 1, the PPE over every particle as if all were the
 *      light fluid (heavy particles take the lightest density), the paper's
 *      first step; later rounds, the light fluid alone (light particles and
 *      the walls no heavy particle touches) holding the heavy solve's
 *      pressure on the heavy particles, so that pressure is continuous and a
 *      pocket of air trapped under water takes the water's pressure;
 *   2. heavy solve: the PPE of the heavy fluid(s) (and the walls they touch)
 *      with their own densities; every other particle that takes part
 *      holds its light-solve pressure: the light pressure applied on the
 *      heavy fluid's interface. Free-surface particles hold p = 0 (eq. 18).
 * After each round the correction each fluid's pressure makes is computed
 * (eq. 15: light particles with the light solve's pressure and densities,
 * heavy ones with the heavy solve's); rounds repeat until that correction
 * moves no fluid particle by more than outerTolerance l0 against the last
 * round's (velocities change by less than outerTolerance l0 / dt), or
 * maxOuterIterations rounds are made. Then positions and velocities are
 * corrected once (eqs. 16-17). After round 1 this is block Gauss-Seidel on
 * the variable-density PPE, split by fluid.
 *
 * Each round and each solve is logged ("Solving for p_<fluid>" in
 * OpenFOAM's form). The Pressure field ends as the heavy solve's pressure
 * on its unknowns and the light solve's elsewhere; the light solve's is
 * kept in the LightPressure field (the next step's warm start, and a
 * restart's).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mf_error.h"
#include "mf_run.h"
#include "multifluid.h"

/* Does i touch a heavy particle? (stops at the first) */
static inline bool heavy_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const multifluid_data *d = ctx;
    if (!d->heavy_mask[pr->j])
        return true;
    *(bool *)acc = true;
    return false;
}

/* The heavy solve's unknowns: heavy fluid particles and walls touching one,
 * among the unknowns of the full system (not free surface, not dummy). */
static int set_heavy_unknowns(multifluid_data *d, const mf_sim *sim, size_t *count)
{
    mps_data *m = d->mps;
    const mf_particles *p = sim->p;
    mf_pairs v;
    MF_CALL(mps_pairs(m, sim, m->h_lap, &v));
    *count = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        bool in = false;
        if (d->in_all[i]) {
            if (p->kind[i] == MF_FLUID)
                in = d->heavy_mask[i];
            else
                mf_pairs_row_r2(&v, i, NULL, heavy_pair, d, &in);
        }
        m->in_ppe[i] = in;
        *count += in;
    }
    return 0;
}

/* "p_<name>" when a group is one fluid, else "p_light" / "p_heavy". */
static void solve_names(const multifluid_data *d, const mf_sim *sim, char *light, char *heavy,
                        size_t len)
{
    int nl = 0, nh = 0, il = 0, ih = 0;
    for (int k = 0; k < sim->nfluids; k++) {
        if (d->heavy[k]) {
            nh++;
            ih = k;
        } else {
            nl++;
            il = k;
        }
    }
    if (nl == 1)
        snprintf(light, len, "p_%s", sim->fluid[il].name);
    else
        snprintf(light, len, "p_light");
    if (nh == 1)
        snprintf(heavy, len, "p_%s", sim->fluid[ih].name);
    else
        snprintf(heavy, len, "p_heavy");
}

static int run_solve(mps_data *m, mf_sim *sim, double dt)
{
    MF_CALL(mps_assemble_ppe(m, sim, dt));
    MF_CALL(mps_solve_ppe(m, sim));
    return 0;
}

/* The light solve of round k: k = 1 every particle as the light fluid
 * (the paper's first step); k > 1 the light fluid alone, holding the heavy
 * solve's pressure on the heavy particles (pressure is continuous across the
 * interface, so a pocket of air trapped in water takes the water's pressure). */
static int light_solve(multifluid_data *d, mf_sim *sim, double dt, long k, double *P, double *pl)
{
    mps_data *m = d->mps;
    const size_t n = sim->p->n_owned;
    if (k == 1) {
        memcpy(m->in_ppe, d->in_all, n);
        m->rho = d->rho_light;
        m->p_dirichlet = NULL;
        memcpy(P, pl, n * sizeof *P); /* warm start from the last light solve */
    } else {
        for (size_t i = 0; i < n; i++)
            m->in_ppe[i] = d->in_all[i] && !d->heavy_rows[i];
        m->rho = d->rho;
        memcpy(d->p_dirichlet, P, n * sizeof *P); /* the heavy solve's pressure */
        MF_CALL(mps_halo_sync(m, sim, d->p_dirichlet, sizeof *d->p_dirichlet));
        m->p_dirichlet = d->p_dirichlet;
        memcpy(P, pl, n * sizeof *P);
    }
    MF_CALL(run_solve(m, sim, dt));
    memcpy(pl, P, sim->p->n * sizeof *P); /* copies too: the solve synchronised P */
    return 0;
}

static int rounds(multifluid_data *d, mf_sim *sim, double dt, long *made, double *dr_last)
{
    mps_data *m = d->mps;
    mf_particles *p = sim->p;
    const size_t n = p->n_owned;
    double *P = mf_particles_fd(p, m->f_pressure);
    double *pl = mf_particles_fd(p, d->f_light_pressure);
    char name_light[80], name_heavy[80];
    solve_names(d, sim, name_light, name_heavy, sizeof name_light);
    MF_CALL(mps_surface_phase(m, sim)); /* at r*: number density, free surface */
    memcpy(d->in_all, m->in_ppe, n);
    size_t rows = 0;
    MF_CALL(set_heavy_unknowns(d, sim, &rows)); /* fills m->in_ppe */
    double global_rows = (double)rows;
    mf_parallel_sum(sim->par, &global_rows, 1); /* every rank solves, or none */
    rows = (size_t)global_rows;
    memcpy(d->heavy_rows, m->in_ppe, n);
    memcpy(d->p_prev, P, n * sizeof *P);
    *made = 0;
    for (long k = 1; k <= d->s.max_outer; k++) {
        /* 1. the light fluid */
        mf_log_printf(sim->log, MF_LOG_STEP, "multiFluid: round %ld: light solve (%s)\n", k,
                      k == 1 ? "every particle as the light fluid"
                             : "the heavy pressure held on the heavy particles");
        m->solve_name = name_light;
        memcpy(P, d->p_prev, n * sizeof *P); /* heavy values (k > 1: this round's) */
        MF_CALL(light_solve(d, sim, dt, k, P, pl));
        /* 2. the heavy fluid, the light pressure held around it */
        mf_log_printf(sim->log, MF_LOG_STEP,
                      "multiFluid: round %ld: heavy solve (%zu unknowns, light pressure on its "
                      "interface)\n",
                      k, rows);
        memcpy(m->in_ppe, d->heavy_rows, n);
        m->rho = d->rho;
        m->p_dirichlet = pl;
        m->solve_name = name_heavy;
        memcpy(P, d->p_prev, n * sizeof *P); /* warm start from the last heavy solve */
        if (rows > 0)
            MF_CALL(run_solve(m, sim, dt));
        else
            memcpy(P, pl, p->n * sizeof *P); /* copies too: pl's are its owners' */
        memcpy(d->p_prev, P, n * sizeof *P);
        /* 3. the correction each fluid's pressure makes (eq. 15), not applied
         * yet: the round has converged when it moves no particle by more
         * than the tolerance against the last round's. */
        double tc = mf_wall_seconds();
        memcpy(d->grad_prev, m->grad, 3 * n * sizeof *m->grad);
        m->rho = k == 1 ? d->rho_light : d->rho;
        MF_CALL(mps_gradient_pairs(m, sim, pl, d->light_mask));
        m->rho = d->rho;
        MF_CALL(mps_gradient_pairs(m, sim, P, d->heavy_mask));
        double change = 0;
        for (size_t i = 0; i < n; i++) {
            if (!d->light_mask[i] && !d->heavy_mask[i])
                continue;
            double c2 = 0;
            for (int c = 0; c < 3; c++) {
                double g = m->grad[3 * i + c] - (k > 1 ? d->grad_prev[3 * i + c] : 0.0);
                c2 += g * g;
            }
            if (c2 > change * change)
                change = sqrt(c2);
        }
        mf_parallel_max(sim->par, &change, 1); /* one decision for every rank */
        m->t_correction += mf_wall_seconds() - tc;
        double du = change * dt, dr = du * dt / sim->l0;
        *made = k;
        *dr_last = dr;
        mf_log_printf(sim->log, MF_LOG_STEP,
                      "multiFluid: round %ld: max |du| = %g m/s, max |dr| = %g l0 %s(tolerance "
                      "%g)\n",
                      k, du, dr, k > 1 ? "against the last round " : "", d->s.outer_tolerance);
        if (!(dr >= d->s.outer_tolerance))
            break; /* converged (a NaN is left to the time loop's check) */
    }
    double tc = mf_wall_seconds();
    mps_apply_correction(m, p, dt, NULL); /* eqs. 16-17 with the last round's */
    m->t_correction += mf_wall_seconds() - tc;
    return 0;
}

int multifluid_iterative_pressure(multifluid_data *d, mf_sim *sim, double dt)
{
    mps_data *m = d->mps;
    const mf_particles *p = sim->p;
    const int32_t *fid = mf_particles_fi(p, d->f_fluid);
    for (size_t i = 0; i < p->n_owned; i++) {
        bool fluid = p->kind[i] == MF_FLUID;
        d->heavy_mask[i] = fluid && d->heavy[fid[i]];
        d->light_mask[i] = fluid && !d->heavy[fid[i]];
    }
    /* A wall is in the heavy solve when a heavy particle, maybe another
     * rank's, is near: the copies' masks. */
    MF_CALL(mps_halo_sync(m, sim, d->heavy_mask, sizeof *d->heavy_mask));
    long made = 0;
    double dr = 0;
    int rc = rounds(d, sim, dt, &made, &dr);
    m->rho = d->rho;
    m->p_dirichlet = NULL;
    m->solve_name = NULL;
    MF_CALL(rc);
    bool converged = dr < d->s.outer_tolerance;
    d->iterative_steps++;
    d->outer_total += made;
    if (made > d->outer_max)
        d->outer_max = made;
    if (!converged)
        d->unconverged++;
    mf_log_printf(sim->log, MF_LOG_STEP,
                  "multiFluid: pressure %s after %ld round(s) (max |dr| = %g l0)\n",
                  converged ? "converged" : "NOT converged", made, dr);
    return 0;
}
