/* mf_wall_weight.h: wall weight functions, the sums a wall's particles would
 * add to a fluid particle's MPS operators, tabulated against the particle's
 * distances to the wall's faces, so that a wall needs no particles.
 *
 * The method is that of Harada, Koshizuka & Shimazaki (2008), "Improvement
 * of wall boundary calculation model for MPS method", Trans. JSCES 2008,
 * 20080006 (the wall's share of the number density as a function Z(d) of
 * the distance to the wall, computed once from a lattice of virtual wall
 * particles), extended here to every sum the MPS step takes and to the
 * edges and corners of a box; a polygon wall gives the distances as
 * Mitsume et al. (2015), "Explicitly represented polygon wall boundary
 * model for the explicit MPS method", Comp. Part. Mech. 2, 73-89, do.
 *
 * The virtual wall behind a face is the lattice a particle wall puts there:
 * its first layer l0/2 behind the face, the next l0 deeper, without end;
 * along the face it is aligned with the fluid particle, so that a particle
 * sliding along a flat face sees a flat wall. A fluid particle of a block
 * whose corner lies on the face sits l0/2 from it and gets exactly the sums
 * a particle wall gives it (a block at rest has n = n0 up to the walls).
 *
 * A table holds c constrained axes (c = 1: one face; 2: the edge where two
 * orthogonal faces meet; 3: a corner) with offsets delta_k, the particle's
 * distance to the k-th plane (negative once it is past the plane), and the
 * remaining dim - c axes free. Its virtual points, as offsets v from the
 * particle in the table's frame, are
 *   v_k = delta_k + (i_k + 1/2) l0, i_k = 0, 1, ...   (constrained axes k < c)
 *   v_f = j_f l0,                   j_f integer        (free axes)
 * and it stores, with w_r the weight of eq. 3 at radius r,
 *   zn = sum w_nd(|v|)                   number density (eq. 4)
 *   g  = sum v / |v|^2 w_grad(|v|)       gradient (eq. 5) of a constant
 *   t  = sum v v^T / |v|^2 w_grad(|v|)   gradient (eq. 5) of a linear field
 *   m  = sum v w_lap(|v|)                Laplacian (eq. 7) of a linear field
 * A virtual point closer than l0/4 to the particle (a particle past the
 * face) counts as if it were l0/4 away, so that every sum stays finite.
 * Values between nodes are multilinear interpolations; the nodes include the
 * lattice offsets (m + 1/2) l0, where the tables are exact. */
#ifndef MF_WALL_WEIGHT_H
#define MF_WALL_WEIGHT_H

#include <stdbool.h>
#include <stddef.h>

/* The sums of one wall, in the world frame. visc is the coefficient of the
 * no-slip term: with the virtual points' velocities extrapolated through the
 * face, u_v = u_w - (s_v / d)(u_i - u_w) (Morris, Fox & Zhu 1997, J. Comput.
 * Phys. 136, 214-226: s_v the point's depth behind the face, d the
 * particle's distance to it), sum (u_v - u_i) w_lap = -(u_i - u_w) visc,
 * visc = sum (d + s_v)/d w_lap = m_n / d (m_n: m along the face's normal
 * into the wall; d at least l0/4). */
typedef struct mf_wall_sums {
    double zn;
    double g[3];
    double t[6]; /* xx yy zz xy xz yz */
    double m[3];
    double visc;
} mf_wall_sums;

/* One term of a wall's expansion: c constrained axes e[k] (unit, pointing
 * into the wall, mutually orthogonal) with the particle's distances delta[k]
 * to their planes, the other axes free; its sums are added times sign. */
typedef struct mf_wall_term {
    int c;
    double e[3][3];
    double delta[3];
    double sign;
} mf_wall_term;

typedef struct mf_wall_tables mf_wall_tables;

/* Tables for a dim-D lattice of spacing l0 and the radii of the number
 * density, the gradient and the Laplacian. */
int mf_wall_tables_create(int dim, double l0, double re_nd, double re_grad, double re_lap,
                          mf_wall_tables **out);
void mf_wall_tables_destroy(mf_wall_tables *t);
/* A plane farther than this from the particle adds nothing (its first
 * virtual layer is out of reach); one this far past it on a constrained axis
 * has all its reach on the wall's side: the caller frees that axis. */
double mf_wall_tables_reach(const mf_wall_tables *t);
double mf_wall_tables_free_beyond(const mf_wall_tables *t);
/* Add term's sums (times its sign) to s; false when the term is out of
 * reach (nothing added). */
bool mf_wall_term_add(const mf_wall_tables *t, const mf_wall_term *term, mf_wall_sums *s);
/* The same sums by brute force over the virtual lattice (tests). */
void mf_wall_term_direct(const mf_wall_tables *t, const mf_wall_term *term, mf_wall_sums *s);
/* Bytes the tables hold. */
size_t mf_wall_tables_memory(const mf_wall_tables *t);

#endif
