/* mf_kernel.h: the MPS kernel weight and the constants of a full lattice.
 * The physics of one particle pair lives here as small inline functions;
 * the neighbour loops that call them are in operators.c. */
#ifndef MF_KERNEL_H
#define MF_KERNEL_H

#include <math.h>

/* eq. 3: w(r) = re/r - 1 for 0 < r < re, else 0 */
static inline double mf_weight(double r, double re)
{
    return (r > 0.0 && r < re) ? re / r - 1.0 : 0.0;
}

typedef struct mf_kernel {
    int dim;
    double l0;     /* initial particle spacing */
    double re;     /* interaction radius */
    double n0;     /* number density of a full interior lattice particle */
    double lambda; /* eq. 8, same lattice */
} mf_kernel;

/* n0 and lambda from the ideal full lattice (2-D square, 3-D cubic) of
 * spacing l0, every lattice point within re of the origin. */
int mf_kernel_init(mf_kernel *k, int dim, double l0, double re);

#endif
