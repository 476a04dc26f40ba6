/* mf_walls.h: the solid boundaries of a scene as geometry, each with a rigid
 * motion and a surface velocity.
 *
 * constant/geometry names two kinds of solid:
 *   walls      the container: a box whose closed faces hold the fluid in
 *              (a tank), or a polygon surface (type mesh);
 *   obstacles  bodies placed in the fluid: box (min, max), cylinder (a disk
 *              in 2-D: centre, radius; in 3-D also axis and length), sphere
 *              (centre, radius), mesh (a polygon file).
 * Any of them may move (motion { type constant | rotation | oscillating |
 * table; ... }, walls_motion.c) and may have a surface velocity (`velocity`:
 * a belt or a lid sliding along its own surface while the geometry stays,
 * as OpenFOAM's movingWallVelocity).
 *
 * How a solver sees a solid is the solver's choice (MPSCoeffs wallBoundary):
 * as layers of wall and dummy particles the scene makes (the paper's walls),
 * moved each step with the solid; or with no particles at all, through the
 * wall weight functions of mf_wall_weight.h evaluated from the distances to
 * the solid's faces (mf_walls_sums).
 *
 * Frames: a solid is described in its body frame, the world frame at t = 0.
 * At time t a body point x_b is at
 *   x = origin + d(t) + R(t) (x_b - origin),
 * moving at v(t) + w(t) x (x - origin - d(t)). The state (d, v, a, R, w, dw)
 * is the motion law's at the time of mf_walls_set_time; a law of type
 * external leaves it to whoever sets it (mf_wall_set_state: the rigid bodies
 * moved by the fluid of issue 18 integrate it from the force and torque that
 * mf_walls_sums reports on each solid). */
#ifndef MF_WALLS_H
#define MF_WALLS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mf_dict.h"
#include "mf_params.h"
#include "mf_particles.h"
#include "mf_wall_weight.h"

typedef enum {
    MF_SOLID_TANK = 0, /* walls: a box, fluid inside, closed faces are walls */
    MF_SOLID_BOX,      /* obstacles: a solid box */
    MF_SOLID_CYLINDER, /* a solid cylinder (a disk in 2-D) */
    MF_SOLID_SPHERE,   /* a solid sphere (a disk in 2-D) */
    MF_SOLID_MESH,     /* a polygon surface (walls or obstacles) */
} mf_solid_shape;

typedef enum {
    MF_MOTION_NONE = 0,
    MF_MOTION_CONSTANT,    /* d = velocity t */
    MF_MOTION_ROTATION,    /* angle = omega t about axis through origin */
    MF_MOTION_OSCILLATING, /* d = amplitude sin(omega t), angle = angleAmplitude sin(omega t) */
    MF_MOTION_TABLE,       /* d(t), angle(t) from tables of (time value) rows */
    MF_MOTION_EXTERNAL,    /* the state is set from outside (mf_wall_set_state) */
    MF_MOTION_RIGID,       /* moved by the fluid's forces (rigid_bodies.c, mf_bodies.h) */
} mf_motion_kind;

/* A table of (t, value) rows, OpenFOAM's `table` habit: values of ncomp
 * components, linear (the default) or natural cubic spline interpolation;
 * before the first row and after the last, the end rows' values. */
typedef struct mf_motion_table {
    size_t n;
    int ncomp;
    double *t, *y;  /* n, n * ncomp */
    double *y2;     /* spline: second derivatives at the rows (n * ncomp), NULL: linear */
} mf_motion_table;

typedef struct mf_motion {
    int kind;
    double origin[3]; /* centre of rotation, m (body frame = world at t = 0) */
    double axis[3];   /* unit axis of rotation (2-D: z) */
    double velocity[3];           /* constant */
    double omega;                 /* rotation: rad/s; oscillating: angular frequency */
    double amplitude[3];          /* oscillating: displacement amplitude, m */
    double angle_amplitude;       /* oscillating: rad */
    double cycles;                /* oscillating: stop after this many (0: never) */
    mf_motion_table disp, angle;  /* table (angle in rad) */
    /* rigid: density or mass and principal inertia (body axes), gravity;
     * origin is the centre of mass (origin_given: the case gave it). */
    double density, mass, inertia[3], g[3];
    double restitution; /* rigid: of its contacts (body_contact.c) */
    double friction;    /* rigid: Coulomb's mu of its contacts (0: none) */
    bool origin_given;
} mf_motion;

/* The rigid state at one time: x = origin + d + R (x_b - origin). */
typedef struct mf_rigid_state {
    double d[3], v[3], a[3];  /* displacement of the origin and its derivatives */
    double R[9];              /* body to world rotation, row-major */
    double w[3], dw[3];       /* angular velocity and acceleration (world), rad/s */
} mf_rigid_state;

struct mf_wall_mesh; /* walls_mesh.c: triangles, pseudonormals, a cell index */
struct mf_body;      /* rigid_bodies.c: a body moved by the fluid (mf_bodies.h) */

typedef struct mf_wall {
    char name[64];
    char where[192];         /* file:line:col of its entry, for messages */
    int shape;               /* mf_solid_shape */
    int dim;                 /* 2 or 3 (set by mf_walls_add) */
    bool obstacle;           /* in obstacles (a body), else in walls (a container) */
    /* shape, body frame */
    double min[3], max[3];   /* tank, box */
    bool open[3][2];         /* tank: faces without wall (z faces in 2-D) */
    double thickness;        /* tank: depth of its particle layers beyond the region, m
                              * ((wallLayers + dummyLayers) l0; 0: none, wall weight) */
    double centre[3], axis[3], radius, half_length; /* cylinder (half_length 0: endless), sphere */
    struct mf_wall_mesh *mesh;
    double surface_velocity[3]; /* body frame, m/s */
    mf_motion motion;
    mf_rigid_state state;    /* at state_time */
    double state_time;
    long first, count;       /* its particles in build order (particle walls), or 0 */
    /* what the fluid did to it over the last step (wall weight walls; a
     * rigid body's, summed by the solver over its particles): N, N m about
     * origin + d (2-D: per metre of depth) */
    double force[3], torque[3];
    struct mf_body *body;    /* motion rigid: its dynamics, else NULL */
} mf_wall;

typedef struct mf_walls {
    int dim;
    double l0;
    size_t n;
    mf_wall *w;
    bool particles;       /* the solids are particles (wall, dummy), else none */
    int f_wall_id;        /* "WallId" field of the particles of moving solids, -1: none */
    /* The ranks of a -parallel run (NULL: one): the rigid bodies' sums over
     * their particles are taken over all of them (mf_bodies.h). */
    const struct mf_parallel *par;
} mf_walls;

int mf_walls_create(int dim, double l0, bool particles, mf_walls **out);
void mf_walls_destroy(mf_walls *ws);
/* Append a copy of *w (its mesh is taken over: w->mesh is NULL on return). */
int mf_walls_add(mf_walls *ws, mf_wall *w, size_t *index);
bool mf_walls_any_moving(const mf_walls *ws);
/* Ready the solids for wall weight sums reaching `reach` from their faces
 * (polygon solids index their triangles by cells at least that large). */
int mf_walls_prepare(mf_walls *ws, double reach);
/* Bytes the solids hold (polygon surfaces, their indices). */
size_t mf_walls_memory(const mf_walls *ws);
bool mf_wall_moves(const mf_wall *w);

/* ---- motion (walls_motion.c) ------------------------------------------- */
/* Read `motion { ... }` (NULL: none) into m; dim fixes the 2-D axis. */
int mf_motion_read(const mf_dict *d, int dim, mf_motion *m);
void mf_motion_free(mf_motion *m);
/* The law's state at time t (external: identity). */
void mf_motion_state(const mf_motion *m, double t, mf_rigid_state *s);
/* Every solid's state at time t (external laws keep theirs). */
void mf_walls_set_time(mf_walls *ws, double t);
void mf_wall_set_state(mf_wall *w, const mf_rigid_state *s, double t);
/* The rotation by angle (rad) about the unit axis a (Rodrigues), row-major. */
void mf_rotation_matrix(const double a[3], double angle, double R[9]);
void mf_wall_to_body(const mf_wall *w, const double x[3], double xb[3]);
void mf_wall_to_world(const mf_wall *w, const double xb[3], double x[3]);
/* The solid's velocity at world point x (rigid motion; with_surface adds the
 * surface velocity, which the caller projects on the face as it needs). */
void mf_wall_velocity(const mf_wall *w, const double x[3], bool with_surface, double v[3]);
void mf_wall_acceleration(const mf_wall *w, const double x[3], double a[3]);
/* Parameter table of `motion`, for docs/reference.md. */
extern const mf_param mf_motion_params[];
extern const size_t mf_motion_nparams;
extern const mf_param_section mf_motion_sections[];
extern const size_t mf_motion_nsections;

/* ---- shapes (walls.c) ------------------------------------------------- */
/* Signed distance from world point x to the solid, positive on the fluid
 * side, and the unit normal there pointing into the fluid (may be NULL).
 * A tank's closed faces are whole planes here: its solid is everything
 * behind any of them. */
double mf_wall_distance(const mf_wall *w, const double x[3], double n[3]);
/* The box that particles on a box obstacle's lattice min + (i + 1/2) l0
 * stand for: max[a] becomes min[a] + n l0 (n = floor((max - min) / l0), the
 * particles along the axis) where that differs from the asked size by more
 * than 1e-6 l0 (scene_solids.c: the obstacle's record; the containment
 * metric: "inside the obstacle"). */
void mf_box_lattice_max(double l0, int dim, const double min[3], double max[3]);
/* True when fluid at x has gone through the solid: past a closed face of a
 * tank by more than l0/2 within that face's extent (the line of its first
 * wall particles; *axis, *side say which face), or inside an obstacle's
 * shape by more than l0/2. Meshes: false (their pressure equation reports
 * such a particle). */
bool mf_wall_passed(const mf_wall *w, double l0, int dim, const double x[3], int *axis,
                    int *side);

/* True when fluid at x, past closed face (axis, side) of tank w by
 * mf_wall_passed, is beyond that face's particle layers as well and was
 * past the face's wall-particle line (l0/2 outside the region) before its
 * last step `step` (its displacement, dt u) too: it is outside the tank,
 * come over the top of the wall (a spill), not through it. One going
 * through is seen in the layers (a step moves a particle maxCo l0 at most,
 * the Courant limit) or crossing the line in the step (a kick). False
 * without layers (thickness 0). */
bool mf_wall_spilled(const mf_wall *w, double l0, const double x[3], const double step[3],
                     int axis, int side);

/* ---- particles of moving solids (walls.c) ----------------------------- */
/* Move the particles of every moving solid from its state at t_from to its
 * state at t_to and give them the solid's velocity there (plus the surface
 * velocity). Solids whose particles are not tagged (no WallId field) and
 * fixed solids are left as they are. Call mf_walls_set_time(ws, t_to)
 * first; from_states are the states at t_from (one per solid). */
void mf_walls_move_particles(const mf_walls *ws, const mf_rigid_state *from_states,
                             mf_particles *p);
/* The time loop's call before each attempt of a step from t_from to t_to:
 * every solid's state at t_from (the particles are where it put them), then
 * at t_to (prescribed laws; an external law keeps the state its owner set for
 * t_to), and the particles of the moving solids moved between the two and
 * given the velocity at t_to. The fluid step then sees the walls where they
 * are at the end of the step: the viscous term through the wall particles'
 * velocities, the pressure equation through their number density. Nothing
 * to do (0) without a moving solid. */
int mf_walls_advance(mf_walls *ws, mf_particles *p, double t_from, double t_to);
/* The largest speed of a moving solid's particles (0: none), for the
 * Courant limit of the step; solids without particles (wall weight): their
 * largest speed at the fluid particles' positions. */
double mf_walls_max_speed(const mf_walls *ws, const mf_particles *p);

/* ---- wall weight sums (walls_sums.c) ---------------------------------- */
/* Everything the MPS step needs of the solids at a point, summed over the
 * solids within reach (mf_wall_weight.h, in the world frame):
 *   s          the sums of every solid;
 *   visc_u     sum over solids of visc_w u_w (u_w: the solid's velocity at
 *              x with its surface velocity, less its part along the normal);
 *   m_a        sum over solids of m_w . a_w (a_w: the solid's acceleration
 *              at x): with the force acceleration f, the wall's pressure is
 *              continued from the particle's as p_v = p_i + rho (f - a_w).v;
 *   t_a        sum over solids of t_w a_w;
 *   dist       the smallest distance to a solid (mf_wall_distance);
 *   wall       which solid that is.
 * Returns false (out untouched but zeroed) when no solid is within reach. */
typedef struct mf_wall_point {
    mf_wall_sums s;
    double visc_u[3];
    double m_a;
    double t_a[3];
    double dist, normal[3];
    int wall;
} mf_wall_point;
bool mf_walls_sums(const mf_walls *ws, const mf_wall_tables *t, const double x[3],
                   mf_wall_point *out);
/* The sums of one solid (the terms of its shape at x). */
bool mf_wall_sums_of(const mf_wall *w, const mf_wall_tables *t, int dim, double l0,
                     const double x[3], mf_wall_sums *s);

/* The virtual points of one solid made of plane faces (tank, box) closer
 * than R to x: each point of each term of its expansion (the lattice of
 * mf_wall_lattice.h, in the body axes) as fn(ctx, r, depth, dist, sign),
 * r the offset from x in the world frame, depth the point's distance
 * behind the nearest of its term's planes (s_v), dist the particle's
 * distance to that plane (d), sign the term's. For the least-squares
 * Laplacian's wall points (mps_wall.c). Returns false for shapes without
 * plane faces (cylinder, sphere, mesh), with no point given. */
typedef void (*mf_wall_point_fn)(void *ctx, const double r[3], double depth, double dist,
                                 double sign);
bool mf_wall_points_each(const mf_wall *w, const mf_wall_tables *t, int dim, double l0,
                         double R, const double x[3], mf_wall_point_fn fn, void *ctx);

#endif
