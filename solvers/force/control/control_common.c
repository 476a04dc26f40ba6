/* control_common.c: what the control forces share (control.h). */
#include <math.h>

#include "control.h"

int control_allreduce_sum(const mf_sim *sim, double *v, size_t n)
{
    (void)sim;
    (void)v;
    (void)n;
    return 0;
}

double control_kernel_lattice_sum(int dim, double h, double R)
{
    const long m = (long)ceil(R / h);
    const long mz = dim == 3 ? m : 0;
    double sum = 0;
    for (long k = -mz; k <= mz; k++)
        for (long j = -m; j <= m; j++)
            for (long i = -m; i <= m; i++) {
                const double r2 = (double)(i * i + j * j + k * k) * h * h;
                sum += control_kernel(r2, R * R);
            }
    return sum;
}
