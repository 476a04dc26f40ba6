/* mf_modules.h: the kind-specific ops tables. Each starts with the common
 * mf_module_info header (so the registry can hold any of them), then the
 * slots of its kind. Required slots are listed first; optional ones may be
 * NULL. Tables only grow at the end (MF_ABI_VERSION says which layout): each
 * slot added after version 1 is marked with the version that added it, and
 * mf_ops_size gives a kind's table size at each version, so that the
 * registry can read an older module's table without reading past its end.
 *
 * Calls into a module go through the thin wrappers at the end of this file
 * (mf_force_accumulate, mf_pressure_solve, mf_solver_step, ...), in the
 * manner of PETSc's KSPSolve and SQLite's API wrappers: the log line, the
 * timers, the checks of the result and the fault-injection point are there,
 * once.
 *
 * Naming (PETSc's habit): a module `foo` of kind `bar` implements
 * foo_create, foo_<verb>, foo_destroy as static functions in
 * solvers/<bar>/foo.c (or plugins/foo/) and exports one const table.
 */
#ifndef MF_MODULES_H
#define MF_MODULES_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stdint.h>

#include "mf_registry.h"
#include "mf_sim.h"

/* ---- solver: advances the particles by one time step ------------------- */
typedef struct mf_solver_ops {
    mf_module_info info;
    /* Required. `dict` is the solver's coefficient dictionary (its settings
     * are already filled); the module requests its fields here. */
    int (*create)(const void *settings, mf_sim *sim, const mf_dict *solver_dict, void **data);
    /* Required. Advance from sim->time by dt. Return >0 (MF_RETRY) when the
     * step failed in a way a smaller dt may fix; the driver then restores
     * the particles and retries. */
    int (*step)(void *data, mf_sim *sim, double dt);
    void (*destroy)(void *data);
    /* Optional: the largest stable dt the module knows of (viscous limit...). */
    int (*stable_dt)(void *data, const mf_sim *sim, double *dt);
    /* Optional: print where the time went (benchmarks, end of a run). */
    void (*report)(void *data, const mf_sim *sim, mf_log *log);
} mf_solver_ops;

/* ---- pressure: solves the (symmetric positive definite) PPE ------------- */
/* Local rows of a distributed sparse matrix in CSR form. Columns are global
 * indices; this rank owns rows [row_offset, row_offset + nrows). Columns are
 * 32-bit, as the hypre of the platform's packages (HYPRE_BigInt is int
 * without --enable-bigint): the matrix is the largest array of a run, and a
 * system has fewer than 2^31 unknowns in all.
 * Callers zero-initialise an mf_csr (a designated initialiser, calloc, or
 * memset) before filling it: fields added at its end (lent_capacity) must
 * read 0, "nothing lent", wherever a caller does not know of them. */
typedef struct mf_csr {
    size_t nrows;
    int64_t row_offset;
    int64_t nglobal;
    size_t *rowptr;   /* nrows + 1 */
    int32_t *col;     /* rowptr[nrows] */
    double *val;      /* rowptr[nrows] */
    /* > 0: the caller lends col and val (room for lent_capacity entries from
     * index 0) to the solve, which may rearrange them while it runs and puts
     * them back, bit for bit, before it returns (solvers/pressure/
     * fine_in_place.c: hypre's fine matrix made in them); 0: read only. */
    size_t lent_capacity;
} mf_csr;
#define MF_CSR_MAX_GLOBAL INT32_MAX

/* Names of the rows of a system, for a pressure module that reuses work
 * (an AMG hierarchy) across solves whose rows change: row r is unknown
 * slot[r] (MPS: the index of its particle), and two solves with the same
 * nslots and epoch mean the same unknown by the same slot (the caller
 * changes epoch when the slots change meaning: particles reordered, added
 * or removed). */
typedef struct mf_row_names {
    const int64_t *slot; /* one per local row, distinct, in [0, nslots) */
    int64_t nslots;
    uint64_t epoch;
} mf_row_names;

typedef struct mf_solve_report {
    int iterations;
    double initial_residual; /* ||b - A x0|| / ||b|| */
    double final_residual;   /* ||b - A x|| / ||b|| */
    bool converged;
    double setup_seconds, solve_seconds;
    int setups; /* preconditioner set-ups this solve made (0: a kept one served) */
} mf_solve_report;

typedef struct mf_pressure_ops {
    mf_module_info info;
    int (*create)(const void *settings, void **data);
    /* x holds the initial guess on entry and the solution on return.
     * MF_RETRY when not converged within the iteration limit. */
    int (*solve)(void *data, const mf_csr *A, const double *b, double *x, mf_solve_report *rep);
    void (*destroy)(void *data);
    /* ABI 2, optional: solve with the rows named (see mf_row_names), so that the
     * module may keep its preconditioner across solves of changing matrices.
     * Absent: mf_pressure_solve calls solve. */
    int (*solve_rows)(void *data, const mf_csr *A, const mf_row_names *rows, const double *b,
                      double *x, mf_solve_report *rep);
} mf_pressure_ops;

/* ---- convection scheme (MPS-MAFL Eulerian phase) -------------------------- */
typedef struct mf_convection_ops {
    mf_module_info info;
    int (*create)(const void *settings, void **data);
    /* One point of the 1-D directional grid: f[0..3] = f_{i-2}, f_{i-1},
     * f_i, f_{i+1}; q = |u| dt / dr. Returns the new f_i. */
    double (*convect)(const void *data, const double f[4], double q);
    void (*destroy)(void *data);
} mf_convection_ops;

/* ---- force: adds an acceleration to fluid particles ---------------------- */
/* mf_force_ops.flags */
enum {
    /* An interaction among the fluid particles only (no body force, no
     * wall, no outside medium): on fluid particles alone the momentum it
     * adds, sum_i m_i a_i, vanishes (in the continuum, and within the
     * discretisation's error on particles): tests/test_force_conformance.c
     * checks it. surfaceTension is one; gravity and drag are not. */
    MF_FORCE_INTERNAL = 1u << 0,
};

typedef struct mf_force_ops {
    mf_module_info info;
    int (*create)(const void *settings, mf_sim *sim, void **data);
    /* Required. Add this force's acceleration (m/s^2) of the owned particles
     * at their current state to acc (3 * sim->p->n entries). Side-effect
     * free: it changes nothing in sim (no particle, no field), and two calls
     * on the same state give the same acc; the module may keep what it
     * computed in its own data, for write_fields and surface_pressure.
     * Solvers call it through mf_force_accumulate, never directly. */
    int (*accumulate)(void *data, const mf_sim *sim, double *acc);
    void (*destroy)(void *data);
    /* ABI 2: MF_FORCE_* flags. */
    unsigned flags;
    /* ABI 2, optional: the largest step this force allows at the current
     * state (INFINITY: none). The time loop takes the smallest of every
     * force's, the solver's and the case's limits (mf_stable_dt). */
    int (*stable_dt)(void *data, const mf_sim *sim, double *dt);
    /* ABI 2, optional: fill the output fields the module requested at create
     * (surfaceTension: Curvature, SurfaceTension) from its last accumulate;
     * called by mf_force_accumulate right after it, on the same particles. */
    int (*write_fields)(void *data, mf_sim *sim);
    /* ABI 2, optional, for a force that acts on a free surface through its
     * pressure (surfaceTension's freeSurface pressure: the Laplace pressure
     * becomes eq. 18's Dirichlet value). claim_surface_pressure: a solver
     * that holds such pressures calls it once at create (through
     * mf_forces_claim_surface_pressure); true if this force has one, and
     * from then on the force leaves the free surface to it (a force that
     * needs the claim and did not get it fails its accumulate, saying so).
     * surface_pressure: after this step's accumulate, add the force's
     * pressure of every owned particle with dirichlet[i] set to p[i]. */
    bool (*claim_surface_pressure)(void *data);
    int (*surface_pressure)(void *data, const mf_sim *sim, const uint8_t *dirichlet, double *p);
} mf_force_ops;

/* ---- function object: observes a run ------------------------------------ */
typedef struct mf_function_object_ops {
    mf_module_info info;
    /* out_dir: where it may write (the case's postProcessing/<name>/). */
    int (*create)(const void *settings, const mf_sim *sim, const char *out_dir, void **data);
    int (*execute)(void *data, const mf_sim *sim); /* after every step */
    void (*destroy)(void *data);
    int (*write)(void *data, const mf_sim *sim);   /* optional: at write times */
} mf_function_object_ops;

/* ---- writer: snapshots and restart --------------------------------------- */
typedef struct mf_writer_ops {
    mf_module_info info;
    int (*create)(const void *settings, const char *case_dir, void **data);
    /* Write the state at sim->time; `params` is the resolved case (may be NULL). */
    int (*write)(void *data, const mf_sim *sim, const mf_dict *params);
    void (*destroy)(void *data);
    /* Optional: restore particles, time and step from the newest snapshot.
     * Returns MF_ERR_INPUT if there is none. */
    int (*read_latest)(void *data, mf_sim *sim);
    /* ABI 2, optional (purgeWrite): delete the snapshots this writer wrote but the
     * newest `keep`; the initial state (snapshot 0) is never deleted. */
    int (*purge)(void *data, long keep);
} mf_writer_ops;

/* ---- surface reconstructor (level set, blobby) --------------------------- */
struct mf_mesh; /* core/output/mf_mesh.h */
typedef struct mf_surface_ops {
    mf_module_info info;
    int (*create)(const void *settings, void **data);
    void (*destroy)(void *data);
    /* Added with the level set (solvers/levelset). Reconstruct the surface of
     * the fluid particles (kind MF_FLUID) of sim at sim->time into out
     * (replacing its contents). A module may keep state between calls: the
     * level set starts each frame from the previous one's. Bad input (no
     * fluid particle, a non-finite position, a grid too fine for memory) is
     * MF_ERR_INPUT or MF_ERR_MEMORY with a message saying what to change. */
    int (*reconstruct)(void *data, const mf_sim *sim, struct mf_mesh *out);
} mf_surface_ops;

/* ---- metric: scores a run against reference data (validation) --------- */
/* What a metric works on: the case (its validation/ reference data, its
 * constant/), the snapshots to use (all of output/ for `validate`, the
 * -time selection for `-postProcess`) and where its report goes
 * (validation/ for `validate`, postProcessing/<name>/ for -postProcess). */
typedef struct mf_metric_ctx {
    const char *case_dir;
    const int *selected;   /* snapshot indices, ascending; NULL: every snapshot */
    size_t nselected;
    const char *out_dir;   /* result.csv and result.png go here */
    /* validation/metric itself, for entries a parameter table cannot hold
     * (a list: volumeFlux's stations); its other keys are in the settings. */
    const mf_dict *dict;
    /* Set by the host, so that a metric (a plugin's too) reads snapshots
     * without the io layer. snapshots: the indices of ctx's snapshots,
     * ascending (malloc'ed: free *indices). read_snapshot: snapshot `index`
     * into a zeroed *snap: snap->p (every particle the file holds; free it
     * with mf_particles_destroy), snap->dim, l0, time, step, and the case's
     * fluids (snap->fluid, nfluids: mf_sim_particle_mass works on it). */
    int (*snapshots)(const struct mf_metric_ctx *ctx, int **indices, size_t *n);
    int (*read_snapshot)(const struct mf_metric_ctx *ctx, int index, mf_sim *snap);
} mf_metric_ctx;

/* ABI 3 (the kind itself). info.params are the keys of the case's
 * validation/metric (the `metric` key that names it among them): the host
 * checks the file against them and fills the settings (mf_module_prepare)
 * before it calls evaluate, so a typo is refused with its file, line and
 * key. Metrics run after the run, in the post-processing layer
 * (driver/post): they read snapshots and write reports; no solver calls
 * them. */
typedef struct mf_metric_ops {
    mf_module_info info;
    /* Required. Score the snapshots of ctx: write ctx->out_dir/result.csv
     * (and, where it can, result.png), set *error (smaller is better; the
     * number `mpsflow validate` prints). */
    int (*evaluate)(const void *settings, const mf_metric_ctx *ctx, double *error);
    /* Keys of validation/metric that evaluate reads from ctx->dict itself
     * (NULL-terminated; may be NULL). FoamFile is always allowed. */
    const char *const *extra_keys;
} mf_metric_ops;

/* The size of a kind's table as a module built for ABI version abi has it
 * (0: unknown kind or version). Tables only grow, so an older table is the
 * prefix of the current layout of this size. */
size_t mf_ops_size(mf_module_kind kind, int abi);

/* ---- creating a module from a case ------------------------------------- */
/* Find `name` of `kind`, allocate its settings and fill them from dict
 * (defaults for what dict does not give; extra_keys are allowed but not the
 * module's). resolved (may be NULL) receives the values used. out->data is
 * left NULL for the kind-specific create. */
int mf_module_prepare(const mf_registry *reg, mf_module_kind kind, const char *name,
                      const mf_dict *dict, const char *const *extra_keys, mf_dict *resolved,
                      mf_module *out);
/* Free the settings (call the kind's destroy on out->data first). */
void mf_module_release(mf_module *m);

/* ---- calling modules: the thin wrappers (core/host/module_calls.c) ------ */
/* Every force of the case (sim->forces): add their accelerations of the
 * owned particles at the current state to acc (3 * sim->p->n entries, not
 * cleared). Also: each force's write_fields; a check that every
 * acceleration is finite (MF_ERR_NUMERIC, `unstable (nonFinite)`, naming
 * the force and the particle); the fault-injection point; the forces' time;
 * and the record of this step's accelerations that the run's watch reads
 * instead of a second pass (the ForceAcceleration field, not written to
 * snapshots, and the power sum m a.u at the state the forces saw). A solver
 * calls it once per step, in its explicit phase. */
int mf_force_accumulate(mf_sim *sim, double *acc);
/* The smallest stable step of the forces (INFINITY: none limits it) and the
 * name of the force that sets it (NULL: none). */
int mf_forces_stable_dt(const mf_sim *sim, double *dt, const char **who);
/* The smallest stable step of the solver and the forces, for the time loop;
 * *who names the module that sets it (NULL: none limits it). */
int mf_stable_dt(const mf_module *solver, const mf_sim *sim, double *dt, const char **who);
/* A solver that holds free-surface pressures claims them (true: some force
 * has one; see mf_force_ops.claim_surface_pressure), and each step, after
 * mf_force_accumulate and once the free surface is known, gets p[i] (one
 * entry per particle: the forces' pressure where dirichlet[i] is set, 0
 * elsewhere). */
bool mf_forces_claim_surface_pressure(mf_sim *sim);
int mf_forces_surface_pressure(const mf_sim *sim, const uint8_t *dirichlet, double *p);

/* One linear solve with pressure module m (a created mf_module of kind
 * pressure): A x = b, x the initial guess on entry. Prints OpenFOAM's line
 * `NAME:  Solving for FIELD, Initial residual = r0, Final residual = r, No
 * Iterations N`, adds the call's time to m->seconds, checks that x came
 * back finite (MF_ERR_NUMERIC otherwise), passes the fault-injection point.
 * MF_RETRY (not converged) is returned as the module returned it, with rep
 * filled, for the caller to name what it was solving. */
int mf_pressure_solve(mf_module *m, const mf_sim *sim, const char *field, const mf_csr *A,
                      const double *b, double *x, mf_solve_report *rep);
/* The same with the rows named (rows may be NULL: as mf_pressure_solve). */
int mf_pressure_solve_rows(mf_module *m, const mf_sim *sim, const char *field, const mf_csr *A,
                           const mf_row_names *rows, const double *b, double *x,
                           mf_solve_report *rep);

/* One step of the solver module: the time, the fault-injection point. */
int mf_solver_step(mf_module *solver, mf_sim *sim, double dt);

#pragma GCC visibility pop
#endif
