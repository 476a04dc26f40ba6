/* mf_bodies.h: rigid bodies moved by the fluid (issue 18): an obstacle with
 *
 *   motion { type rigid; density 500; }            // or mass 1.2; inertia (0 0 0.003);
 *
 * is a moving wall whose state the fluid's forces decide. The method is
 * the force integration of Akinci et al. (2012), "Versatile rigid-fluid
 * coupling for incompressible SPH", ACM TOG 31(4) 62, section 4, as
 * SPlisHSPlasH does it: the body's particles act on the fluid as a moving
 * wall, and the body receives the opposite of the pair forces the fluid
 * particles received from them (here the MPS step's pressure gradient,
 * eq. 15, and viscosity, eq. 7, restricted to the body's particles:
 * solvers/solver/mps/mps_bodies.c), plus gravity. Newton's and Euler's
 * equations are integrated by symplectic Euler:
 *
 *   v^{n+1} = v^n + J^n / m + dt g,       L^{n+1} = L^n + H^n,
 *   w^{n+1} = R^n I_b^{-1} R^nT L^{n+1},  R^{n+1} = exp(dt [w^{n+1}]x) R^n,
 *   x^{n+1} = x^n + dt v^{n+1},
 *
 * J^n, H^n the impulse and angular impulse the fluid gave the body over the
 * step that ended at t^n (force and torque times that step's dt, so that the
 * body's momentum gain is exactly the fluid's loss whatever the steps). The
 * body is then where it is at the end of the step the fluid takes
 * (mf_walls_advance moves its particles there with its velocity there).
 *
 * Contact: where a body's surface would overlap a wall, an obstacle or
 * another body at the trial state, the approach at the deepest point is
 * stopped by an impulse (restitution e: -(1+e) v_n over the pair's
 * effective mass, the collision of two rigid bodies, e.g. Baraff 1997,
 * "An introduction to physically based modeling: rigid body simulation
 * II", eq. 8-18; with `friction` mu a tangential impulse of at most mu
 * times it, Catto 2005) and the overlap is removed from the trial
 * position (p holds the particles where the committed state has them).
 *
 * A retry of a step computes the trial state again from the committed state
 * at t^n: nothing to restore. A step is committed by mf_bodies_accept, which
 * writes the row of postProcessing/<body>/bodyState.csv. */
#ifndef MF_BODIES_H
#define MF_BODIES_H

#include <stdbool.h>
#include <stddef.h>

#include "mf_walls.h"

/* Mass, inertia and the centre of mass of w (motion rigid) from its shape
 * and density or from the given mass and inertia; the initial state. */
int mf_body_create(mf_wall *w, int dim);
void mf_body_destroy(struct mf_body *b);
size_t mf_bodies_count(const mf_walls *ws);

/* The states of the bodies at t_from (committed) or at t_to (the trial
 * state of a step of t_to - t_from from there): mf_walls_advance's. */
void mf_bodies_set_committed(mf_walls *ws);
int mf_bodies_set_trial(mf_walls *ws, const mf_particles *p, double dt);

/* The solver's part: w->force and w->torque of every body set to zero (the
 * start of an attempt), then a force f on the body at world point x. */
void mf_bodies_clear_forces(mf_walls *ws);
void mf_body_add_force(mf_wall *w, const double x[3], const double f[3]);

/* The surface the body's wall particles (kind MF_WALL) stand for, for the
 * pressure force: prepare counts the wall particles within l0 of each face
 * (index: the body's place in ws, its WallId less one; over every rank of
 * par, collective, NULL: one rank); mf_body_surface
 * gives, for the wall particle at world point x, up to 3 surface elements
 * (a box's edge or corner particle stands for 2 or 3 faces): the outward
 * area vectors A n (m^2; 2-D: m per metre) and the shifts from x to the
 * surface along n. Returns how many. */
int mf_body_surface_prepare(mf_wall *w, const mf_particles *p, int f_wall_id, int index,
                            double l0, const struct mf_parallel *par);
int mf_body_surface(const mf_wall *w, const double x[3], double l0, double out_area[3][3],
                    double out_shift[3][3]);

/* The step to t (of length dt) is accepted: the trial state becomes the
 * body's, the force and torque of the step its impulse for the next, and
 * the row of its CSV file is written. */
int mf_bodies_accept(mf_walls *ws, double t, double dt);

/* Open postProcessing/<body>/bodyState.csv under post_dir (created) for
 * each body and write the row of the initial state at time t; on a restart
 * (from a snapshot at t) keep the file's rows up to t and append. */
int mf_bodies_open_output(mf_walls *ws, const char *post_dir, double t, bool restart);

/* The body's mass and its linear and angular momentum (angular about its
 * centre of mass), committed, and the pending impulses J^n, H^n. */
typedef struct mf_body_momentum {
    double mass;
    double centre[3], rotation[9], velocity[3], omega[3];
    double momentum[3], angular[3];
    double impulse[3], angular_impulse[3];
} mf_body_momentum;
void mf_body_get(const mf_wall *w, mf_body_momentum *out);

/* A restart: the committed state (and pending impulses) from a snapshot's
 * /RigidBodies/<name> (mf_body_get's fields; mass checked against the
 * case's, where names the snapshot group for the message). */
int mf_body_set(mf_wall *w, const mf_body_momentum *s, const char *where);

#endif
