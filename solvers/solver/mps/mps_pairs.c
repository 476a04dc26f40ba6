/* mps_pairs.c: the MPS operators with a coefficient per particle pair, for
 * a density and a viscosity per particle (the multi-fluid solver, eq. 27).
 * The pair coefficients are the inline averages of mps.h; the loops are the
 * ones of core/particles/operators.c with that coefficient inside the sum. */
#include <math.h>

#include "mps.h"

/* r_ij = r_j - r_i and its length. */
static inline double pair_vector(const double *xi, const double *xj, double d[3])
{
    d[0] = xj[0] - xi[0];
    d[1] = xj[1] - xi[1];
    d[2] = xj[2] - xi[2];
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

/* The list of an operator's radius: the full list when it is the largest. */
static const mf_nlist *list_for(const mps_data *d, const mf_nlist *filtered, double re)
{
    return re >= d->nl_max.radius ? &d->nl_max : filtered;
}

/* eq. 27's nu_x <lap u>: (1/rho_i) 2d/(lambda n0) sum_j mu_ij (u_j - u_i) w_ij.
 * Like pairs give nu_x <lap u> (eq. 7); unlike pairs exchange momentum
 * through the pair viscosity, equal and opposite. Walls and dummies (u = 0)
 * take the viscosity of the fluid particle they touch. */
void mps_viscous_pairs(const mps_data *d, const mf_particles *p, const mf_nlist *nl,
                       double *acc)
{
    const double re = nl->radius, coef = 2.0 * d->k_lap.dim / (d->k_lap.lambda * d->k_lap.n0);
    const double *mu = d->mu, *rho = d->rho, *u = p->vel;
    const int avg = d->mu_average;
    const long np = (long)p->n_owned;
#pragma omp parallel for schedule(static)
    for (long i = 0; i < np; i++) {
        if (!d->is_fluid[i])
            continue;
        double a[3] = {0.0, 0.0, 0.0}, r[3];
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            size_t j = nl->j[k];
            double w = mf_weight(pair_vector(&p->pos[3 * i], &p->pos[3 * j], r), re);
            if (w <= 0.0)
                continue;
            double mu_ij = d->is_fluid[j] ? mps_mu_pair(mu[i], mu[j], avg) : mu[i];
            for (int c = 0; c < 3; c++)
                a[c] += mu_ij * (u[3 * j + c] - u[3 * i + c]) * w;
        }
        for (int c = 0; c < 3; c++)
            acc[3 * i + c] += coef * a[c] / rho[i];
    }
}

/* eq. 15 with 1/rho_ij inside the gradient sum (eq. 5): the same pair
 * coefficient as the PPE, so the correction is the one the PPE solved for
 * (1/rho with one fluid, rho NULL). */
void mps_gradient_pairs(mps_data *d, const mf_particles *p, const double *pressure,
                        const uint8_t *imask)
{
    const mf_nlist *nl = list_for(d, &d->nl_grad, d->k_grad.re);
    const double re = nl->radius, coef = d->k_grad.dim / d->k_grad.n0;
    const double *rho = d->rho;
    const int avg = d->rho_average;
    const bool use_min = d->s.gradient_pmin;
    const uint8_t *own = d->own_reference;
    const double inv_rho0 = 1.0 / d->rho_default;
    double *grad = d->grad;
    const long np = (long)p->n_owned;
#pragma omp parallel for schedule(static)
    for (long i = 0; i < np; i++) {
        if (!d->is_fluid[i] || (imask && !imask[i]))
            continue;
        double pi = pressure[i];
        if (use_min && !(own && own[i]))
            for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
                size_t j = nl->j[k];
                if (d->not_dummy[j] && pressure[j] < pi)
                    pi = pressure[j];
            }
        double g[3] = {0.0, 0.0, 0.0}, r[3];
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            size_t j = nl->j[k];
            if (!d->not_dummy[j])
                continue;
            double len = pair_vector(&p->pos[3 * i], &p->pos[3 * j], r);
            if (len <= 0.0)
                continue; /* coincident particles carry no direction */
            double inv_rho = rho ? mps_inv_rho_pair(rho[i], rho[j], avg) : inv_rho0;
            double s = (pressure[j] - pi) * inv_rho * mf_weight(len, re) / (len * len);
            for (int c = 0; c < 3; c++)
                g[c] += s * r[c];
        }
        for (int c = 0; c < 3; c++)
            grad[3 * i + c] = coef * g[c];
    }
}

/* eqs. 16-17: u' = -dt grad, u += u', r += dt u'. */
double mps_apply_correction(mps_data *d, mf_particles *p, double dt, const uint8_t *imask)
{
    double du_max = 0.0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->is_fluid[i] || (imask && !imask[i]))
            continue;
        double du2 = 0.0;
        for (int c = 0; c < 3; c++) {
            double du = -dt * d->grad[3 * i + c];
            p->vel[3 * i + c] += du;
            p->pos[3 * i + c] += dt * du;
            du2 += du * du;
        }
        if (du2 > du_max * du_max)
            du_max = sqrt(du2);
    }
    return du_max;
}
