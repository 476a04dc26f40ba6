/* st_timestep.c: the capillary time-step limit of surfaceTension. */
#include <math.h>

#include "surface_tension.h"

/* Brackbill et al. (1992): a capillary wave must not cross a particle in a
 * step, dt <= sqrt(rho_bar l0^3 / (2 pi sigma)). */
int st_stable_dt(void *data, const mf_sim *sim, double *out)
{
    const st_data *d = data;
    double dt = INFINITY;
    for (int x = 0; x < d->nfluids; x++)
        for (int y = x; y < d->nfluids; y++) {
            double sig = d->sigma[x][y];
            if (!(sig > 0))
                continue;
            double rho = x == y ? sim->fluid[x].rho : 0.5 * (sim->fluid[x].rho + sim->fluid[y].rho);
            double lim = d->s.dt_factor * sqrt(rho * pow(d->l0, 3) / (2 * M_PI * sig));
            if (lim < dt)
                dt = lim;
        }
    *out = dt;
    return 0;
}
