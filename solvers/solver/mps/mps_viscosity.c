/* mps_viscosity.c: implicit viscosity for the MPS explicit phase.
 *
 * The explicit viscous term (eq. 9 with eq. 7) is stable only for
 * nu dt / l0^2 below about 0.1 (maxDi): at high viscosity that limit is the
 * stiff one. `viscosity implicit;` solves instead, per velocity component,
 *
 *   u*_i - dt nu <lap u*>_i = u^n_i + dt a_i        (a: the force modules)
 *
 * with the eq. 7 Laplacian: <lap u>_i = c sum_j (u_j - u_i) w_ij,
 * c = 2d/(lambda n0). Rows are the fluid particles; a wall or dummy neighbour
 * is a Dirichlet value (its velocity, as the explicit term reads it); a
 * free-surface particle keeps its row, its missing neighbours simply absent
 * (the explicit term does the same). The matrix
 *   A_ii = 1 + dt nu c sum_j w_ij,  A_ij = -dt nu c w_ij  (j fluid)
 * is symmetric and strictly diagonally dominant, hence SPD: a linear-solver
 * module (kind pressure) named by solverDict's `viscosity { solver NAME; }`
 * like the pressure's, PCG_BoomerAMG by default (a second instance).
 * With a viscosity per particle (mps_data.mu, multi-fluid, eq. 27) row i is
 * multiplied by rho_i: A_ii = rho_i + dt c sum_j mu_ij w_ij, A_ij = -dt c
 * mu_ij w_ij, which keeps it symmetric since mu_ij is a symmetric average.
 * Copies (periodic images, other ranks' particles: mps_halo.c) map to their
 * owner's row.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_run.h"
#include "mps.h"

typedef struct mps_viscosity {
    mf_module solver; /* a linear-solver module of its own (solverDict `viscosity`) */
    const mf_pressure_ops *ops;
    mf_csr A;
    double *b, *x;
    long *row; /* particle -> row, -1: not an unknown */
    long *row_global; /* on several ranks: particle -> global row (copies: their owners') */
    size_t cap_p, cap_rows, cap_nnz;
    long solves, iterations;
    double seconds;
} mps_viscosity;

int mps_viscosity_create(mps_data *d, mf_sim *sim, const mf_dict *solver_dict)
{
    mps_viscosity *v = calloc(1, sizeof *v);
    if (!v)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->visc = v;
    /* Defaults where the case is silent: a tighter tolerance than the
     * pressure's (the solve is cheap, a few iterations), and one AMG set-up
     * for the dim components, which share the matrix. */
    const mps_default defaults[] = {{"tolerance", 1e-10}, {"reuseSetup", sim->dim - 1}};
    double tolerance = NAN;
    MF_CALL(mps_create_solve(sim, solver_dict, "viscosity", defaults, 2, &v->solver, &tolerance));
    v->ops = (const mf_pressure_ops *)v->solver.info;
    /* The viscous limit of the time step does not apply any more. */
    sim->viscosity_implicit = true;
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "Viscosity: implicit (%s, tolerance %g); no viscous time-step limit\n",
                  v->solver.info->name, tolerance);
    return 0;
}

void mps_viscosity_destroy(mps_viscosity *v)
{
    if (!v)
        return;
    if (v->ops && v->solver.data)
        v->ops->destroy(v->solver.data);
    mf_module_release(&v->solver);
    free(v->A.rowptr);
    free(v->A.col);
    free(v->A.val);
    free(v->b);
    free(v->x);
    free(v->row);
    free(v->row_global);
    free(v);
}

static int reserve(mps_viscosity *v, size_t np, size_t rows, size_t nnz)
{
    if (np > v->cap_p) {
        size_t cap = np + np / 4 + 64;
        if (mf_resize(&v->row, cap, sizeof *v->row) ||
            mf_resize(&v->row_global, cap, sizeof *v->row_global))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particles", np);
        v->cap_p = cap;
    }
    if (rows + 1 > v->cap_rows) {
        size_t cap = rows + rows / 4 + 64;
        if (mf_resize(&v->A.rowptr, cap + 1, sizeof *v->A.rowptr) ||
            mf_resize(&v->b, cap, sizeof *v->b) || mf_resize(&v->x, cap, sizeof *v->x))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu viscous unknowns", rows);
        v->cap_rows = cap;
    }
    if (nnz > v->cap_nnz) {
        size_t cap = nnz + nnz / 16 + 64;
        if (mf_resize(&v->A.col, cap, sizeof *v->A.col) ||
            mf_resize(&v->A.val, cap, sizeof *v->A.val))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu matrix entries", nnz);
        v->cap_nnz = cap;
    }
    return 0;
}

/* One row of the matrix (the header's A_ii, A_ij) from the pair engine's
 * assemble sink: the coefficient kernel is dt c mu_ij w_ij (mu_ij = nu with
 * one fluid); a wall or dummy neighbour's velocity is a known value. */
typedef struct visc_ctx {
    const mps_data *d;
    mf_pairs v;
    mf_rows rows;
    const double *vel;
    double nu, dtc, re;
    double *dirichlet; /* 3 per row: sum of dt c mu_ij w_ij u_j over the known j */
} visc_ctx;

static inline bool visc_takes_part(const void *ctx, const mf_pair *pr)
{
    const visc_ctx *c = ctx;
    return mf_weight(pr->len, c->re) > 0.0;
}

static inline double visc_coef(const void *ctx, const mf_pair *pr)
{
    const visc_ctx *c = ctx;
    const mps_data *d = c->d;
    const double w = mf_weight(pr->len, c->re);
    if (!d->mu)
        return c->dtc * c->nu * w;
    const size_t i = pr->i, j = pr->j;
    const double mu_ij = d->is_fluid[j] ? mf_mu_pair(d->mu[i], d->mu[j], d->mu_average) : d->mu[i];
    return c->dtc * mu_ij * w;
}

static inline void visc_known(void *acc, const void *ctx, const mf_pair *pr, double a)
{
    const visc_ctx *c = ctx;
    double *known = acc;
    for (int q = 0; q < 3; q++)
        known[q] += a * c->vel[3 * pr->j + q];
}

static size_t visc_row(const void *ctx, size_t i, size_t r)
{
    const visc_ctx *c = ctx;
    const mps_data *d = c->d;
    double known[3] = {0.0, 0.0, 0.0};
    size_t entries = 0;
    const double sum = mf_pairs_row_assemble(&c->v, i, NULL, visc_takes_part, visc_coef,
                                             visc_known, c, known, &c->rows, r, &entries);
    d->visc->A.val[c->rows.rowptr[r]] = (d->rho ? d->rho[i] : 1.0) + sum;
    memcpy(&c->dirichlet[3 * r], known, sizeof known);
    return entries;
}

static int visc_sized(void *ctx, size_t nnz)
{
    visc_ctx *c = ctx;
    mps_viscosity *v = c->d->visc;
    MF_CALL(reserve(v, 0, v->A.nrows, nnz));
    c->rows.rowptr = v->A.rowptr;
    c->rows.col = v->A.col;
    c->rows.val = v->A.val;
    return 0;
}

/* Matrix of the fluid rows and, in dirichlet (3 per row), the wall
 * contributions dt c mu_ij w_ij u_j. */
static int assemble(mps_data *d, const mf_sim *sim, double dt, double *dirichlet,
                    const long *global_col)
{
    mps_viscosity *v = d->visc;
    mf_csr *A = &v->A;
    visc_ctx c = {
        .d = d,
        .rows = {v->row, A->row_offset, A->rowptr, A->col, A->val, global_col},
        .vel = sim->p->vel,
        .nu = sim->fluid[0].nu,
        .dtc = dt * 2.0 * d->k_lap.dim / (d->k_lap.lambda * d->k_lap.n0),
        .dirichlet = dirichlet,
    };
    MF_CALL(mps_pairs(d, sim, d->h_lap, &c.v));
    c.re = c.v.radius;
    size_t failed;
    MF_CALL(mf_pairs_assemble(&c.v, &c.rows, A->nrows, visc_sized, visc_row, &c, &failed));
    return 0;
}

int mps_viscosity_implicit(mps_data *d, mf_sim *sim, double dt)
{
    mps_viscosity *v = d->visc;
    mf_particles *p = sim->p;
    size_t rows = 0;
    MF_CALL(reserve(v, p->n, 0, 0));
    for (size_t i = 0; i < p->n_owned; i++)
        v->row[i] = d->is_fluid[i] ? (long)rows++ : -1;
    /* Rows over the ranks; copies (images, other ranks' particles) are their
     * owners' unknowns. */
    int64_t offset = 0, nglobal = 0;
    const long *global_col = NULL;
    MF_CALL(mps_global_rows(d, sim, v->row, rows, v->row_global, &offset, &nglobal,
                            &global_col));
    if (nglobal > MF_CSR_MAX_GLOBAL)
        return MF_ERROR(MF_ERR_INPUT,
                        "%lld viscous unknowns: the matrix's columns are 32-bit (hypre's "
                        "HYPRE_BigInt), at most %d in all",
                        (long long)nglobal, MF_CSR_MAX_GLOBAL);
    MF_CALL(reserve(v, p->n, rows, 0)); /* the entries: counted by assemble */
    v->A.nrows = rows;
    v->A.row_offset = offset;
    v->A.nglobal = nglobal;
    double *dirichlet = malloc(3 * (rows ? rows : 1) * sizeof *dirichlet);
    if (!dirichlet)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu viscous unknowns", rows);
    int rc = assemble(d, sim, dt, dirichlet, global_col);
    static const char *const names[3] = {"Ux", "Uy", "Uz"};
    const double t0 = mf_wall_seconds();
    for (int c = 0; rc == 0 && c < sim->dim; c++) {
        /* b = rho_i (u^n + dt a) + walls; the guess: u^n + dt a. */
        for (size_t i = 0; i < p->n_owned; i++) {
            long r = v->row[i];
            if (r < 0)
                continue;
            const double ut = p->vel[3 * i + c] + dt * d->acc[3 * i + c];
            v->x[r] = ut;
            v->b[r] = (d->rho ? d->rho[i] : 1.0) * ut + dirichlet[3 * r + c];
        }
        mf_solve_report rep;
        rc = mf_pressure_solve(&v->solver, sim, names[c], &v->A, v->b, v->x, &rep);
        v->solves++;
        v->iterations += rep.iterations;
        if (rc == 0)
            for (size_t i = 0; i < p->n_owned; i++)
                if (v->row[i] >= 0)
                    p->vel[3 * i + c] = v->x[v->row[i]];
    }
    v->seconds += mf_wall_seconds() - t0;
    free(dirichlet);
    for (int c = sim->dim; rc == 0 && c < 3; c++) /* z in 2-D: forces only */
        for (size_t i = 0; i < p->n_owned; i++)
            if (d->is_fluid[i])
                p->vel[3 * i + c] += dt * d->acc[3 * i + c];
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    /* The copies' velocities follow after the explicit phase (mps_step.c). */
    for (size_t i = 0; i < p->n_owned; i++)
        if (d->is_fluid[i])
            for (int c = 0; c < 3; c++)
                p->pos[3 * i + c] += dt * p->vel[3 * i + c];
    return 0;
}

void mps_viscosity_report(const mps_viscosity *v, const mf_sim *sim, mf_log *log)
{
    if (!v)
        return;
    (void)sim;
    mf_log_printf(log, MF_LOG_QUIET,
                  "MPS implicit viscosity: %ld solves, %.2f iterations per solve, %.3f s in "
                  "the solves\n",
                  v->solves, v->solves ? (double)v->iterations / (double)v->solves : 0.0,
                  v->seconds);
}
