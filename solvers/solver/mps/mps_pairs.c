/* mps_pairs.c: the correction of eq. 15 with a coefficient per particle
 * pair, for a density per particle (the multi-fluid solver, eq. 27): the
 * gradient operator of core (mf_gradient_ex) with 1/rho_ij inside the sum,
 * then the update of eqs. 16-17. */
#include <math.h>

#include "mf_error.h"
#include "mf_operators.h"
#include "mps.h"

/* eq. 15 with 1/rho_ij inside the gradient sum (eq. 5): the same pair
 * coefficient as the PPE, so the correction is the one the PPE solved for
 * (1/rho with one fluid, rho NULL). */
int mps_gradient_pairs(mps_data *d, const mf_sim *sim, const double *pressure,
                       const uint8_t *imask)
{
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_grad, &v));
    const mf_gradient_opts o = {
        .f = pressure,
        .use_min = d->s.gradient_pmin,
        .own_reference = d->own_reference,
        .rho = d->rho,
        .rho_average = d->rho_average,
        .coef = 1.0 / d->rho_default,
    };
    mf_gradient_ex(&v, &d->k_grad, &o, imask ? imask : d->is_fluid, d->not_dummy, d->grad);
    return 0;
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
