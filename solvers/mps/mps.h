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
 * its Lagrangian phase; the multi-fluid solver reuses the PPE assembly with
 * a per-pair density.
 */
#ifndef MPS_H
#define MPS_H

#include <stdbool.h>
#include <stdint.h>

#include "mf_kernel.h"
#include "mf_modules.h"
#include "mf_neighbours.h"

typedef struct mps_settings {
    double re_number_density; /* radii in units of l0 */
    double re_gradient;
    double re_laplacian;
    double beta;              /* eq. 18: free surface when n* < beta n0 */
    double relaxation;        /* factor on the PPE source term (1: the paper) */
    double compressibility;   /* 1/Pa; adds rho c / dt^2 to the diagonal (0: off) */
    bool clip_negative_pressure;
    bool gradient_pmin;       /* eq. 5 with p_min (Koshizuka et al. 1998) */
    bool collision;           /* optional collision model (off: the paper uses none) */
    double collision_distance; /* in l0 */
    double restitution;
    long reorder_interval;    /* sort particles along cells every N steps (0: never) */
} mps_settings;

typedef struct mps_data {
    mps_settings s;
    mf_kernel k_nd, k_grad, k_lap; /* one kernel per operator radius */
    mf_grid grid;
    mf_nlist nl_max, nl_nd, nl_grad, nl_lap; /* at the largest radius, and filtered */
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
    double *rhs, *x;
    mf_csr A;
    size_t cap_rows, cap_nnz;
    /* Last solve, for the log and for benchmarks. */
    mf_solve_report last;
    long ppe_rows;
    double t_neighbours, t_explicit, t_assembly, t_solve, t_correction;
    double t_setup, t_pcg; /* parts of t_solve, as the pressure module reports them */
} mps_data;

enum { MPS_FLAG_SURFACE = 1 }; /* bits of the Flags field */

extern const mf_solver_ops mf_solver_MPS;
#define MPS_NPARAMS 12 /* checked against the table in mps_params.c */
extern const mf_param mps_params[MPS_NPARAMS];

/* mps_module.c */
int mps_create_data(const mps_settings *s, mf_sim *sim, const mf_dict *solver_dict,
                    mps_data **out);
void mps_destroy_data(mps_data *d);
int mps_reserve(mps_data *d, size_t n);

/* mps_step.c: phases of one step (Algorithm 1). */
/* Grid and lists at the current positions; with reorder, particles are
 * first sorted along cells every reorder_interval steps. */
int mps_build_neighbours(mps_data *d, mf_sim *sim, bool reorder);
int mps_explicit_phase(mps_data *d, mf_sim *sim, double dt);     /* eqs. 9-10 */
int mps_pressure_phase(mps_data *d, mf_sim *sim, double dt);     /* eqs. 11-14, 18 */
int mps_correction_phase(mps_data *d, mf_sim *sim, double dt);   /* eqs. 15-17 */
/* The whole Lagrangian step, as MPS-MAFL calls it. */
int mps_lagrangian_step(mps_data *d, mf_sim *sim, double dt);

/* mps_ppe.c */
int mps_assemble_ppe(mps_data *d, const mf_sim *sim, double dt);
int mps_solve_ppe(mps_data *d, mf_sim *sim);

#endif
