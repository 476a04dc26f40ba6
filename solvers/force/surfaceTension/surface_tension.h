/* surface_tension.h: the surface tension force of the paper's Appendix A
 * (after Nomura et al. 2001), eq. 33's sigma kappa delta n per unit volume,
 * returned as the acceleration f_st / rho_x of eq. 27 (and written to the
 * SurfaceTension field; the curvature to Curvature).
 *
 * Interface particles. A fluid particle of fluid x is on an interface when a
 * particle of another fluid lies within r_st, or (a free surface, where
 * sigma_x > 0) when fewer than beta N_full particles of any kind lie within
 * r_st, N_full the count of a full neighbourhood in the current packing.
 * Walls and dummies count as the particle's own fluid (no contact-angle
 * model).
 *
 * Counts (eqs. 34-37). n^st1_i counts the own-fluid particles within r_st
 * (w = 1 inside r_st); n^st2_i only those deeper inside than i,
 * n^st1_j > n^st1_i, a tie counting one half (the particle's own layer is
 * neither in nor out whatever the disorder); walls count as deeper. n0^st
 * is n^st2 at a flat interface (kappa = 0): on the lattice it is N_full / 2,
 * and N_full is measured on the deep particles of the current packing
 * (disorder changes it by a particle or two). Where the probe is full (an
 * interface between fluids) the particle's own count of every particle
 * stands for N_full.
 *
 * Curvature, with f = n^st2 / (2 n0^st) the fraction of the r_st disk
 * (ball) the fluid fills:
 *   paper:  eqs. 38-39, 2 theta = pi n^st2 / n0^st, kappa = 2 cos(theta)/r_st.
 *           They take the fluid's part of the disk as the sector of angle
 *           2 theta and leave out the two segments between the chords and
 *           the arc: f = 1/2 - r_st/(3 pi R) where the sector gives
 *           1/2 - r_st/(2 pi R), so kappa comes out 2/3 of 1/R.
 *   exact:  f inverted through the exact area of a disk of radius r_st
 *           centred on a circle of radius R (2-D), or the volume of a ball
 *           centred on a sphere (3-D, f = 1/2 - 3 r_st/(16 R), kappa = 2/R,
 *           the sum of the principal curvatures: dp = sigma kappa is
 *           Laplace's 2 sigma/R). Right on a lattice drop, but the counts
 *           follow the particle density: in motion a few per cent of
 *           compression at the interface reads as a curvature of 1/R.
 *   normal: (default) kappa = div n, n the outward unit normal of the colour
 *           gradient (Brackbill et al. 1992): insensitive to the density.
 * (README, "Multi-fluid", has the measurements.)
 *
 * delta n (eq. 33). The colour C_x (1 in fluid x, 0 elsewhere) has the
 * gradient g^y_i = -C sum_{j in y} phi(r_ij) r_hat_ij toward another fluid
 * y and g^0_i = C sum_{j present} phi r_hat (the missing neighbours' share)
 * toward the void, phi = (1 - r/r_st)^2, C = d / sum_lattice r phi(r): across
 * a flat interface the sum of g over a column of particles is half the jump
 * of C on each side. So each side of a fluid/fluid interface takes
 * sigma_xy kappa g^y (kappa the pair's mean curvature: the two sides carry
 * equal shares) and a free surface, which has one side, 2 sigma_x kappa g^0.
 * The force per unit volume integrated across the interface is sigma kappa.
 *
 * Free surfaces, freeSurface:
 *   force:    (default) the paper's form above. The free-surface particles of
 *             the solver (eq. 18: n* < beta n0, p = 0) are the outer layers of
 *             the band: they take their share of the force with no pressure,
 *             and the pressure inside a drop comes out about 0.6-0.7 sigma/R.
 *   pressure: the Laplace pressure sigma kappa is the Dirichlet value of the
 *             solver's free-surface particles instead of 0 (the usual
 *             free-surface treatment of surface tension), and no force acts on
 *             free surfaces (it would count the jump twice); the curvature is
 *             computed as above. A solver applies it through
 *             mf_forces_surface_pressure (forces.h): multiFluid, one solve.
 *
 * Tension of a pair: sigma_xy of an `interfaces` entry, else Antonow's rule
 * |sigma_x - sigma_y| (a fluid against one with sigma 0 keeps its own
 * sigma); a free surface of fluid x: sigma_x.
 *
 * The folder, one job a file (the shared data and the phases are declared
 * below):
 *   st_params.c     the parameter table
 *   st_module.c     create, destroy, the work arrays, the fields written,
 *                   the ops table
 *   st_tensions.c   sigma of each fluid pair (constant/fluids, interfaces)
 *   st_interface.c  the counts of eqs. 34-37 and the interface particles
 *   st_curvature.c  the count models of the curvature (exact, paper) and
 *                   the lattice constants
 *   st_normal.c     the normal model: smoothed normals and their divergence
 *   st_smooth.c     curvature smoothing over free surfaces
 *   st_force.c      the force sigma kappa delta n (accumulate: every phase
 *                   in order)
 *   st_pressure.c   freeSurface pressure: the Laplace pressure for the solver
 *   st_timestep.c   the capillary time-step limit
 */
#ifndef MF_SURFACE_TENSION_H
#define MF_SURFACE_TENSION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "force/forces.h"
#include "mf_pairs.h"

typedef struct st_settings {
    double radius;          /* r_st in l0 */
    const char *curvature;  /* exact | paper */
    double beta;            /* free surface below beta N_full */
    double dt_factor;       /* capillary time step factor */
    long smoothing;         /* passes of curvature smoothing */
    const char *free_surface; /* force | pressure */
    const mf_dict *interfaces;
} st_settings;

#define ST_NPARAMS 7 /* checked against the table in st_params.c */
extern const mf_param st_params[ST_NPARAMS];

#define EXACT_TABLE 2001 /* the 2-D area fraction F(eps), eps = r_st / R in [0, 2] */

typedef struct st_data {
    st_settings s;
    bool paper, normal;
    bool pressure_mode;        /* freeSurface pressure: p = sigma kappa, no force there */
    bool claimed;              /* a solver applies the surface pressure */
    double g_ref;              /* |delta n| of the outer layer of a flat lattice surface */
    int dim;
    double l0, r;              /* r = r_st in m */
    int nfluids;
    double sigma[MF_MAX_FLUIDS][MF_MAX_FLUIDS]; /* fluid pairs; [x][x]: free surface of x */
    bool any;                  /* some tension is > 0 */
    double n_full, n0st;       /* eqs. 34-39 on the lattice */
    double g_coef;             /* d / sum_lattice r phi(r): the colour gradient's constant */
    double table_f[EXACT_TABLE];
    int f_curvature;           /* Curvature field */
    int f_accel;               /* SurfaceTension field: f_st / rho_x, m/s^2 */
    int pairs;                 /* neighbour request within r_st (sim->neighbours) */
    size_t cap;
    int32_t *n1, *nall;
    double *kappa, *kappa_s, *fdir;
    double *nrm;               /* outward unit normal of the particle's own fluid; 0: none */
    double *p_surface;         /* freeSurface pressure: sigma kappa near a free surface; NAN */
    size_t p_surface_n;        /* particles p_surface holds (this step's) */
    /* The last accumulate's curvature and acceleration, for write_fields
     * (accumulate itself leaves the fields alone: forces are side-effect free). */
    double *kappa_out, *accel_out;
    size_t out_n;              /* particles they hold */
} st_data;

/* What the phases' loops share: the pairs within r_st and the fields. */
typedef struct st_ctx {
    st_data *d;
    const mf_particles *p;
    const int32_t *fid;
    const mf_pairs *v;
    double n_full, thr;
    const double *kin; /* curvature smoothing: the pass's input */
    double *kout;
    const double *kap; /* the force and the surface pressure: the curvature */
    double *acc, *accel_out, *kappa_out;
    const mf_sim *sim;
} st_ctx;

/* The weight of the colour gradient (delta n): the gradient of the smooth
 * number density sum_j phi(r_ij), phi = (1 - r/r_st)^2. Not the MPS weight
 * re/r - 1: its 1/r singularity lets the nearest neighbour decide the
 * normal, and when the outer layer is pressed onto the next one, that
 * layer's normal turns outward and the force pushes it out (measured on a
 * 2-D drop: the integrated force fell from sigma/R to 0.2 sigma/R within
 * 0.1 s). */
static inline double colour_weight(double r, double rst)
{
    return r < rst ? (1 - r / rst) * (1 - r / rst) : 0.0;
}

static inline int fluid_of(const int32_t *fid, size_t i) { return fid ? fid[i] : 0; }

/* Same fluid as x (walls and dummies count as every fluid's own). */
static inline bool own(const mf_particles *p, const int32_t *fid, size_t j, int x)
{
    return p->kind[j] != MF_FLUID || fluid_of(fid, j) == x;
}


/* st_module.c */
int st_reserve(st_data *d, size_t n);
/* st_tensions.c */
int st_setup_tensions(st_data *d, const mf_sim *sim);
/* st_curvature.c */
void st_lattice_counts(st_data *d);
void st_exact_table(st_data *d);
double st_curvature(const st_data *d, double f);
/* st_interface.c */
void st_count_neighbours(const st_ctx *c);
double st_measured_full_count(st_ctx *c);
void st_find_interface(const st_ctx *c);
/* st_normal.c */
void st_smooth_normals(const st_ctx *c);
void st_normal_divergence(const st_ctx *c);
/* st_smooth.c */
const double *st_smooth_curvature(st_ctx *c);
/* st_force.c */
int st_accumulate(void *data, const mf_sim *sim, double *acc);
/* st_pressure.c */
void st_surface_pressure_field(const st_ctx *c);
bool st_claim_surface_pressure(void *data);
int st_surface_pressure(void *data, const mf_sim *sim, const uint8_t *dirichlet, double *p);
/* st_timestep.c */
int st_stable_dt(void *data, const mf_sim *sim, double *out);

#endif
