/* scene_lattice.h: the particle lattice of the scene builders (scene.c,
 * emitter.c, scene_estimate.c): how many lattice points fit along an axis,
 * and the check every box of a case passes. Internal to core/scene. */
#ifndef MF_SCENE_LATTICE_H
#define MF_SCENE_LATTICE_H

#include <math.h>

#include "mf_dict.h"

/* Number of lattice points a + (i + 1/2) l0 that fit in [a, b], as a double
 * (a spacing of 1e-9 m over a metre must not overflow an estimate). The small
 * tolerance keeps (b - a) / l0 = 50 from rounding down to 49. */
static inline double mf_lattice_span(double a, double b, double l0)
{
    return floor((b - a) / l0 + 1e-9);
}

/* The same count as the builders place it. */
static inline long mf_lattice_count(double a, double b, double l0)
{
    return (long)mf_lattice_span(a, b, l0);
}

/* A box [mn, mx] of the entry `name` (a `what`: "wall", "inlet", ...) must
 * have max > min on each of the dim axes; the error names the entry's file
 * and line. */
int mf_lattice_check_box(const char *what, const char *name, const mf_dict *d, const double *mn,
                         const double *mx, int dim);

#endif
