/* control_common.c: what the control forces share (control.h). */
#include <limits.h>
#include <math.h>

#include "control.h"
#include "mf_error.h"
#include "mf_parallel.h"

/* Sums over the owned particles of every rank (nothing to do serially). */
int control_allreduce_sum(const mf_sim *sim, double *v, size_t n)
{
    if (n > (size_t)INT_MAX)
        return MF_ERROR(MF_ERR_INTERNAL, "a sum of %zu values over the ranks", n);
    mf_parallel_sum(sim->par, v, (int)n);
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
