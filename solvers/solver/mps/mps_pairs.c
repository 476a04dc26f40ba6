/* mps_pairs.c: the correction of eq. 15 with a coefficient per particle
 * pair, for a density per particle (the multi-fluid solver, eq. 27): the
 * gradient operator of core (mf_gradient_ex) with 1/rho_ij inside the sum,
 * then the update of eqs. 16-17. */
#include <math.h>
#include <string.h>

#include "mf_error.h"
#include "mf_lsmps.h"
#include "mf_operators.h"
#include "mps.h"

/* The LSMPS gradient (Tamai & Koshizuka 2014) divided by rho_i, eq. 5 with
 * the pair coefficient where the fit is singular. */
static int least_squares(mps_data *d, const mf_sim *sim, const mf_pairs *v,
                         const mf_gradient_opts *o, const uint8_t *imask)
{
    const mf_particles *p = sim->p;
    MF_CALL(mps_scheme_reserve(d, p->n));
    uint8_t *failed = d->flag_work;
    memset(failed, 0, p->n);
    size_t nfailed =
        mf_lsmps_gradient(v, &d->k_grad, o->f, imask, d->not_dummy, d->grad, failed);
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!imask[i] || failed[i])
            continue;
        const double inv_rho = d->rho ? 1.0 / d->rho[i] : o->coef;
        for (int c = 0; c < 3; c++)
            d->grad[3 * i + c] *= inv_rho;
    }
    if (nfailed) {
        d->ls_fallbacks += (long)nfailed;
        mf_gradient_ex(v, &d->k_grad, o, failed, d->not_dummy, d->grad);
    }
    return 0;
}

int mps_corrected_pmin(const mps_data *d, const mf_sim *sim, const mf_pairs *v,
                       const double *pressure, double *fhat)
{
    mf_neighbour_min(v, pressure, true, d->own_reference, d->not_dummy, d->not_dummy, fhat);
    MF_CALL(mps_halo_sync(d, sim, fhat, sizeof *fhat)); /* copies: their owners' p^ */
    return 0;
}

/* eq. 15 with 1/rho_ij inside the gradient sum (eq. 5): the same pair
 * coefficient as the PPE, so the correction is the one the PPE solved for
 * (1/rho with one fluid, rho NULL). */
int mps_gradient_pairs(mps_data *d, const mf_sim *sim, const double *pressure,
                       const uint8_t *imask)
{
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_grad, &v));
    mf_gradient_opts o = {
        .f = pressure,
        .use_min = d->s.gradient_pmin,
        .own_reference = d->own_reference,
        .rho = d->rho,
        .rho_average = d->rho_average,
        .coef = 1.0 / d->rho_default,
    };
    const uint8_t *im = imask ? imask : d->is_fluid;
    if (d->sc.gradient == MPS_GRADIENT_LEAST_SQUARES)
        return least_squares(d, sim, &v, &o, im);
    if (d->sc.gradient == MPS_GRADIENT_CORRECTED) {
        MF_CALL(mps_scheme_reserve(d, sim->p->n));
        MF_CALL(mps_corrected_pmin(d, sim, &v, pressure, d->work));
        o.fhat = d->work;
    }
    mf_gradient_ex(&v, &d->k_grad, &o, im, d->not_dummy, d->grad);
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
