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

#include "forces/forces.h"
#include "mf_error.h"
#include "multifluid.h"

int multifluid_surface_pressure_phase(multifluid_data *d, mf_sim *sim, double dt)
{
    mps_data *m = d->mps;
    MF_CALL(mps_surface_phase(m, sim));
    mf_forces_surface_pressure(sim, m->dirichlet, d->p_dirichlet);
    m->p_dirichlet = d->p_dirichlet;
    int rc = mps_assemble_ppe(m, sim, dt);
    if (rc == 0)
        rc = mps_solve_ppe(m, sim);
    m->p_dirichlet = NULL;
    return rc == 0 ? 0 : mf_error_trace(rc, __FILE__, __LINE__, __func__);
}

static inline double pair_vector(const double *xi, const double *xj, double r[3])
{
    r[0] = xj[0] - xi[0];
    r[1] = xj[1] - xi[1];
    r[2] = xj[2] - xi[2];
    return sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
}

/* eq. 15 as mps_gradient_pairs, with p^_i = p_i on the Dirichlet particles.
 * One fluid: 1/rho_ij = 1/rho. */
static void surface_gradient(multifluid_data *d, const mf_sim *sim, const double *pressure)
{
    mps_data *m = d->mps;
    const mf_particles *p = sim->p;
    const mf_nlist *nl = m->k_grad.re >= m->nl_max.radius ? &m->nl_max : &m->nl_grad;
    const double re = nl->radius, coef = m->k_grad.dim / m->k_grad.n0;
    const double *rho = m->rho, rho0 = sim->fluid[0].rho;
    const int avg = m->rho_average;
    const long np = (long)p->n_owned;
#pragma omp parallel for schedule(static)
    for (long i = 0; i < np; i++) {
        if (!m->is_fluid[i])
            continue;
        double pi = pressure[i];
        if (m->s.gradient_pmin && !m->dirichlet[i])
            for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
                size_t j = nl->j[k];
                if (m->not_dummy[j] && pressure[j] < pi)
                    pi = pressure[j];
            }
        double g[3] = {0.0, 0.0, 0.0}, r[3];
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            size_t j = nl->j[k];
            if (!m->not_dummy[j])
                continue;
            double len = pair_vector(&p->pos[3 * i], &p->pos[3 * j], r);
            if (len <= 0.0)
                continue;
            double inv_rho = rho ? mps_inv_rho_pair(rho[i], rho[j], avg) : 1.0 / rho0;
            double s = (pressure[j] - pi) * inv_rho * mf_weight(len, re) / (len * len);
            for (int c = 0; c < 3; c++)
                g[c] += s * r[c];
        }
        for (int c = 0; c < 3; c++)
            m->grad[3 * i + c] = coef * g[c];
    }
}

int multifluid_surface_correction(multifluid_data *d, mf_sim *sim, double dt)
{
    mps_data *m = d->mps;
    const double *pr = mf_particles_fd(sim->p, m->f_pressure);
    surface_gradient(d, sim, pr);
    mps_apply_correction(m, sim->p, dt, NULL);
    return 0;
}
