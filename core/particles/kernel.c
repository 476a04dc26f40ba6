/* kernel.c: n0 and lambda from an ideal full lattice (eqs. 3, 8). */
#include "mf_kernel.h"

#include <math.h>

#include "mf_error.h"

int mf_kernel_init(mf_kernel *k, int dim, double l0, double re)
{
    if (dim != 2 && dim != 3)
        return MF_ERROR(MF_ERR_INPUT, "dimension must be 2 or 3, not %d", dim);
    if (!(l0 > 0) || !(re > l0))
        return MF_ERROR(MF_ERR_INPUT,
                        "kernel radius re = %g must exceed the particle spacing l0 = %g > 0", re,
                        l0);
    int m = (int)ceil(re / l0);
    int mz = dim == 3 ? m : 0;
    double n0 = 0.0, r2w = 0.0, r2hl = 0.0, half_y = 0.0;
    for (int ix = -m; ix <= m; ix++)
        for (int iy = -m; iy <= m; iy++)
            for (int iz = -mz; iz <= mz; iz++) {
                double r = l0 * sqrt((double)(ix * ix + iy * iy + iz * iz));
                double w = mf_weight(r, re);
                n0 += w;
                r2w += r * r * w;
                r2hl += r * r * mf_weight_hl(r, re, dim);
                if (iy < 0 && r > 0.0)
                    half_y += l0 * iy / r * w;
            }
    k->dim = dim;
    k->l0 = l0;
    k->re = re;
    k->n0 = n0;
    k->lambda = r2w / n0; /* eq. 8 on the lattice */
    k->hl_coef = 2.0 * dim / r2hl;
    k->asym_flat = fabs(half_y) / n0;
    k->grad_weight = MF_GRAD_WEIGHT_PAPER;
    k->n0_grad = n0;
    return 0;
}

int mf_kernel_set_gradient_weight(mf_kernel *k, int shape)
{
    if (shape != MF_GRAD_WEIGHT_PAPER && shape != MF_GRAD_WEIGHT_WENDLAND &&
        shape != MF_GRAD_WEIGHT_WENDLAND_W)
        return MF_ERROR(MF_ERR_INPUT, "unknown gradient weight %d", shape);
    const double l0 = k->l0, re = k->re;
    int m = (int)ceil(re / l0);
    int mz = k->dim == 3 ? m : 0;
    double n0 = 0.0; /* the same lattice points and order as mf_kernel_init */
    for (int ix = -m; ix <= m; ix++)
        for (int iy = -m; iy <= m; iy++)
            for (int iz = -mz; iz <= mz; iz++)
                n0 += mf_weight_gradient(l0 * sqrt((double)(ix * ix + iy * iy + iz * iz)), re,
                                         shape);
    if (!(n0 > 0))
        return MF_ERROR(MF_ERR_INPUT, "the gradient weight has no neighbour within re = %g", re);
    k->grad_weight = shape;
    k->n0_grad = n0;
    return 0;
}
