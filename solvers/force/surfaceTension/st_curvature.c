/* st_curvature.c: kappa from the fraction of the r_st disk (ball) the fluid
 * fills (the count models, exact and paper), and the lattice constants. */
#include <math.h>

#include "surface_tension.h"

/* 2-D: the part of a disk of radius r centred on a circle of radius R that
 * lies inside the circle, as a fraction of the disk; eps = r / R in (0, 2]. */
static double disk_fraction(double eps)
{
    if (eps <= 0)
        return 0.5;
    return (acos(eps / 2) + acos(1 - eps * eps / 2) / (eps * eps) -
            sqrt(4 - eps * eps) / (2 * eps)) /
           M_PI;
}

/* eps >= 0 with disk_fraction(eps) = f, f in [1/4, 1/2] (clamped). */
static double invert_disk_fraction(const st_data *d, double f)
{
    const double *t = d->table_f; /* decreasing from 1/2 to 1/4 */
    if (f >= t[0])
        return 0;
    if (f <= t[EXACT_TABLE - 1])
        return 2;
    size_t lo = 0, hi = EXACT_TABLE - 1;
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (t[mid] > f)
            lo = mid;
        else
            hi = mid;
    }
    double a = t[lo], b = t[hi], s = (a - f) / (a - b);
    return 2.0 * ((double)lo + s) / (EXACT_TABLE - 1);
}

/* kappa (1/m) of a particle whose fluid fills the fraction f of its probe. */
double st_curvature(const st_data *d, double f)
{
    if (d->paper) { /* eqs. 38-39: 2 theta = pi n^st2 / n0^st = 2 pi f */
        double theta = M_PI * f;
        return 2 * cos(theta) / d->r;
    }
    double sign = f <= 0.5 ? 1.0 : -1.0; /* concave: the other side's convex fraction */
    double g = f <= 0.5 ? f : 1 - f, eps;
    if (d->dim == 2) {
        eps = invert_disk_fraction(d, g);
        return sign * eps / d->r;
    }
    eps = fmin(2.0, 16.0 / 3.0 * (0.5 - g)); /* ball on a sphere: f = 1/2 - 3 eps / 16 */
    return sign * 2 * eps / d->r;             /* 2/R */
}

/* N_full: lattice points within r_st; n0^st: n^st2 of a particle on a flat
 * lattice surface (deeper layers count 1, its own layer one half). */
void st_lattice_counts(st_data *d)
{
    int m = (int)ceil(d->s.radius), mz = d->dim == 3 ? m : 0;
    double full = 0, flat = 0, rphi = 0, gy = 0;
    const double r2 = d->s.radius * d->s.radius;
    for (int i = -m; i <= m; i++)
        for (int j = -m; j <= m; j++)
            for (int k = -mz; k <= mz; k++) {
                double q = (double)(i * i + j * j + k * k);
                if (q == 0 || q >= r2)
                    continue;
                full += 1;
                double r = sqrt(q) * d->l0;
                rphi += r * colour_weight(r, d->r);
                if (j <= 0) /* the outer particle of a flat surface: colour gradient */
                    gy += colour_weight(r, d->r) * (j * d->l0) / r;
                /* the interface is normal to y; fluid at y <= 0 */
                if (j < 0)
                    flat += 1;
                else if (j == 0)
                    flat += 0.5;
            }
    d->n_full = full;
    d->n0st = flat;
    d->g_coef = d->dim / rphi;
    d->g_ref = fabs(d->g_coef * gy);
}


/* The exact model's table of disk_fraction, for st_curvature's inversion. */
void st_exact_table(st_data *d)
{
    for (int i = 0; i < EXACT_TABLE; i++)
        d->table_f[i] = disk_fraction(2.0 * i / (EXACT_TABLE - 1));
}
