/* multifluid_surface.c: the Laplace pressure on a free surface
 * (surfaceTension `freeSurface pressure`), the standard free-surface MPS
 * treatment of surface tension.
 *
 * The paper's form (eq. 33) applies sigma kappa delta n as a body force on
 * the interface band; in a free-surface MPS fluid the outer particle layers
 * of that band are Dirichlet particles of eq. 18 (n* < beta n0, p = 0), so
 * their share of the force meets no pressure and the pressure inside a drop
 * comes out about 0.7 sigma/R (README, "Multi-fluid"). Here the jump is the
 * pressure's boundary value instead: the free-surface particles hold
 * p = sigma kappa (mps_data.p_dirichlet; kappa the module's smoothed
 * curvature) and the module applies no force there, so the two are not
 * counted twice.
 *
 * The correction (eq. 15) then needs the surface particle's own pressure.
 * With gradientPmin the reference p^_i is the neighbourhood's minimum, which
 * drops p_i wherever it is the largest: at a convex tip (high kappa) the
 * inward push of its own Laplace pressure is lost, the tip is left behind as
 * the fluid under it flows away, and particles are shed (a 2-D square drop
 * blew apart at t = 0.6 s). So a Dirichlet particle takes p^_i = p_i; the
 * unknowns keep the minimum.
 */
#include <math.h>

#include "mf_error.h"
#include "multifluid.h"

int multifluid_surface_pressure_phase(multifluid_data *d, mf_sim *sim, double dt)
{
    mps_data *m = d->mps;
    MF_CALL(mps_surface_phase(m, sim));
    MF_CALL(mf_forces_surface_pressure(sim, m->dirichlet, d->p_dirichlet));
    MF_CALL(mps_halo_sync(m, sim, d->p_dirichlet, sizeof *d->p_dirichlet)); /* the PPE reads it */
    m->p_dirichlet = d->p_dirichlet;
    int rc = mps_assemble_ppe(m, sim, dt);
    if (rc == 0)
        rc = mps_solve_ppe(m, sim);
    m->p_dirichlet = NULL;
    return rc == 0 ? 0 : mf_error_trace(rc, __FILE__, __LINE__, __func__);
}

int multifluid_surface_correction(multifluid_data *d, mf_sim *sim, double dt)
{
    mps_data *m = d->mps;
    const double *pr = mf_particles_fd(sim->p, m->f_pressure);
    m->own_reference = m->dirichlet; /* p^_i = p_i on the free surface */
    int rc = mps_gradient_pairs(m, sim, pr, NULL);
    m->own_reference = NULL;
    MF_CALL(rc);
    mps_apply_correction(m, sim->p, dt, NULL);
    return 0;
}
