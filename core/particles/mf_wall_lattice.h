/* mf_wall_lattice.h: the virtual lattice behind a wall's faces (the points a
 * particle wall would put there), as one term of mf_wall_weight.h sees it,
 * in the term's local frame: c constrained axes first, at
 *   v_k = delta_k + (i_k + 1/2) l0, i_k = 0, 1, ...   (k < c)
 * and the free axes at j l0, |j| <= floor(R / l0), aligned with the particle.
 * One walker shared by the wall weight tables (wall_weight.c, which sum the
 * eq. 3 weights over it) and the least-squares Laplacian's wall points
 * (lsmps.c's callers, mps_wall.c), so that both see the same wall. */
#ifndef MF_WALL_LATTICE_H
#define MF_WALL_LATTICE_H

/* Called once per lattice point v (local frame, offset from the particle). */
typedef void (*mf_wall_lattice_fn)(void *ctx, const double v[3]);

/* Every lattice point of the term whose constrained coordinates can be
 * within R of the particle (the caller filters |v| < R), in a fixed order
 * (the last axis outermost). Nothing when a constrained plane lies farther
 * than R. delta: the particle's distances to the c planes (negative past
 * them). */
void mf_wall_lattice_each(int dim, double l0, double R, int c, const double *delta,
                          mf_wall_lattice_fn fn, void *ctx);

#endif
