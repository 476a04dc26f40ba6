/* mps_repulsion.c: eq. 5 with its repulsive part at a wider radius
 * (MPSCoeffs `repulsionRadius`; docs/notes/mps.md, "rest", and the "Next"
 * of resting3).
 *
 * Eq. 5 with p^_i the neighbourhood's minimum (Koshizuka et al. 1998) is
 * the sum of a consistent part and a repulsion:
 *   (d/n0) sum_j (p_j - p^_i) r_ij w_ij / r_ij^2
 *     = (d/n0) sum_j (p_j - p_i) r_ij w_ij / r_ij^2        (consistent)
 *     + (p_i - p^_i) (d/n0) sum_j r_ij w_ij / r_ij^2       (repulsion).
 * Here the consistent part keeps reGradient (the dam break front's radius)
 * and the repulsion, with its own p^_i, w and n0, takes repulsionRadius R:
 *   G_i = G(p, no min; re) + [G(p, min; R) - G(p, no min; R)],
 * the bracket being (p_i - p^_i(R)) (d/n0_R) sum_{r < R} r w_R / r^2, by
 * the same mf_gradient as eq. 5 (three passes; the split is exact up to
 * round-off). With R = reGradient it is eq. 5 up to round-off. */
#include <stdlib.h>

#include "mf_error.h"
#include "mf_operators.h"
#include "mps.h"

int mps_gradient_split(mps_data *d, mf_sim *sim, const mf_pairs *v, const double *pr)
{
    const mf_particles *p = sim->p;
    const size_t m = 3 * (p->n ? p->n : 1);
    double *with_min = malloc(m * sizeof *with_min), *no_min = malloc(m * sizeof *no_min);
    if (!with_min || !no_min) {
        free(with_min);
        free(no_min);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the split gradient");
    }
    mf_pairs vr;
    int rc = mps_pairs(d, sim, d->h_rep, &vr);
    if (rc == 0) {
        mf_gradient(v, &d->k_grad, pr, false, d->is_fluid, d->not_dummy, d->grad);
        mf_gradient(&vr, &d->k_rep, pr, true, d->is_fluid, d->not_dummy, with_min);
        mf_gradient(&vr, &d->k_rep, pr, false, d->is_fluid, d->not_dummy, no_min);
        for (size_t i = 0; i < p->n_owned; i++)
            if (d->is_fluid[i])
                for (int c = 0; c < 3; c++)
                    d->grad[3 * i + c] += with_min[3 * i + c] - no_min[3 * i + c];
    }
    free(with_min);
    free(no_min);
    return rc == 0 ? 0 : mf_error_trace(rc, __FILE__, __LINE__, __func__);
}
