/* mafl.h: the MPS-MAFL solver (the paper's section 3.3 and Algorithm 2;
 * Yoon, Koshizuka & Oka's moving-particle semi-implicit method with a
 * meshless advection on a flying grid).
 *
 * One step from t^n:
 *   1. Lagrangian phase (mafl_lagrangian.c): the MPS module's own step,
 *      with inlet and outlet points moving along like fluid so that the
 *      number density near them stays right; gives r^L, u^L.
 *   2. Reconfiguration (mafl_reconfigure.c): the computation points r^{n+1}.
 *      Walls, dummies, inlets and outlets go back to r^n. Free-surface
 *      points follow the flow (r^L) and are re-spaced along the surface.
 *      Interior points follow the case's rule: fixed (r^n: the Eulerian
 *      limit), fraction (r^n + a (r^L - r^n)), relax (r^L shifted toward an
 *      even distribution) or lagrangian (r^L: pure MPS). Then
 *      u^c = (r^{n+1} - r^n)/dt (eq. 19) and u^a = (r^L - r^{n+1})/dt (eq. 20).
 *   3. Eulerian phase (mafl_eulerian.c): every carried field (velocity
 *      components and each transported scalar) at r^{n+1}_i = r^L_i - u^a dt
 *      (eq. 21), on a 1-D grid along u^a through r^L_i with spacing dr, the
 *      grid values from the neighbours in a thin disk (eq. 23), advanced by
 *      the convection module (eqs. 24-26).
 *   4. Point count (mafl_points.c): points closer than removeDistance merge;
 *      holes inside the fluid get a new point whose values are those of the
 *      closest old point after step 3 (eq. 22).
 *
 * Free-surface points are those the MPS phase flags (eq. 18) whose
 * neighbours lie on one side and include no inlet or outlet point; a
 * flagged point with neighbours all round, or beside the gap at an inlet,
 * keeps the interior rule.
 *
 * Settings come from MAFLCoeffs: the MPS parameters (the same table as
 * MPSCoeffs), the reconfiguration rule, densityReference (the PPE source,
 * mafl_lagrangian.c) and the `convection { scheme QUICK; ... }`
 * sub-dictionary, whose other keys are the scheme module's.
 *
 * Inlet and outlet points are computation points that stay in place: the
 * solver sets the emitters to fixed buffers (mf_emitter.h).
 */
#ifndef MAFL_H
#define MAFL_H

#include <stdbool.h>
#include <stdint.h>

#include "mf_modules.h"
#include "mf_halo.h"
#include "mf_neighbours.h"
#include "mf_pairs.h"
#include "solver/mps/mps.h"

typedef enum {
    MAFL_RULE_FIXED,      /* interior points stay: the Eulerian limit */
    MAFL_RULE_FRACTION,   /* move with a fraction of the flow */
    MAFL_RULE_RELAX,      /* follow the flow, shifted toward an even distribution */
    MAFL_RULE_LAGRANGIAN  /* follow the flow: pure MPS */
} mafl_rule;

typedef struct mafl_settings {
    mps_settings mps;          /* the Lagrangian phase */
    const char *reconfiguration;
    const char *density_reference; /* n0 | startOfStep: the PPE source's reference */
    double fraction;           /* rule fraction: share of the Lagrangian motion */
    double shift;              /* rule relax: strength of the shift */
    double surface_shift;      /* re-spacing of free-surface points along the surface */
    double grid_spacing;       /* dr, in l0 */
    double re_interpolation;   /* radius of the weight of eq. 23, in l0 */
    double disk_thickness;     /* thickness of the disk of eq. 23, in dr */
    const mf_dict *convection; /* { scheme NAME; <the scheme's parameters> } */
    bool add_points;           /* fill holes (eq. 22) */
    double remove_distance;    /* merge fluid points closer than this, in l0 (0: never) */
    double hole_distance;      /* a lattice site with no point this close (in l0) ... */
    double hole_density;       /* ... and number density >= this n0 is a hole */
    bool hole_spacing;         /* a new point goes l0 from its nearest point */
    double separation;         /* rules fraction, relax: points closer than this (l0) move apart */
} mafl_settings;

#define MAFL_MAX_CARRIED (3 + MF_MAX_SCALARS)

typedef struct mafl_data {
    mafl_settings s;
    mafl_rule rule;
    bool incremental;          /* densityReference startOfStep or divergence */
    bool linear_source;        /* densityReference divergence: every pair linearised */
    mps_data *mps;             /* the composed MPS solver */
    mf_module conv;            /* the convection scheme */
    const mf_convection_ops *conv_ops;
    /* Particle fields (they follow the MPS module's reordering). */
    int f_pos_n;               /* MaflPositionN: r^n */
    int f_vel_n;               /* MaflVelocityN: u^n (inlet points keep it) */
    int f_kind;                /* MaflKind: kinds before the Lagrangian phase */
    int f_conv_vel;            /* ConvectionVelocity: u^a (eq. 20), written */
    int f_point_vel;           /* PointVelocity: u^c (eq. 19), written */
    int f_scalar[MF_MAX_SCALARS];
    int nscalars;
    double lattice[3];         /* a lattice site: holes are filled on this lattice */
    /* The neighbour service's grid for point queries (mf_grid_near), at r^L
     * (reconfiguration, Eulerian phase) and at r^{n+1} (point count). */
    const mf_grid *grid;
    /* Work arrays, grown as needed. */
    size_t cap;
    double *pos_l;             /* 3n: r^L */
    /* densityReference startOfStep (mafl_lagrangian.c): */
    double *n_offset;          /* n: n* - n_eff, the MPS module's source offset */
    double *pos_new;           /* 3n: r^{n+1} */
    double *value;             /* MAFL_MAX_CARRIED * n: new values, field-major */
    uint8_t *convected;        /* 1 if the Eulerian phase set the point's values */
    uint8_t *remove;           /* points merged away */
    double *shift;             /* 3n: the separation's shifts (mafl_separation.c) */
    /* Statistics. */
    size_t last_added, last_removed, total_added, total_removed;
    size_t last_separated, total_separated; /* points moved apart (mafl_separation.c) */
    double q_max;              /* largest q of the last step */
    long q_limited;            /* grid points where |u^a| dt > dr widened the grid */
    double t_lagrangian, t_reconfigure, t_eulerian, t_points;
    /* Copies of other ranks' points for the reconfiguration, the Eulerian
     * phase and the point count (a -parallel run; NULL otherwise). */
    mf_halo *halo;
} mafl_data;

extern const mf_solver_ops mf_solver_MAFL;
#define MAFL_NPARAMS (MPS_NPARAMS + 15)
extern const mf_param mafl_params[MAFL_NPARAMS];

/* mafl_module.c */
int mafl_reserve(mafl_data *d, size_t n);

/* mafl_step.c */
int mafl_step(mafl_data *d, mf_sim *sim, double dt);

/* On several ranks: copies of the other ranks' points within radius into
 * [n_owned, n) (with the fields the MAFL phases read of a neighbour when
 * values is set); nothing on one rank. */
int mafl_copies(mafl_data *d, mf_sim *sim, double radius, bool values);

/* mafl_lagrangian.c: the Lagrangian phase, the MPS module's step. */
int mafl_lagrangian(mafl_data *d, mf_sim *sim, double dt);

/* mafl_reconfigure.c: r^{n+1} into d->pos_new (eqs. 19-20 into the
 * PointVelocity and ConvectionVelocity fields). Needs d->grid at r^L. */
int mafl_reconfigure(mafl_data *d, mf_sim *sim, double dt);

/* mafl_separation.c: fluid points closer than separation l0 at r^{n+1}
 * (d->pos_new) move apart, shift: 3n of work. Needs d->grid at r^L. */
int mafl_separate(mafl_data *d, mf_sim *sim, double *shift);

/* mafl_eulerian.c: new values of the carried fields into d->value
 * (eqs. 21, 23-26). Needs d->grid at r^L. */
int mafl_eulerian(mafl_data *d, mf_sim *sim, double dt);

/* mafl_points.c: merge close points and fill holes at r^{n+1} (eq. 22). */
int mafl_update_points(mafl_data *d, mf_sim *sim);

#endif
