/* mps.h: the pure MPS solver (the paper's Algorithm 1; Koshizuka & Oka 1996).
 *
 * Every solver folder has the same files (SWIFT's habit):
 *   <name>.h          settings, state, the functions the folder shares
 *   <name>_params.c   the parameter table (names, defaults, ranges, docs)
 *   <name>_module.c   create, destroy, stable_dt and the const ops table
 *   <name>_step.c     one time step, phase by phase
 * plus files for a phase big enough to stand alone (here mps_ppe.c).
 *
 * Other solvers compose this one: MPS-MAFL calls mps_lagrangian_step for
 * its Lagrangian phase; the multi-fluid solver reuses the phases, the PPE
 * assembly and the correction with a density and a viscosity per particle
 * and a pair average (the `Multi-fluid` fields of mps_data). Left NULL,
 * those fields keep the single-fluid path, bit for bit.
 */
#ifndef MPS_H
#define MPS_H

#include <stdbool.h>
#include <stdint.h>

#include "mf_kernel.h"
#include "mf_modules.h"
#include "mf_neighbours.h"
#include "mf_pairs.h"

typedef struct mps_settings {
    double re_number_density; /* radii in units of l0 */
    double re_gradient;
    double re_laplacian;
    double beta;              /* eq. 18: free surface when n* < beta n0 */
    double relaxation;        /* factor on the PPE source term (0: the scheme's) */
    double compressibility;   /* 1/Pa; adds rho c / dt^2 to the diagonal (0: off) */
    bool clip_negative_pressure;
    bool gradient_pmin;       /* eq. 5 with p_min (Koshizuka et al. 1998) */
    const char *gradient_weight; /* eq. 5's weight: paper | wendland | wendlandW (mf_grad_weight) */
    bool wall_pressure_extrapolated; /* the gradient reads the walls' p from the fluid's (mps_wall_pressure.c) */
    double velocity_filter;   /* XSPH eps on u^n in the explicit phase (Monaghan 1989, mps_xsph.c; 0: off) */
    /* The scheme (mps_scheme.c): a named set of the five choices below,
     * each of which a case may set apart ("scheme": the scheme's). */
    const char *scheme;       /* paper | robust | stabilised */
    const char *source;       /* PPE source: density | mixed | higherOrder | errorCompensating | mixedHigherOrder */
    const char *gradient;     /* pressure gradient: paper | corrected | leastSquares */
    const char *laplacian;    /* paper | higherOrder | leastSquares */
    const char *shifting;     /* none | fickian */
    const char *surface_detection; /* numberDensity | asymmetry */
    const char *collision_choice;  /* scheme | yes | no: the collision model */
    double density_factor;    /* mixed source: gamma of the density term */
    double shift_coefficient; /* fickian shifting: A of dr = -A l0^2 grad C */
    double shift_max;         /* largest shift a step, in l0 */
    double asymmetry;         /* asymmetry test: fraction of a flat surface's */
    bool retry_source;        /* a retry keeps the source's density terms (mps_step.c) */
    bool collision;           /* the collision model (resolved from collision_choice) */
    double collision_distance; /* in l0 */
    bool collision_after_correction; /* a second collision pass after eqs. 15-17 */
    double restitution;
    long reorder_interval;    /* sort particles along cells every N steps (0: never) */
    const char *viscosity;    /* "explicit" (eq. 7 term in the explicit phase) or "implicit" */
    double periodic_length;   /* period along x, m (0: no periodic axis) */
    double periodic_origin;   /* x of the periodic box's lower face, m */
    const char *wall;         /* particles | wallWeight (mps_wall.c) */
} mps_settings;

/* Pair averages: mf_inv_rho_pair, mf_mu_pair (mf_kernel.h); mps_data's
 * rho_average and mu_average are mf_average values. */

/* The scheme's choices, resolved from the settings (mps_scheme.c). */
typedef enum {
    MPS_SOURCE_DENSITY,            /* eq. 14: relaxation (rho/dt^2)(n* - n0)/n0 */
    MPS_SOURCE_MIXED,              /* Tanaka & Masunaga 2010 */
    MPS_SOURCE_HIGHER_ORDER,       /* Khayyer & Gotoh 2009 (HS) */
    MPS_SOURCE_ERROR_COMPENSATING, /* Khayyer & Gotoh 2011 (HS + ECS) */
    MPS_SOURCE_MIXED_HIGHER_ORDER  /* mixed, its divergence as HS (robust's) */
} mps_source_kind;

/* Does the source need n at r^n (the mixed forms and ECS's density terms)? */
static inline bool mps_source_mixed(mps_source_kind s)
{
    return s == MPS_SOURCE_MIXED || s == MPS_SOURCE_MIXED_HIGHER_ORDER;
}
typedef enum { MPS_GRADIENT_PAPER, MPS_GRADIENT_CORRECTED, MPS_GRADIENT_LEAST_SQUARES } mps_gradient_kind;
typedef enum { MPS_LAPLACIAN_PAPER, MPS_LAPLACIAN_HIGHER_ORDER, MPS_LAPLACIAN_LEAST_SQUARES } mps_laplacian_kind;
typedef enum { MPS_SHIFT_NONE, MPS_SHIFT_FICKIAN } mps_shift_kind;
typedef enum { MPS_DETECT_NUMBER_DENSITY, MPS_DETECT_ASYMMETRY } mps_detection_kind;

typedef struct mps_scheme {
    const char *name;
    mps_source_kind source;
    mps_gradient_kind gradient;
    mps_laplacian_kind laplacian;
    mps_shift_kind shifting;
    mps_detection_kind detection;
    bool collision;
    double relaxation; /* factor on the eq. 14 source (1: the paper) */
} mps_scheme;

typedef struct mps_data {
    mps_settings s;
    mps_scheme sc;                 /* the resolved choices of s */
    mf_kernel k_nd, k_grad, k_lap; /* one kernel per operator radius */
    /* Neighbour requests (sim->neighbours), all in the order of cells of the
     * largest radius: that radius, each operator's, and the collision's. */
    mf_neighbours *nb;
    int h_max, h_nd, h_grad, h_lap, h_coll;
    /* Field indices in the particle storage. */
    int f_pressure, f_number_density, f_flags;
    /* Pressure module. */
    mf_module pressure;
    const mf_pressure_ops *pressure_ops;
    /* Work arrays, grown as needed. */
    size_t cap;
    double *acc;       /* 3n: explicit acceleration */
    double *grad;      /* 3n: pressure gradient */
    uint8_t *is_fluid, *in_ppe, *dirichlet, *not_dummy;
    long *row;         /* particle -> PPE row, -1 if not in the system */
    long *row_global;  /* on several ranks: particle -> global PPE row (copies: their owners') */
    double *rhs, *x;
    mf_csr A;
    size_t cap_rows, cap_nnz;
    int64_t *slot;     /* PPE row -> its name for the pressure module (mf_rows) */
    size_t cap_slot;
    /* The scheme's work arrays (mps_source.c, mps_shift.c), NULL where the
     * scheme does not use them; one entry per particle unless said. */
    double *n_start;   /* n at r^n (mixed, mixedHigherOrder, errorCompensating) */
    double *rate_start; /* Dn/Dt at r^n, u^n (errorCompensating) */
    double *src;       /* the PPE source / rho of the unknowns (NULL: eq. 14 as printed) */
    double *work;      /* 3n, 15n with shifting: scratch (divergence, minimum, asymmetry, shifting) */
    uint8_t *flag_work; /* n: scratch (LSMPS fallbacks, the surface band) */
    size_t cap_scheme;
    double density_scale;      /* the density terms' factor this step (retries, mps_source.c) */
    long attempt_step;         /* the step, time and dt of the first attempt at this step */
    double attempt_time, attempt_dt;
    long shifted;              /* particles shifted in the last step */
    double shift_largest;      /* their largest shift, in l0 */
    long ls_fallbacks;         /* LSMPS rows that fell back to eq. 5/7, all steps */
    /* Last solve, for the log and for benchmarks. */
    mf_solve_report last;
    long ppe_rows;
    double t_neighbours, t_explicit, t_assembly, t_solve, t_correction;
    long solves;               /* pressure solves run here (sim->pressure_iterations' count) */
    long attempts;             /* explicit phases run here, retried ones included: the
                                * timers' denominator (sim->step counts from before a restart) */
    double t_setup, t_pcg; /* parts of t_solve, as the pressure module reports them */
    /* Multi-fluid, set by a composing solver after mps_create_data (all NULL
     * for one fluid: the single-fluid path, unchanged). Arrays have one entry
     * per particle (walls included) and follow the current particle order. */
    const double *rho;         /* density; NULL: sim->fluid[0].rho */
    const double *mu;          /* dynamic viscosity of fluids; NULL: sim->fluid[0].nu */
    int rho_average, mu_average; /* mf_average of each pair */
    /* PPE: the pressure of particles that are not unknowns but take part
     * (non-dummy neighbours: free surface, or held by another solve); NULL: 0. */
    const double *p_dirichlet;
    /* eq. 15 (gradientPmin): these particles take p^_i = p_i rather than the
     * neighbourhood's minimum (surfaceTension's freeSurface pressure); NULL:
     * none. */
    const uint8_t *own_reference;
    double rho_default;        /* sim->fluid[0].rho, where rho is NULL */
    const char *solve_name;    /* the log's "Solving for <name>"; NULL: p */
    /* PPE source against a per-particle reference: rhs ~ (n*_i - n0 - n_offset_i)/n0
     * (MPS-MAFL's densityReference startOfStep); NULL: none. */
    const double *n_offset;
    /* Called by mps_pressure_phase between the surface phase (n* and the
     * unknowns known, lists at r*) and the assembly, for a composing solver
     * to fill n_offset from r* (MPS-MAFL's densityReference startOfStep);
     * NULL: nothing. */
    int (*before_assembly)(struct mps_data *d, mf_sim *sim, void *ctx);
    void *before_assembly_ctx;
    /* Implicit viscosity (mps_viscosity.c); NULL with `viscosity explicit`. */
    struct mps_viscosity *visc;
    /* Copies of other ranks' particles and periodic images (mps_halo.c); NULL
     * in a serial run without a period. While a step runs, particles
     * [n_owned, n) are copies. */
    struct mps_halo *halo;
    /* `wall wallWeight;` (mps_wall.c): the walls' terms; NULL with wall
     * particles (the walls are particles and the step is unchanged). */
    struct mps_wall *wall;
} mps_data;

enum { MPS_FLAG_SURFACE = 1 }; /* bits of the Flags field */

extern const mf_solver_ops mf_solver_MPS;
#define MPS_NPARAMS 31 /* checked against the table in mps_params.c */
extern const mf_param mps_params[MPS_NPARAMS];
extern const char *const mps_viscosity_choices[]; /* explicit, implicit */
extern const char *const mps_wall_choices[];      /* particles, wallWeight */
extern const char *const mps_gradient_weight_choices[]; /* paper, wendland, wendlandW */
/* The index of word in a NULL-ended choices list, -1 if absent (the
 * parameter table has checked the word; mps_scheme.c). */
int mps_choice(const char *const *choices, const char *word);
/* mps_scheme.c */
extern const char *const mps_scheme_choices[], *const mps_source_choices[],
    *const mps_gradient_choices[], *const mps_laplacian_choices[], *const mps_shifting_choices[],
    *const mps_detection_choices[], *const mps_collision_choices[];
/* The entries of that table, for a solver whose settings embed an
 * mps_settings (the multi-fluid solver): OFF(field) is the offset of the
 * embedded field in the embedding struct; SCHEME the solver's default scheme
 * (docs/topics/schemes.md: MPS robust; MAFL paper, where robust was
 * measured to lose MAFL points; multiFluid stabilised, where paper stopped
 * three of its five tutorials and robust broke the droplets' free-surface
 * pressure). One list, three tables.
 * reNumberDensity 3.1 rather than Koshizuka & Oka's 2.1: on hydrostatic2D
 * the resting pressure comes out 7.5% high at the bottom with 2.1 and within
 * 1% with 3.1 (README, "Choices measured"). */
#define MPS_PARAM_ENTRIES(OFF, SCHEME)                                                          \
    {"reNumberDensity", MF_PARAM_SCALAR, "3.1", 1.01, 10, NULL,                                 \
     OFF(re_number_density),                                                                    \
     "radius of the number density (source term, surface), in l0"},                             \
    {"reGradient", MF_PARAM_SCALAR, "2.1", 1.01, 10, NULL, OFF(re_gradient),                    \
     "radius of the pressure gradient, in l0"},                                                 \
    {"reLaplacian", MF_PARAM_SCALAR, "3.1", 1.01, 10, NULL, OFF(re_laplacian),                  \
     "radius of the Laplacian (viscosity, pressure equation), in l0"},                          \
    {"beta", MF_PARAM_SCALAR, "0.97", 0.5, 1.0, NULL, OFF(beta),                                \
     "free surface where n* < beta n0 (eq. 18)"},                                               \
    {"relaxation", MF_PARAM_SCALAR, "0", 0, 1, NULL, OFF(relaxation),                           \
     "factor on the eq. 14 source term (1: the paper; 0: the scheme's, 0.2 for stabilised)"},   \
    {"compressibility", MF_PARAM_SCALAR, "0", 0, 1e-3, NULL,                                    \
     OFF(compressibility),                                                                      \
     "artificial compressibility, 1/Pa (adds rho c/dt^2 to the diagonal; 0: off)"},             \
    {"clipNegativePressure", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL,                           \
     OFF(clip_negative_pressure), "set negative pressures to zero"},                            \
    {"gradientPmin", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL,                                   \
     OFF(gradient_pmin),                                                                        \
     "pressure gradient with p_min of the neighbourhood (eq. 5 note)"},                         \
    {"gradientWeight", MF_PARAM_WORD, "paper", MF_NO_RANGE, mps_gradient_weight_choices,        \
     OFF(gradient_weight),                                                                      \
     "weight of the pressure gradient's sum (eq. 5), scaled by its own lattice n0: paper "      \
     "(re/r - 1), wendland (-r W'(r) of the Wendland C2 kernel: the pair force -W', Dehnen & "  \
     "Aly 2012), wendlandW (W itself); not with wall wallWeight or gradient leastSquares"},     \
    {"wallPressureExtrapolated", MF_PARAM_BOOL, "no", MF_NO_RANGE, NULL,                        \
     OFF(wall_pressure_extrapolated),                                                           \
     "the pressure gradient takes the wall particles' pressure from their fluid neighbours' "   \
     "(Adami, Hu & Adams 2012, eq. 27) instead of the PPE's (gradient paper, wall particles)"}, \
    {"velocityFilter", MF_PARAM_SCALAR, "0", 0, 1, NULL, OFF(velocity_filter),                 \
     "before the explicit update each fluid velocity u^n moves by eps sum_j c_ij (u_j - u_i) "   \
     "towards its fluid neighbours', c_ij = w_ij / max(n0, s_i, s_j) (XSPH, Monaghan 1989, "    \
     "applied to the velocity; solver MPS only; 0: off)"},                                       \
    {"scheme", MF_PARAM_WORD, SCHEME, MF_NO_RANGE, mps_scheme_choices, OFF(scheme),             \
     "the scheme: the defaults of source, gradient, laplacian, shifting, surfaceDetection "      \
     "and collision (paper: eqs. 5, 7, 14, 18 as printed; robust: mixed source, asymmetry "     \
     "surface test, collision; stabilised: paper with relaxation 0.2 and collision)"},           \
    {"source", MF_PARAM_WORD, "scheme", MF_NO_RANGE, mps_source_choices, OFF(source),          \
     "source term of the pressure equation: density (eq. 14), mixed (Tanaka & Masunaga 2010), " \
     "higherOrder (Khayyer & Gotoh 2009), errorCompensating (Khayyer & Gotoh 2011), "            \
     "mixedHigherOrder (mixed with the divergence in Khayyer & Gotoh 2009's form)"},             \
    {"densityFactor", MF_PARAM_SCALAR, "0.2", 0, 1, NULL, OFF(density_factor),                \
     "source mixed, mixedHigherOrder: weight gamma of the density-deviation term"},            \
    {"gradient", MF_PARAM_WORD, "scheme", MF_NO_RANGE, mps_gradient_choices, OFF(gradient),    \
     "pressure gradient: paper (eq. 5), corrected (CMPS, Khayyer & Gotoh 2008), "               \
     "leastSquares (LSMPS, Tamai & Koshizuka 2014)"},                                           \
    {"laplacian", MF_PARAM_WORD, "scheme", MF_NO_RANGE, mps_laplacian_choices, OFF(laplacian), \
     "Laplacian: paper (eq. 7), higherOrder (Khayyer & Gotoh 2010), leastSquares (LSMPS in "    \
     "the viscous term, higherOrder in the pressure equation; with wall wallWeight the walls' " \
     "virtual points enter each fit, tank and box solids only)"},                               \
    {"shifting", MF_PARAM_WORD, "scheme", MF_NO_RANGE, mps_shifting_choices, OFF(shifting),    \
     "particle shifting: none, fickian (Lind et al. 2012; tangential at the free surface)"},   \
    {"shiftCoefficient", MF_PARAM_SCALAR, "0.05", 0, 1, NULL, OFF(shift_coefficient),          \
     "shifting fickian: A of dr = -A l0^2 grad C"},                                             \
    {"shiftMax", MF_PARAM_SCALAR, "0.05", 0, 0.5, NULL, OFF(shift_max),                         \
     "shifting: largest shift of a particle in a step, in l0"},                                 \
    {"surfaceDetection", MF_PARAM_WORD, "scheme", MF_NO_RANGE, mps_detection_choices,          \
     OFF(surface_detection),                                                                    \
     "free surface: numberDensity (eq. 18), asymmetry (eq. 18 and neighbour asymmetry, "        \
     "Khayyer et al. 2009; walls under fluid stay unknowns)"},                                  \
    {"asymmetry", MF_PARAM_SCALAR, "0.2", 0, 2, NULL, OFF(asymmetry),                          \
     "surfaceDetection asymmetry: surface where n* < beta n0 and the asymmetry exceeds this "   \
     "fraction of a flat surface's"},                                                           \
    {"retrySource", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL, OFF(retry_source),                 \
     "when the watch retries a step with a shorter dt, keep the density terms of the source "   \
     "(mixed, mixedHigherOrder, errorCompensating) at the first attempt's strength (eq. 14 "    \
     "stays as printed)"},                                                                       \
    {"collision", MF_PARAM_WORD, "scheme", MF_NO_RANGE, mps_collision_choices,                 \
     OFF(collision_choice),                                                                     \
     "push apart particles closer than collisionDistance (yes/no; the paper uses none)"},      \
    {"collisionAfterCorrection", MF_PARAM_BOOL, "no", MF_NO_RANGE, NULL,                        \
     OFF(collision_after_correction),                                                           \
     "collide again after the pressure correction (keeps fluid out of thin walls)"},            \
    {"collisionDistance", MF_PARAM_SCALAR, "0.5", 0.1, 1, NULL,                                 \
     OFF(collision_distance), "collision distance, in l0"},                                     \
    {"restitution", MF_PARAM_SCALAR, "0.2", 0, 1, NULL, OFF(restitution),                       \
     "coefficient of restitution of the collision model"},                                      \
    {"reorderInterval", MF_PARAM_INT, "25", 0, 1000000, NULL,                                   \
     OFF(reorder_interval),                                                                     \
     "sort particles along cells every N steps for memory locality (0: never)"},                \
    {"viscosity", MF_PARAM_WORD, "explicit", MF_NO_RANGE, mps_viscosity_choices,                 \
     OFF(viscosity),                                                                            \
     "explicit (eq. 7 in the explicit phase, dt limited by maxDi) or implicit (the solver of "   \
     "solverDict's viscosity { solver NAME; })"},                                                \
    {"periodicLength", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, OFF(periodic_length),                 \
     "period along x, m (0: none); the walls must be open at xmin and xmax"},                    \
    {"periodicOrigin", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL, OFF(periodic_origin),             \
     "x of the periodic box's lower face, m"},                                                   \
    {"wall", MF_PARAM_WORD, "particles", MF_NO_RANGE, mps_wall_choices, OFF(wall),                \
     "walls: particles (wall and dummy particles) or wallWeight (no particles: wall weight "      \
     "functions, Harada et al. 2008, no slip and no penetration on the wall face; solver MPS)"}, \


/* mps_module.c */
/* A linear solve of the solver (kind pressure): the module named by
 * solverDict's `key { solver NAME; ... }` (PCG_BoomerAMG when absent),
 * created with the case's settings and, where the case does not give them
 * and the module has them, the solver's defaults. tolerance (may be NULL):
 * the tolerance used, NAN if the module has none. */
typedef struct mps_default {
    const char *key;
    double value;
} mps_default;
int mps_create_solve(const mf_sim *sim, const mf_dict *solver_dict, const char *key,
                     const mps_default *defaults, size_t ndefaults, mf_module *out,
                     double *tolerance);
int mps_create_data(const mps_settings *s, mf_sim *sim, const mf_dict *solver_dict,
                    mps_data **out);
void mps_destroy_data(mps_data *d);
int mps_reserve(mps_data *d, size_t n);

/* mps_step.c: phases of one step (Algorithm 1). */
/* An order point of the neighbour service at the current positions, and the
 * lists there; with reorder, particles are first sorted along cells every
 * reorder_interval steps. */
int mps_build_neighbours(mps_data *d, mf_sim *sim, bool reorder);
/* The pairs of one of mps_data's requests at the current positions. */
int mps_pairs(const mps_data *d, const mf_sim *sim, int handle, mf_pairs *out);
void mps_set_masks(mps_data *d, const mf_particles *p);          /* is_fluid, not_dummy */
int mps_explicit_phase(mps_data *d, mf_sim *sim, double dt);     /* eqs. 9-10 (27) */
/* eq. 18: number density at r*, free surface, PPE unknowns (in_ppe). */
int mps_surface_phase(mps_data *d, mf_sim *sim);
int mps_pressure_phase(mps_data *d, mf_sim *sim, double dt);     /* eqs. 11-14, 18 */
int mps_correction_phase(mps_data *d, mf_sim *sim, double dt);   /* eqs. 15-17 */
/* The whole Lagrangian step, as MPS-MAFL calls it. */
int mps_lagrangian_step(mps_data *d, mf_sim *sim, double dt);

/* mps_scheme.c: the scheme's choices from the settings (errors name the
 * dictionary); the work arrays the scheme needs; its log line. */
int mps_scheme_resolve(const mps_settings *s, int dim, mps_scheme *out);
int mps_scheme_reserve(mps_data *d, size_t n);
/* The scheme's work arrays' pages given back (mf_release_pages) once they
 * are dead for the step: n_start, rate_start and work once the source is
 * made (mps_source_terms), src too (with_src) once the matrix is. Each is
 * rewritten in the next step before it is read. Returns the bytes released. */
size_t mps_scheme_release(mps_data *d, bool with_src);
void mps_scheme_free(mps_data *d);
void mps_scheme_log(const mps_data *d, mf_log *log);

/* mps_source.c: the source term of the pressure equation. */
/* At r^n with u^n (lists at r^n), before the explicit phase: what the
 * source needs of the start of the step. */
int mps_source_start(mps_data *d, mf_sim *sim);
/* At r* with u* (lists at r*), after the surface phase: d->src of the
 * unknowns (in_ppe), or nothing for the density source of eq. 14. */
int mps_source_terms(mps_data *d, const mf_sim *sim, double dt);

/* mps_bodies.c: the force and torque of the fluid on the rigid bodies
 * (core/scene/mf_bodies.h), the opposite of what the fluid received from
 * their particles: begin (at the start of an attempt), the viscous share
 * (explicit phase, lists at r^n), the pressure share (correction phase,
 * lists at r*). Nothing without a rigid body; a clear error where the
 * step's sums do not split over pairs or on several ranks. */
/* The bodies' WallId field into the halo copies (after mps_halo_create). */
int mps_bodies_halo(mps_data *d, const mf_sim *sim);
void mps_bodies_begin(mps_data *d, mf_sim *sim);
int mps_bodies_viscous(mps_data *d, mf_sim *sim);
int mps_bodies_pressure(mps_data *d, mf_sim *sim, const double *pressure);

/* mps_shift.c: particle shifting after the correction (Lind et al. 2012). */
int mps_shift(mps_data *d, mf_sim *sim);
/* mps_xsph.c: the XSPH velocity filter on u^n in the explicit phase (Monaghan 1989). */
int mps_velocity_filter(mps_data *d, mf_sim *sim);

/* mps_ppe.c */
int mps_assemble_ppe(mps_data *d, const mf_sim *sim, double dt);
int mps_solve_ppe(mps_data *d, mf_sim *sim);

/* mps_pairs.c: the correction with a per-pair coefficient (multi-fluid). */
/* eq. 15 with 1/rho_ij: grad_i = d/n0 sum_j (1/rho_ij) (p_j - p^_i) r_ij/|r_ij|^2 w_ij
 * (the pressure acceleration, already divided by the density), p^_i = p_i or
 * the neighbourhood minimum (gradientPmin), into d->grad for the fluid
 * particles with imask set (NULL: all fluid; imask holds fluid particles
 * only); p of non-dummy neighbours. */
int mps_gradient_pairs(mps_data *d, const mf_sim *sim, const double *pressure,
                       const uint8_t *imask);
/* The corrected gradient's p^ (CMPS: eq. 5's neighbourhood minimum, always)
 * of every particle the sums over v read, into fhat (p->n): the owned
 * particles' from their neighbours, the halo copies' their owners' (a
 * copy's own neighbourhood is incomplete). */
int mps_corrected_pmin(const mps_data *d, const mf_sim *sim, const mf_pairs *v,
                       const double *pressure, double *fhat);
/* eqs. 16-17 for those particles: u' = -dt grad, u += u', r += dt u'.
 * Returns max |u'|. */
double mps_apply_correction(mps_data *d, mf_particles *p, double dt, const uint8_t *imask);

/* mps_viscosity.c: implicit viscosity. Solve, per velocity component,
 *   (I - dt nu <lap>) u* = u^n + dt a_forces
 * with the eq. 7 Laplacian (per particle rho and pair mu_ij with
 * mps_data.mu: rows scaled by rho_i, so the matrix stays symmetric), walls and
 * dummies as Dirichlet values (their velocity), free-surface particles in the
 * system with their missing neighbours absent. */
/* The solver is solverDict's `viscosity { solver NAME; ... }` (a module of
 * kind pressure; PCG_BoomerAMG, tolerance 1e-10 by default). */
int mps_viscosity_create(mps_data *d, mf_sim *sim, const mf_dict *solver_dict);
void mps_viscosity_destroy(struct mps_viscosity *v);
/* Replaces the explicit update of mps_explicit_phase: d->acc holds the force
 * accelerations; on return u = u*, r = r^n + dt u*. */
int mps_viscosity_implicit(mps_data *d, mf_sim *sim, double dt);
void mps_viscosity_report(const struct mps_viscosity *v, const mf_sim *sim, mf_log *log);

/* mps_halo.c: copies of other ranks' particles (a -parallel run) and
 * periodic images along x, appended after n_owned for the duration of a
 * step; operators read them like any neighbour, mps_halo_sync gives them
 * their owners' values of what a phase computed (masks, global PPE rows,
 * pressure). Nothing of it exists in a serial run without a period. */
int mps_halo_create(mps_data *d, mf_sim *sim);
void mps_halo_destroy(struct mps_halo *mh);
/* A particle field the copies carry, at r^n (the explicit phase) and/or at
 * r* (the pressure phase). */
enum { MPS_HALO_START = 1, MPS_HALO_STAR = 2 };
int mps_halo_add_field(mps_data *d, int field, int when);
/* Drop the copies, wrap the period; at the first build of a step
 * (step_start) particles also migrate between ranks. */
int mps_halo_begin(mps_data *d, mf_sim *sim, bool step_start);
int mps_halo_add(mps_data *d, mf_sim *sim, bool at_star); /* build the copies */
void mps_halo_end(mps_data *d, mf_sim *sim);    /* drop them, wrap */
/* The copies of values (n values of size bytes each) from their owners.
 * Collective; nothing without a halo. */
int mps_halo_sync(const mps_data *d, const mf_sim *sim, void *values, size_t size);
/* Positions and velocities of the copies from their owners'. */
int mps_halo_sync_motion(const mps_data *d, const mf_sim *sim);
/* Rows over the ranks: row[i] of the owned particles holds a local row (or
 * -1) of the nrows this rank has. *offset, *nglobal: where this rank's rows
 * start (the ranks' rows follow each other in rank order) and how many
 * there are in all. On one rank an image's row[j] becomes its owner's and
 * *global_col is NULL (column = offset + row). On several, global[] (n
 * entries) holds every particle's global row, the copies their owners',
 * row[j] of a copy says only whether it has one (0 or -1), and *global_col
 * is global (mf_rows.global_col). */
int mps_global_rows(const mps_data *d, const mf_sim *sim, long *row, size_t nrows,
                    long *global, int64_t *offset, int64_t *nglobal, const long **global_col);

/* mps_wall.c: `wall wallWeight;`, the walls' part of each operator from the
 * wall weight tables (each a function of core/particles/mf_wall_terms.h
 * over the owned fluid particles). Nothing of it runs with wall particles
 * (d->wall NULL). */
/* An error naming where `wall` was set, with why (0 when s says particles). */
int mps_wall_refuse(const mps_settings *s, const mf_dict *solver_dict, const char *why);
/* file:line:col of key in the solver dictionary's Coeffs (into buf). */
const char *mps_key_where(const mf_dict *sd, const char *key, char *buf, size_t len);
/* The tables and work arrays (nothing with wall particles); refuses the
 * choices the terms do not cover. */
int mps_wall_create(mps_data *d, mf_sim *sim, const mf_dict *solver_dict);
void mps_wall_destroy(struct mps_wall *w);
/* The wall weight sums of the owned fluid particles at their positions. */
int mps_wall_points(mps_data *d, const mf_sim *sim);
/* d->acc (the forces only) kept for the pressure continued into the walls. */
void mps_wall_keep_forces(mps_data *d, const mf_sim *sim);
/* After the explicit update (u = u*): across each wall face the forces'
 * acceleration replaced by (u* - u_w).n / dt. */
void mps_wall_keep_approach(mps_data *d, const mf_sim *sim, double dt);
void mps_wall_number_density(const mps_data *d, const mf_sim *sim, double *n);
void mps_wall_viscous(mps_data *d, const mf_sim *sim, double nu);              /* into d->acc */
/* eq. 7's wall term only where mask is set (the LSMPS fit's fallbacks). */
void mps_wall_viscous_where(mps_data *d, const mf_sim *sim, double nu, const uint8_t *mask);
/* laplacian leastSquares: nu <lap u> into d->acc by LSMPS with the walls'
 * virtual points in each fit (plane faces); failed as mf_lsmps_laplacian_add. */
size_t mps_wall_lsmps_laplacian(mps_data *d, const mf_sim *sim, const mf_pairs *v, double nu,
                                uint8_t *failed);
void mps_wall_divergence(const mps_data *d, const mf_sim *sim, const uint8_t *imask,
                         double *div);
/* Into d->grad; phat: p^ of eq. 5 (the neighbourhood's minimum or p). */
/* Adami, Hu & Adams 2012's wall pressure (mps_wall_pressure.c): out = pressure,
 * the wall particles' entries from their fluid neighbours in v. */
void mps_wall_pressure_extrapolate(const mps_data *d, const mf_sim *sim, const mf_pairs *v,
                                   const double *pressure, double *out);
void mps_wall_gradient(const mps_data *d, const mf_sim *sim, const double *pressure,
                       const double *phat, double rho);
int mps_wall_collide(mps_data *d, mf_sim *sim, double dt);                    /* against faces */
void mps_wall_report(const struct mps_wall *w, mf_log *log);

#endif
