/* wall_lattice.c: the walker of mf_wall_lattice.h (the loop the wall weight
 * tables always summed over, taken out of wall_weight.c unchanged). */
#include "mf_wall_lattice.h"

#include <math.h>

void mf_wall_lattice_each(int dim, double l0, double R, int c, const double *delta,
                          mf_wall_lattice_fn fn, void *ctx)
{
    long lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    const long J = (long)floor(R / l0);
    for (int a = 0; a < dim; a++) {
        if (a < c) {
            lo[a] = 0;
            hi[a] = (long)ceil((R - delta[a]) / l0); /* delta + (i + 1/2) l0 < R */
            if (hi[a] < 0)
                return;
        } else {
            lo[a] = -J;
            hi[a] = J;
        }
    }
    double v[3] = {0, 0, 0};
    for (long k = lo[2]; k <= hi[2]; k++)
        for (long j = lo[1]; j <= hi[1]; j++)
            for (long i = lo[0]; i <= hi[0]; i++) {
                const long idx[3] = {i, j, k};
                for (int a = 0; a < dim; a++)
                    v[a] = a < c ? delta[a] + ((double)idx[a] + 0.5) * l0 : (double)idx[a] * l0;
                fn(ctx, v);
            }
}
