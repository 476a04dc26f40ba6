/* mps_step.c: one MPS step, phase by phase (the paper's Algorithm 1). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_lsmps.h"
#include "mf_operators.h"
#include "mf_run.h"
#include "mps.h"

int mps_pairs(const mps_data *d, const mf_sim *sim, int handle, mf_pairs *out)
{
    MF_CALL(mf_neighbours_pairs(d->nb, sim->p, handle, out));
    return 0;
}

int mps_build_neighbours(mps_data *d, mf_sim *sim, bool reorder)
{
    double t0 = mf_wall_seconds();
    mf_particles *p = sim->p;
    if (d->halo) /* drop the last copies, wrap; migrate at the start of a step */
        MF_CALL(mps_halo_begin(d, sim, reorder));
    if (reorder && d->s.reorder_interval > 0 && sim->step % d->s.reorder_interval == 0) {
        /* Sort along cells: neighbours become neighbours in memory too. */
        size_t *perm = malloc((p->n ? p->n : 1) * sizeof *perm);
        if (!perm)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory reordering particles");
        int rc = mf_neighbours_locality_order(d->nb, p, d->h_max, perm);
        if (rc == 0)
            rc = mf_particles_permute(p, perm);
        free(perm);
        MF_CALL(rc);
    }
    if (d->halo) /* copies from other ranks and across the period */
        MF_CALL(mps_halo_add(d, sim, !reorder)); /* reorder: the build at r^n */
    MF_CALL(mf_neighbours_update(d->nb, p, d->h_max));
    d->t_neighbours += mf_wall_seconds() - t0;
    return 0;
}

void mps_set_masks(mps_data *d, const mf_particles *p)
{
    for (size_t i = 0; i < p->n; i++) {
        d->is_fluid[i] = p->kind[i] == MF_FLUID;
        d->not_dummy[i] = p->kind[i] != MF_DUMMY;
    }
}

/* Is there a pair at all (the first ends the row)? */
static inline bool any_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    (void)ctx;
    (void)pr;
    *(bool *)acc = true;
    return false;
}

/* Optional collision model (Koshizuka lab's MPS codes, mf_collision):
 * approaching pairs closer than the collision distance exchange momentum
 * with restitution e; positions follow the velocity change. */
static int collide(mps_data *d, mf_sim *sim, double dt)
{
    mf_particles *p = sim->p;
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_coll, &v));
    double *vnew = d->grad; /* scratch: the new velocities */
    mf_collision(&v, d->is_fluid, d->rho, d->s.restitution, p->vel, vnew);
    for (size_t i = 0; i < p->n_owned; i++)
        if (d->is_fluid[i])
            for (int c = 0; c < 3; c++) {
                p->pos[3 * i + c] += dt * (vnew[3 * i + c] - p->vel[3 * i + c]);
                p->vel[3 * i + c] = vnew[3 * i + c];
            }
    return 0;
}

/* The viscous term of eqs. 9 and 27 with the scheme's Laplacian: the
 * higher-order one (Khayyer & Gotoh 2010), or LSMPS (Tamai & Koshizuka
 * 2014) for one fluid, eq. 7 where its fit is singular; with a viscosity per
 * particle leastSquares takes the higher-order form (the pair viscosity
 * mu_ij has no least-squares counterpart here). */
static int viscous_term(mps_data *d, mf_sim *sim)
{
    mf_particles *p = sim->p;
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_lap, &v));
    if (d->mu) {
        mf_laplacian_hl_mu(&v, &d->k_lap, p->vel, d->mu, d->mu_average, d->is_fluid, d->rho,
                           d->is_fluid, d->acc);
        return 0;
    }
    const double nu = sim->fluid[0].nu;
    if (d->sc.laplacian == MPS_LAPLACIAN_HIGHER_ORDER) {
        mf_laplacian_hl_add(&v, &d->k_lap, p->vel, nu, d->is_fluid, NULL, d->acc);
        return 0;
    }
    MF_CALL(mps_scheme_reserve(d, p->n));
    uint8_t *failed = d->flag_work;
    memset(failed, 0, p->n);
    /* wall wallWeight: the walls' virtual points in each fit (mps_wall.c) */
    size_t nfailed = d->wall ? mps_wall_lsmps_laplacian(d, sim, &v, nu, failed)
                             : mf_lsmps_laplacian_add(&v, &d->k_lap, p->vel, nu, d->is_fluid,
                                                      d->not_dummy, d->acc, failed);
    if (nfailed) {
        d->ls_fallbacks += (long)nfailed;
        mf_laplacian_add(&v, &d->k_lap, p->vel, nu, failed, NULL, d->acc);
        if (d->wall) /* and eq. 7's wall term there */
            mps_wall_viscous_where(d, sim, nu, failed);
    }
    return 0;
}

/* A retry: the run loop (core/run/run.c) restored the particles and calls
 * again from the same time and step with a shorter dt. The density terms of
 * the scheme's source (mps_source.c) then keep the first attempt's
 * strength, dt / dt_first: a density error (n - n0)/n0 corrected within one
 * step needs a velocity of (n - n0)/n0 l / dt, which each halving would
 * double, driving the particle-scale noise of n* harder at every retry (the
 * 1/dt^2 of eq. 14). Eq. 14 itself (source density) is left as printed. */
static void retry_scale(mps_data *d, const mf_sim *sim, double dt)
{
    if (d->s.retry_source && sim->step == d->attempt_step && sim->time == d->attempt_time &&
        dt < d->attempt_dt) {
        d->density_scale = dt / d->attempt_dt;
        return;
    }
    d->attempt_step = sim->step;
    d->attempt_time = sim->time;
    d->attempt_dt = dt;
    d->density_scale = 1.0;
}

/* grad and acc are dead from the end of the explicit phase to the
 * correction: their pages given back (mf_release_pages) so that the lists
 * at r*, the assembly and the solve do not stack on them; each is rewritten
 * before it is read again. grad: the correction's gradient (and the
 * collision's new velocities) write it first; worst_row (mps_ppe.c) writes
 * the part it uses; the multi-fluid rounds write it before they read it.
 * acc: zeroed at the next explicit phase, but wallPressureExtrapolated
 * without wall weight reads it in the correction (mps_wall_pressure.c),
 * so there it is kept. */
static void release_step_scratch(mps_data *d)
{
    (void)mf_release_pages(d->grad, 3 * d->cap * sizeof *d->grad);
    if (!(d->s.wall_pressure_extrapolated && !d->wall))
        (void)mf_release_pages(d->acc, 3 * d->cap * sizeof *d->acc);
}

/* eqs. 9-10: u* = u + dt (nu lap u + forces), r* = r + dt u*. With a
 * density and viscosity per particle (mps_data.mu), eq. 27: each particle's
 * own nu, pairs of unlike particles through mu_ij. */
int mps_explicit_phase(mps_data *d, mf_sim *sim, double dt)
{
    double t0 = mf_wall_seconds();
    d->attempts++;
    mf_particles *p = sim->p;
    const double nu = sim->fluid[0].nu;
    retry_scale(d, sim, dt);
    /* The mixed source's n at r^n rides in the viscous term's pass when both
     * are eq. 3's sums over the same pairs (the same values, one pass); not
     * with wall weight, whose share is added to n at r^n (mps_wall.c). */
    const bool nd_with_viscosity = !d->visc && !d->mu && !d->wall && nu > 0 &&
                                   d->sc.laplacian == MPS_LAPLACIAN_PAPER &&
                                   mps_source_mixed(d->sc.source) && d->k_nd.re == d->k_lap.re;
    if (d->wall) /* wall weight: the walls' sums at r^n */
        MF_CALL(mps_wall_points(d, sim));
    if (nd_with_viscosity)
        MF_CALL(mps_scheme_reserve(d, p->n));
    else
        MF_CALL(mps_source_start(d, sim)); /* what the scheme's source needs of r^n, u^n */
    mps_bodies_begin(d, sim);
    memset(d->acc, 0, 3 * p->n * sizeof *d->acc);
    MF_CALL(mf_force_accumulate(sim, d->acc));
    if (d->wall) /* the force acceleration continues the pressure into the walls */
        mps_wall_keep_forces(d, sim);
    if (d->visc) { /* viscosity implicit: u* = (I - dt nu lap)^-1 (u + dt a), r* = r + dt u* */
        MF_CALL(mps_viscosity_implicit(d, sim, dt));
    } else if ((d->mu || nu > 0) && d->sc.laplacian != MPS_LAPLACIAN_PAPER) {
        MF_CALL(viscous_term(d, sim));
    } else if (d->mu || nu > 0) {
        mf_pairs v;
        MF_CALL(mps_pairs(d, sim, d->h_lap, &v));
        if (d->mu) /* eq. 27: each pair through mu_ij, walls and dummies with mu_i */
            mf_laplacian_mu(&v, &d->k_lap, p->vel, d->mu, d->mu_average, d->is_fluid, d->rho,
                            d->is_fluid, d->acc);
        else if (nd_with_viscosity)
            mf_laplacian_add_number_density(&v, &d->k_lap, p->vel, nu, d->not_dummy, d->is_fluid,
                                            d->acc, d->n_start);
        else
            mf_laplacian_add(&v, &d->k_lap, p->vel, nu, d->is_fluid, NULL, d->acc);
    }
    /* no slip on the walls' faces (leastSquares for one fluid: in its fit) */
    if (d->wall && nu > 0 && (d->mu || d->sc.laplacian != MPS_LAPLACIAN_LEAST_SQUARES))
        mps_wall_viscous(d, sim, nu);
    MF_CALL(mps_bodies_viscous(d, sim)); /* the rigid bodies' share, at r^n */
    MF_CALL(mps_velocity_filter(d, sim)); /* on u^n, before u* (mps_xsph.c) */
    for (size_t i = 0; i < p->n_owned && !d->visc; i++) {
        if (!d->is_fluid[i])
            continue;
        for (int c = 0; c < 3; c++) {
            p->vel[3 * i + c] += dt * d->acc[3 * i + c];
            p->pos[3 * i + c] += dt * p->vel[3 * i + c];
        }
    }
    if (d->wall) /* u*: what the wall's pressure will stop (mps_wall.c) */
        mps_wall_keep_approach(d, sim, dt);
    if (d->halo) /* copies move with their owners (the collision model reads them) */
        MF_CALL(mps_halo_sync_motion(d, sim));
    if (d->s.collision)
        MF_CALL(collide(d, sim, dt));
    if (d->s.collision && d->wall)
        MF_CALL(mps_wall_collide(d, sim, dt));
    release_step_scratch(d);
    d->t_explicit += mf_wall_seconds() - t0;
    return 0;
}

/* Free surface by eq. 18 and the asymmetry of the neighbourhood (Khayyer,
 * Gotoh & Shao 2009, Appl. Ocean Res. 31, 111-131, section 3.3): a fluid
 * particle with n* < beta n0 is on the free surface only where its
 * neighbours (walls and dummies included) lie to one side, |(1/n0) sum_j
 * r_ij/|r_ij| w_ij| above `asymmetry` times that of a flat free surface: a
 * particle beside a wall, or inside a thin sheet between two of its faces,
 * whose n* has dipped is not; one with n* below MPS_SPARSE n0 (spray, a
 * chain of particles: symmetric but no bulk around it) is. A wall particle takes part as an unknown
 * while a fluid particle is within the gradient's radius of it (a thin
 * sheet on a floor is held up by the floor's pressure), else it is on the
 * surface (p = 0); its source is clipped at zero (mps_ppe.c): a wall pushes
 * and does not pull. Into d->flag_work: 1 on the surface. */
#define MPS_SPARSE 0.8
static int detect_by_asymmetry(mps_data *d, mf_sim *sim)
{
    mf_particles *p = sim->p;
    const double *n = mf_particles_fd(p, d->f_number_density);
    const double *F = d->work; /* the asymmetry of the fluid (mps_surface_phase) */
    mf_pairs vg;
    MF_CALL(mps_pairs(d, sim, d->h_grad, &vg));
    const double thr = d->s.asymmetry * d->k_nd.asym_flat, n0 = d->k_nd.n0;
    uint8_t *surface = d->flag_work;
    for (size_t i = 0; i < p->n_owned; i++) {
        surface[i] = 0;
        if (!d->not_dummy[i] || !(n[i] < d->s.beta * n0))
            continue;
        if (d->is_fluid[i]) {
            const double *f = &F[3 * i];
            surface[i] = n[i] < MPS_SPARSE * n0 ||
                         sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]) > thr;
        } else {
            bool contact = false;
            mf_pairs_row_r2(&vg, i, d->is_fluid, any_pair, NULL, &contact);
            surface[i] = !contact;
        }
    }
    return 0;
}

/* eq. 18: number density at r*, free surface, the PPE's unknowns. */
int mps_surface_phase(mps_data *d, mf_sim *sim)
{
    double t0 = mf_wall_seconds();
    mf_particles *p = sim->p;
    double *n = mf_particles_fd(p, d->f_number_density);
    int32_t *flags = mf_particles_fi(p, d->f_flags);
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_nd, &v));
    const double n0 = d->k_nd.n0;
    const bool asymmetry = d->sc.detection == MPS_DETECT_ASYMMETRY;
    if (asymmetry)
        MF_CALL(mps_scheme_reserve(d, p->n));
    if (asymmetry && !d->wall) /* n* of the particles and the fluid's asymmetry in one pass */
        mf_number_density_asymmetry(&v, &d->k_nd, d->not_dummy, d->is_fluid, n, d->work);
    else
        mf_number_density(&v, d->not_dummy, NULL, n);
    if (d->wall) { /* the walls' sums at r*, their number density */
        MF_CALL(mps_wall_points(d, sim));
        mps_wall_number_density(d, sim, n);
        if (asymmetry) /* after the walls' sums, which may use the scratch */
            mf_neighbour_asymmetry(&v, &d->k_nd, d->is_fluid, NULL, d->work);
    }
    if (asymmetry)
        MF_CALL(detect_by_asymmetry(d, sim));
    for (size_t i = 0; i < p->n_owned; i++) {
        bool surface = d->sc.detection == MPS_DETECT_ASYMMETRY
                           ? d->flag_work[i]
                           : d->not_dummy[i] && n[i] < d->s.beta * n0;
        d->dirichlet[i] = surface;
        d->in_ppe[i] = d->not_dummy[i] && !surface;
        flags[i] = surface ? MPS_FLAG_SURFACE : 0;
        if (!d->not_dummy[i])
            n[i] = 0; /* dummies take part only as neighbours */
    }
    if (d->halo) /* a copy is what its owner is (its unknowns: mps_assemble_ppe) */
        MF_CALL(mps_halo_sync(d, sim, d->dirichlet, 1));
    d->t_assembly += mf_wall_seconds() - t0;
    return 0;
}

/* A composing solver's hook before the assembly (mps_data.before_assembly). */
static int run_before_assembly(mps_data *d, mf_sim *sim)
{
    if (!d->before_assembly)
        return 0;
    MF_CALL(d->before_assembly(d, sim, d->before_assembly_ctx));
    return 0;
}

/* eqs. 11-14 and 18: number density at r*, free surface, PPE. */
int mps_pressure_phase(mps_data *d, mf_sim *sim, double dt)
{
    MF_CALL(mps_surface_phase(d, sim));
    MF_CALL(run_before_assembly(d, sim));
    MF_CALL(mps_assemble_ppe(d, sim, dt));
    /* The scheme's source is dead until the next step too (the rest was
     * released in the assembly): its pages given back, so that the solve's
     * peak (the AMG set-up) does not stack on them. */
    (void)mps_scheme_release(d, true);
    MF_CALL(mps_solve_ppe(d, sim));
    return 0;
}

/* eqs. 15-17: u' = -(dt/rho) <grad p>, u = u* + u', r = r* + dt u'. */
int mps_correction_phase(mps_data *d, mf_sim *sim, double dt)
{
    double t0 = mf_wall_seconds();
    mf_particles *p = sim->p;
    const double *pr = mf_particles_fd(p, d->f_pressure);
    if (d->rho || d->sc.gradient != MPS_GRADIENT_PAPER) {
        /* a density per particle (1/rho_ij in the sum) or the scheme's gradient */
        MF_CALL(mps_gradient_pairs(d, sim, pr, NULL));
        MF_CALL(mps_bodies_pressure(d, sim, pr)); /* the rigid bodies' share, at r* */
        mps_apply_correction(d, p, dt, NULL);
        if (!d->rho && d->s.collision && d->s.collision_after_correction)
            MF_CALL(collide(d, sim, dt));
        d->t_correction += mf_wall_seconds() - t0;
        MF_CALL(mps_shift(d, sim));
        return 0;
    }
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_grad, &v));
    if (d->s.wall_pressure_extrapolated && !d->wall) { /* the walls' p by the Neumann condition */
        MF_CALL(mps_scheme_reserve(d, p->n));
        /* copies (other ranks', periodic images) carry no force of their own
         * at r*: their owners' f, then their owners' p_w */
        MF_CALL(mps_halo_sync(d, sim, d->acc, 3 * sizeof *d->acc));
        mps_wall_pressure_extrapolate(d, sim, &v, pr, d->work);
        MF_CALL(mps_halo_sync(d, sim, d->work, sizeof *d->work));
        pr = d->work;
    }
    mf_gradient(&v, &d->k_grad, pr, d->s.gradient_pmin, d->is_fluid, d->not_dummy, d->grad);
    MF_CALL(mps_bodies_pressure(d, sim, pr)); /* the rigid bodies' share, at r* */
    const double rho = sim->fluid[0].rho;
    if (d->wall) { /* the walls' part, with eq. 5's p^ of each particle */
        MF_CALL(mps_scheme_reserve(d, p->n));
        double *phat = d->work;
        mf_neighbour_min(&v, pr, d->s.gradient_pmin, NULL, d->is_fluid, d->not_dummy, phat);
        mps_wall_gradient(d, sim, pr, phat, rho);
    }
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->is_fluid[i])
            continue;
        for (int c = 0; c < 3; c++) {
            double du = -dt / rho * d->grad[3 * i + c];
            p->vel[3 * i + c] += du;
            p->pos[3 * i + c] += dt * du;
        }
    }
    if (d->s.collision && d->s.collision_after_correction) {
        if (d->halo) /* the corrected motion of the copies' owners */
            MF_CALL(mps_halo_sync_motion(d, sim));
        MF_CALL(collide(d, sim, dt));
    }
    d->t_correction += mf_wall_seconds() - t0;
    MF_CALL(mps_shift(d, sim));
    return 0;
}

int mps_lagrangian_step(mps_data *d, mf_sim *sim, double dt)
{
    MF_CALL(mps_reserve(d, sim->p->n));
    MF_CALL(mps_build_neighbours(d, sim, true)); /* at r^n, for viscosity */
    mps_set_masks(d, sim->p);
    MF_CALL(mps_explicit_phase(d, sim, dt));
    MF_CALL(mps_build_neighbours(d, sim, false)); /* at r*, for the pressure */
    MF_CALL(mps_pressure_phase(d, sim, dt));
    MF_CALL(mps_correction_phase(d, sim, dt));
    if (d->halo)
        mps_halo_end(d, sim); /* drop the copies, wrap */
    return 0;
}
