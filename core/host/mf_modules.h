/* mf_modules.h: the kind-specific ops tables. Each starts with the common
 * mf_module_info header (so the registry can hold any of them), then the
 * slots of its kind. Required slots are listed first; optional ones may be
 * NULL. Tables only grow at the end (MF_ABI_VERSION says which layout).
 *
 * Naming (PETSc's habit): a module `foo` of kind `bar` implements
 * foo_create, foo_<verb>, foo_destroy as static functions in
 * solvers/<bar>/foo.c (or plugins/foo/) and exports one const table.
 */
#ifndef MF_MODULES_H
#define MF_MODULES_H

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
 * system has fewer than 2^31 unknowns in all. */
typedef struct mf_csr {
    size_t nrows;
    int64_t row_offset;
    int64_t nglobal;
    size_t *rowptr;   /* nrows + 1 */
    int32_t *col;     /* rowptr[nrows] */
    double *val;      /* rowptr[nrows] */
} mf_csr;
#define MF_CSR_MAX_GLOBAL INT32_MAX

typedef struct mf_solve_report {
    int iterations;
    double initial_residual; /* ||b - A x0|| / ||b|| */
    double final_residual;   /* ||b - A x|| / ||b|| */
    bool converged;
    double setup_seconds, solve_seconds;
} mf_solve_report;

typedef struct mf_pressure_ops {
    mf_module_info info;
    int (*create)(const void *settings, void **data);
    /* x holds the initial guess on entry and the solution on return.
     * MF_RETRY when not converged within the iteration limit. */
    int (*solve)(void *data, const mf_csr *A, const double *b, double *x, mf_solve_report *rep);
    void (*destroy)(void *data);
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
typedef struct mf_force_ops {
    mf_module_info info;
    int (*create)(const void *settings, mf_sim *sim, void **data);
    /* acc has 3 * sim->p->n entries; add this force's acceleration (m/s^2). */
    int (*accumulate)(void *data, const mf_sim *sim, double *acc);
    void (*destroy)(void *data);
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
    /* Optional (purgeWrite): delete the snapshots this writer wrote but the
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

#endif
