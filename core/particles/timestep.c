/* timestep.c: time-step limits. */
#include "mf_timestep.h"

#include <math.h>

#include "mf_pairs.h" /* the threads policy: MF_STREAM_CHUNK */

double mf_max_fluid_speed(const mf_particles *p)
{
    double u2max = 0.0;
    const long n = (long)p->n_owned;
#pragma omp parallel for schedule(dynamic, MF_STREAM_CHUNK) \
    reduction(max : u2max)
    for (long i = 0; i < n; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *v = &p->vel[3 * i];
        double u2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if (u2 > u2max)
            u2max = u2;
    }
    return sqrt(u2max);
}

void mf_courant(const mf_particles *p, double dt, double l0, double *mean, double *max)
{
    double sum = 0.0, mx = 0.0;
    long count = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *v = &p->vel[3 * i];
        double c = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * dt / l0;
        sum += c;
        if (c > mx)
            mx = c;
        count++;
    }
    *mean = count ? sum / count : 0.0;
    *max = mx;
}

void mf_dt_choose(double l0, double umax, double courant, double nu, double viscous,
                  double dt_max, mf_dt_choice *out)
{
    out->dt = dt_max;
    out->umax = umax;
    out->limiter = "maxDeltaT";
    if (courant > 0 && umax > 0 && courant * l0 / umax < out->dt) {
        out->dt = courant * l0 / umax;
        out->limiter = "Courant";
    }
    if (viscous > 0 && nu > 0 && viscous * l0 * l0 / nu < out->dt) {
        out->dt = viscous * l0 * l0 / nu;
        out->limiter = "viscous";
    }
}
