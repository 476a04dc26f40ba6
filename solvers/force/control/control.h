/* control.h: what the control forces (issue 18: directing the fluid) share.
 *
 *   attraction      toward a target shape, by control particles that sample
 *                   it (Thuerey, Keiser, Pauly & Ruede 2006): attraction.c
 *   velocityRegion  a velocity prescribed in a region, the fluid's velocity
 *                   relaxed toward it at a rate: velocity_region.c
 *   pathFollow      a region of fluid that follows a table of positions
 *                   against time: path_follow.c
 *
 * Each is an ordinary force (forces.h): it allocates nothing and makes no
 * pass unless the case names it. Each reads only particle-local data and the
 * engine's neighbour pairs; what sums over all the fluid (a control
 * particle's fluid density, a region's centroid) goes through
 * control_allreduce_sum, the one place to point at mf_parallel's reduction
 * when forces run per rank on owned particles (the mpi branch). */
#ifndef CONTROL_H
#define CONTROL_H

#include "control_shape.h"
#include "mf_modules.h"

/* Sum v[0..n) over the ranks of the run, in place. One rank today: nothing
 * to do. */
int control_allreduce_sum(const mf_sim *sim, double *v, size_t n);

/* The smooth kernel of the control forces: (1 - r^2/R^2)^3 for r < R
 * (Mueller, Charypar & Gross 2003's poly6 shape, unnormalised: 1 at r = 0),
 * from r^2. */
static inline double control_kernel(double r2, double R2)
{
    if (!(r2 < R2))
        return 0;
    const double q = 1 - r2 / R2;
    return q * q * q;
}

/* The sum of control_kernel over the points of a lattice of spacing h
 * within R of one of them (itself included): the value of a full
 * neighbourhood, which normalises the sums of the forces. */
double control_kernel_lattice_sum(int dim, double h, double R);

#endif
