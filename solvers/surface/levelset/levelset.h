/* levelset.h: surface reconstruction from particles (the paper's section 4).
 *
 * Two modules of kind surface and one function object:
 *   levelSet   eqs. 29-32: phi_t = |grad phi| (alpha F + beta H) in a narrow
 *              band, integrated in pseudo-time by SUNDIALS ARKODE (explicit
 *              ERKStep or IMEX ARKStep), warm-started from the previous frame;
 *   blobby     the iso-surface of a sum of compact kernels: a fast preview;
 *   surface    (functionObject) runs one of them at the write times of a run.
 *
 * Files (the solver folder's file set, plus one file per phase):
 *   levelset.h          this header
 *   levelset_params.c   the parameter tables of the three modules
 *   levelset_module.c   create, destroy, reconstruct, the ops tables
 *   levelset_step.c     one frame: field, seeds, band, evolution, mesh
 *   ls_bricks.c         the sparse grid: a hash of 8^3 bricks (like OpenVDB's leaves)
 *   ls_field.c          the particles' field F (eqs. 30-32) and the blobby field
 *   ls_detect.c         which bricks the zero level of a field crosses
 *   ls_band.c           the narrow band: seeds, fast marching, active points
 *   ls_rhs.c            the right-hand side of eq. 29 (upwind + curvature), and the
 *                       preconditioner of the implicit curvature (IMEX)
 *   ls_arkode.c         ARKODE glue: ERKStep / ARKStep + SPGMR, statistics
 *   ls_mesh.c           marching tetrahedra with normals from grad phi
 *   ls_mesh_check.c     topology of a mesh (closed, manifold, Euler characteristic)
 *   blobby.c            the blobby preview module
 *   surface_fo.c        the `surface` function object
 *
 * Units inside: positions on the grid are integers (x = i h, the grid is
 * anchored at the world origin so that consecutive frames share points);
 * phi is in grid cells; pseudo-time tau is such that alpha F moves the zero
 * level by alpha F cells per unit tau. The mean curvature is made
 * dimensionless with the particle spacing l0, so that the steady state
 * alpha F + beta l0 H = 0 does not depend on the grid.
 */
#ifndef LEVELSET_H
#define LEVELSET_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mf_clock.h"
#include "mf_hashmap.h"
#include "mf_log.h"
#include "mf_mesh.h"
#include "mf_modules.h"
#include "mf_sim.h"

/* ---- settings ------------------------------------------------------------ */

typedef struct ls_settings {
    double grid_spacing;   /* m; 0: l0 / 2 */
    double radius;         /* r_i of eq. 31, in l0 */
    double cutoff;         /* support of the (tapered) kernel, in l0 */
    long kernel_power;     /* k of eq. 31 */
    double threshold;      /* T of eq. 30 */
    bool anisotropic;      /* eq. 32 (off by default: README, "Surface") */
    double alpha, beta;    /* eq. 29 */
    const char *integrator; /* "explicit" (ERKStep) or "imex" (ARKStep, SPGMR); read at create */
    double tolerance;      /* converged: |d phi / d tau| on the surface below this, cells */
    double rel_tol, abs_tol; /* ARKODE's tolerances (IMEX's Newton iterations) */
    long max_steps;        /* ARKODE steps per frame */
    double max_pseudo_time; /* per frame */
    long band_width;       /* half-width of the evolved band, cells */
    bool warm_start;       /* start from the previous frame's phi */
    double max_memory;     /* MB; 0: 3/4 of the physical memory */
} ls_settings;

typedef struct blobby_settings {
    double grid_spacing;   /* m; 0: l0 / 2 */
    double radius;         /* kernel support, in l0 */
    double iso_value;      /* the surface is sum_i w_i = isoValue */
    double max_memory;     /* MB; 0: 3/4 of the physical memory */
} blobby_settings;

/* The `surface` function object and `mpsflow surface` (system/surfaceDict). */
typedef struct surface_settings {
    const char *method;            /* levelSet | blobby */
    const mf_dict *levelset_coeffs; /* levelSetCoeffs { ... } (may be NULL) */
    const mf_dict *blobby_coeffs;   /* blobbyCoeffs { ... } (may be NULL) */
    bool write_ply, write_obj;
} surface_settings;

#define LS_NPARAMS 17
#define BLOBBY_NPARAMS 4
#define SURFACE_NPARAMS 5
extern const mf_param ls_params[LS_NPARAMS];
extern const mf_param blobby_params[BLOBBY_NPARAMS];
extern const mf_param surface_params[SURFACE_NPARAMS];

/* Open a surface module from a dictionary laid out as system/surfaceDict
 * (method, <method>Coeffs { ... }, writePLY, writeOBJ; dict may be NULL:
 * defaults), method_override (may be NULL) replacing `method`. Fills s,
 * prepares and creates m; resolved (may be NULL) receives the values used.
 * Close with surface_close. */
int surface_open(const mf_registry *reg, const mf_dict *dict, const char *method_override,
                 const char *const *extra_keys, mf_dict *resolved, surface_settings *s,
                 mf_module *m);
void surface_close(mf_module *m);

extern const mf_surface_ops mf_surface_levelSet;
extern const mf_surface_ops mf_surface_blobby;

/* ---- sparse bricks (ls_bricks.c) ----------------------------------------- */

#define LS_B 8    /* brick side, grid points */
#define LS_B3 512
#define LS_NONE (-1)

/* Brick coordinate of a grid coordinate (floor division by 8) and the local
 * coordinate within it; exact for negative coordinates too. */
static inline int32_t ls_brick_of(int32_t x) { return (x - (x & 7)) / 8; }
static inline int ls_local_of(int32_t x) { return x & 7; }
static inline int ls_local_index(int i, int j, int k) { return i + LS_B * (j + LS_B * k); }

typedef struct ls_bricks {
    size_t n, cap;
    int32_t *coord;        /* 3n: brick coordinates */
    mf_hashmap map;        /* packed coordinates -> brick index, at most half full */
} ls_bricks;

/* Brick coordinates must stay within +-2^20 (checked against the grid). */
#define LS_BRICK_LIMIT (1 << 20)

void ls_bricks_init(ls_bricks *b);
void ls_bricks_free(ls_bricks *b);
void ls_bricks_clear(ls_bricks *b); /* keep the memory */
int32_t ls_bricks_find(const ls_bricks *b, int32_t bx, int32_t by, int32_t bz);
/* Index of the brick, adding it if absent (*added says which). */
int ls_bricks_insert(ls_bricks *b, int32_t bx, int32_t by, int32_t bz, int32_t *index,
                     bool *added);
size_t ls_bricks_memory(const ls_bricks *b);

/* ---- memory limit -------------------------------------------------------- */

/* Bytes allowed (setting in MB; 0: 3/4 of the physical memory). */
size_t ls_memory_limit(double max_memory_mb);

/* ---- the particles' field (ls_field.c) ----------------------------------- */

enum { LS_KERNEL_LEVELSET = 0, LS_KERNEL_BLOBBY = 1 };

typedef struct ls_field {
    int kernel;            /* LS_KERNEL_* */
    double h;              /* grid spacing, m */
    double r2_inv;         /* 1 / r^2 (grid units) */
    double rc2;            /* cutoff^2 (grid units) */
    double rc2_inv;
    double k_half;         /* kernel power / 2 */
    double offset;         /* T (level set) or -isoValue (blobby) */
    /* Fluid particles in grid units, structure of arrays. The metric of eq. 32
     * as d'^2 = c2 |dx|^2 + c1 (dx . u)^2 (u the unit velocity). */
    size_t n;
    double *x, *y, *z;
    float *ux, *uy, *uz, *c1, *c2;
    float *ex, *ey, *ez;   /* half-extent of the support along each axis */
    bool anisotropic;
    double ext_max;
    /* Candidates per brick: the particles whose support (+ a cell) reaches it. */
    ls_bricks touched;
    size_t *start;         /* touched.n + 1 */
    uint32_t *list;
    size_t cap_list, cap_start;
} ls_field;

void ls_field_init(ls_field *f);
void ls_field_free(ls_field *f);
/* Load the fluid particles of p (grid spacing h in metres, l0 the particle
 * spacing) and bin them into the bricks they reach. Errors: no fluid
 * particle, a non-finite position or velocity, a grid too fine for the
 * memory limit or the coordinate range. `what` names the source in messages. */
int ls_field_setup(ls_field *f, const mf_particles *p, int kernel, double h, double l0,
                   double radius_l0, double cutoff_l0, double kernel_power, double offset,
                   bool anisotropic, size_t mem_limit, const char *what);
/* F at grid point (x, y, z) given the brick's candidate range (cand < 0: none). */
double ls_field_at(const ls_field *f, int32_t cand, int32_t x, int32_t y, int32_t z);
/* F at the points of brick (bx, by, bz), local block [0, n)^3 with n = 8 or 9
 * (9: one more layer on the + sides), into out (n^3, x fastest). */
void ls_field_brick(const ls_field *f, int32_t bx, int32_t by, int32_t bz, int n, float *out);
/* The same on a coarse lattice of stride s (nodes 0, s, ..., 8: (8/s+1)^3). */
void ls_field_brick_coarse(const ls_field *f, int32_t bx, int32_t by, int32_t bz, int s,
                           float *out);

/* ---- zero-level detection (ls_detect.c) ---------------------------------- */

/* Bricks holding an end of a grid edge (of the 6-tetrahedra split of the
 * cubes) along which the field changes sign, with the field at all their
 * points. */
typedef struct ls_crossing {
    ls_bricks b;
    float *F;              /* 512 per brick */
    size_t cap;
} ls_crossing;

void ls_crossing_init(ls_crossing *c);
void ls_crossing_free(ls_crossing *c);
/* Find the crossing bricks of f (coarse pass at about 0.6 l0, then fine). */
int ls_detect(const ls_field *f, double l0, size_t mem_limit, ls_crossing *out);

/* ---- the narrow band (ls_band.c) ----------------------------------------- */

enum {
    LS_HAS_F = 1,     /* F known at the point */
    LS_HAS_PHI = 2,   /* phi known (the band and its frozen rim) */
    LS_ACTIVE = 4,    /* evolved: |phi| <= band width */
    LS_SEED = 8,      /* a fast-marching seed (kept as is) */
    LS_DONE = 16      /* fast marching: accepted */
};

typedef struct ls_band {
    ls_bricks b;
    size_t cap;            /* payload capacity, bricks */
    double *phi;           /* 512 per brick */
    float *F;
    uint8_t *flag;
    int32_t *idx;          /* index in the state vector, or -1 */
    int32_t *nb;           /* 27 per brick: neighbour bricks (ls_band_link) */
    size_t nact;
    uint32_t *act;         /* active points: brick * 512 + local */
    size_t cap_act;
    double width;          /* |phi| <= width is active */
    double rim;            /* phi known up to this distance */
    size_t mem_limit;
} ls_band;

typedef struct ls_seed {
    int32_t x, y, z;
    double phi;
} ls_seed;

void ls_band_init(ls_band *band, double width, size_t mem_limit);
void ls_band_free(ls_band *band);
void ls_band_clear(ls_band *band);
size_t ls_band_memory(const ls_band *band);
/* Index of a brick, added (payload cleared) if absent. */
int ls_band_brick(ls_band *band, int32_t bx, int32_t by, int32_t bz, int32_t *index);
/* Fill the 27-neighbour table of every brick. */
int ls_band_link(ls_band *band);
/* phi in the band from seeds (values kept) by fast marching to band->rim;
 * points beyond keep no value. */
int ls_band_from_seeds(ls_band *band, const ls_seed *seeds, size_t nseeds);
/* Points with a face neighbour of the other sign (phi > 0 inside). */
int ls_band_interface(const ls_band *band, ls_seed **seeds, size_t *n);
/* The points with |phi| <= dist, as seeds (a warm start keeps the previous
 * frame's evolved values, not only its interface). */
int ls_band_within(const ls_band *band, double dist, ls_seed **seeds, size_t *n);
/* Seeds from a field's sign changes: sub-cell distance along the axes. */
int ls_crossing_seeds(const ls_crossing *c, ls_seed **seeds, size_t *n);
/* F at every point of the band's bricks that lacks it: copied from the same
 * brick of another set (from_b, 512 values per brick in from_F; may be NULL)
 * or evaluated from the particles. */
int ls_band_fill_F(ls_band *band, const ls_field *f, const ls_bricks *from_b,
                   const float *from_F);
/* The active set (|phi| <= width) and the state-vector indices. */
int ls_band_activate(ls_band *band);
/* Value at a point by global coordinates, through the neighbour table of a
 * nearby brick: returns false if unknown. */
bool ls_band_lookup(const ls_band *band, int32_t x, int32_t y, int32_t z, double *phi,
                    float *F);

/* ---- the right-hand side of eq. 29 (ls_rhs.c) ---------------------------- */

typedef struct ls_rhs {
    ls_band *band;
    size_t *bstart;        /* nbricks + 1: the active points of brick b are bstart[b] .. */
    int32_t *padof;        /* per brick: its padded block, or -1 (no active point) */
    double *pad;           /* 10^3 per padded brick: the brick and a one-point halo */
    float *Fpad;           /* 16^3 per padded brick: F with a four-point halo */
    uint8_t *edge;         /* per active point: a stencil neighbour is beyond the rim */
    double far_F;          /* F where no particle reaches (T) */
    float *pn;             /* preconditioner: normals at the active points */
    double *zpad;          /* preconditioner: padded correction */
    double pgamma;
    size_t npad;
    size_t *slot_start;    /* nact + 1 */
    uint32_t *slot;        /* where each active value is copied (UINT32_MAX: nowhere) */
    double alpha;
    double beta_grid;      /* beta * l0 / h */
    double fmax;           /* largest |F| met in the last evaluation */
    long evaluations;
} ls_rhs;

enum { LS_RHS_ALL = 3, LS_RHS_ADVECTION = 1, LS_RHS_CURVATURE = 2 };

/* Build the stencil blocks for the band's current active set (ls_band_activate). */
int ls_rhs_setup(ls_rhs *r);
void ls_rhs_free(ls_rhs *r);
/* dphi/dtau at the active points for state y (n = band->nact): the parts
 * selected by `parts`. */
void ls_rhs_eval(ls_rhs *r, const double *y, double *ydot, int parts);
/* Preconditioner of I - gamma J_curvature (IMEX): set up at y, then solve. */
int ls_rhs_precond_setup(ls_rhs *r, const double *y, double gamma);
void ls_rhs_precond_solve(ls_rhs *r, const double *rhs, double *z);
/* The largest stable explicit step: advection (and curvature if `curvature`). */
double ls_rhs_stable_step(const ls_rhs *r, bool curvature);
/* Bounds of the spectrum of eq. 29's linearisation for the speed bound fmax:
 * the curvature term's eigenvalues lie on [-curv, 0], the upwind advection
 * term's in the disk |z + adv| <= adv. */
void ls_rhs_spectrum(const ls_rhs *r, double fmax, double *curv, double *adv);

/* ---- ARKODE glue (ls_arkode.c) ------------------------------------------- */

typedef struct ls_stats {
    long steps, steps_stability, steps_accuracy, error_fails;
    long rhs_explicit, rhs_implicit, rhs_jtimes;
    long newton_iters, newton_fails, lin_iters, lin_fails;
    long rebuilds;
    long rhs_calls;        /* calls of our right-hand side (any part), counted here */
    long redone;           /* explicit: chunks redone with a larger spectrum bound */
    int stages;            /* explicit: stages of the last RKC table */
    double step;           /* explicit: its fixed pseudo-time step */
    double pseudo_time;
    double last_change;    /* the convergence measure at the end */
    bool converged;
} ls_stats;

typedef struct ls_evolve_opts {
    bool imex;
    double alpha, beta_grid;
    double rel_tol, abs_tol;
    double tolerance;
    long max_steps;
    double max_pseudo_time;
} ls_evolve_opts;

/* Evolve phi in the band until converged (or the limits); the band is
 * rebuilt around the zero level when the level moves by more than a cell. */
int ls_evolve(ls_band *band, const ls_field *f, const ls_evolve_opts *o, ls_stats *st);

/* ---- mesh extraction (ls_mesh.c) ----------------------------------------- */

/* The zero level of a field on bricks (> 0 inside) as a triangle mesh,
 * closed and manifold where the level is closed inside the known points.
 * Values: 512 per brick of b, in values32 or values64 (one is NULL); known
 * (may be NULL: every point of every brick) flags points with LS_HAS_PHI;
 * nb the 27-neighbour table; h the grid spacing (positions in metres). */
int ls_mesh_extract(const ls_bricks *b, const int32_t *nb, const float *values32,
                    const double *values64, const uint8_t *known, double h, mf_mesh *out);
/* 27-neighbour table for a brick set (27 per brick). */
int ls_bricks_neighbours(const ls_bricks *b, int32_t **nb);

/* ---- mesh topology (ls_mesh_check.c) ------------------------------------- */

typedef struct ls_topology {
    size_t vertices, edges, faces;
    long euler;            /* V - E + F */
    size_t boundary_edges; /* used by one triangle */
    size_t nonmanifold_edges; /* used by more than two */
    size_t nonmanifold_vertices; /* whose triangles do not form one fan */
    size_t components;
    bool closed, manifold;
} ls_topology;

int ls_mesh_topology(const mf_mesh *m, ls_topology *t);

/* ---- the level set module's state (levelset_module.c, levelset_step.c) -- */

typedef struct ls_data {
    ls_settings s;         /* s.integrator is not kept: it may point into a dictionary */
    bool imex;
    ls_band band;          /* the previous frame's (warm start) */
    bool have_previous;
    double prev_h;
    ls_stats last;         /* the last frame's statistics */
    double t_field, t_detect, t_band, t_evolve, t_mesh; /* wall, s */
    double c_field, c_detect, c_band, c_evolve, c_mesh; /* CPU (all threads), s */
    size_t peak_band_bytes;
} ls_data;

int ls_frame(ls_data *d, const mf_sim *sim, mf_mesh *out);

/* ---- helpers ------------------------------------------------------------- */

/* The grid spacing a setting gives (0: l0 / 2). */
static inline double ls_grid_spacing(double setting, double l0)
{
    return setting > 0 ? setting : 0.5 * l0;
}

#endif
