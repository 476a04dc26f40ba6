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
 * is symmetric and strictly diagonally dominant, hence SPD: hypre PCG with
 * BoomerAMG (the pressure module PCG_BoomerAMG, a second instance of it).
 * With a viscosity per particle (mps_data.mu, multi-fluid, eq. 27) row i is
 * multiplied by rho_i: A_ii = rho_i + dt c sum_j mu_ij w_ij, A_ij = -dt c
 * mu_ij w_ij, which keeps it symmetric since mu_ij is a symmetric average.
 * Periodic images (mps_periodic.c) map to their owner's row.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_run.h"
#include "mps.h"
#include "pressure/pressure_hypre.h"

typedef struct mps_viscosity {
    mf_module solver; /* a PCG_BoomerAMG instance of its own */
    const mf_pressure_ops *ops;
    mf_csr A;
    double *b, *x;
    long *row; /* particle -> row, -1: not an unknown */
    size_t cap_p, cap_rows, cap_nnz;
    long solves, iterations;
    double seconds;
} mps_viscosity;

int mps_viscosity_create(mps_data *d, mf_sim *sim)
{
    mps_viscosity *v = calloc(1, sizeof *v);
    if (!v)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->visc = v;
    MF_CALL(mf_module_prepare(sim->reg, MF_KIND_PRESSURE, "PCG_BoomerAMG", NULL, NULL, NULL,
                              &v->solver));
    v->ops = (const mf_pressure_ops *)v->solver.info;
    mf_pcg_boomeramg_settings *s = v->solver.settings;
    s->tolerance = d->s.viscosity_tolerance;
    /* The components share one matrix: one AMG set-up serves them all. */
    s->reuse_setup = sim->dim - 1;
    MF_CALL(v->ops->create(v->solver.settings, &v->solver.data));
    /* The viscous limit of the time step does not apply any more. */
    sim->viscosity_implicit = true;
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "Viscosity: implicit (PCG_BoomerAMG, tolerance %g); no viscous time-step "
                  "limit\n",
                  s->tolerance);
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
    free(v);
}

static int reserve(mps_viscosity *v, size_t np, size_t rows, size_t nnz)
{
    if (np > v->cap_p) {
        size_t cap = np + np / 4 + 64;
        long *row = realloc(v->row, cap * sizeof *row);
        if (!row)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particles", np);
        v->row = row;
        v->cap_p = cap;
    }
    if (rows + 1 > v->cap_rows) {
        size_t cap = rows + rows / 4 + 64;
        size_t *rowptr = realloc(v->A.rowptr, (cap + 1) * sizeof *rowptr);
        if (rowptr)
            v->A.rowptr = rowptr;
        double *b = realloc(v->b, cap * sizeof *b);
        if (b)
            v->b = b;
        double *x = realloc(v->x, cap * sizeof *x);
        if (x)
            v->x = x;
        if (!rowptr || !b || !x)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu viscous unknowns", rows);
        v->cap_rows = cap;
    }
    if (nnz > v->cap_nnz) {
        size_t cap = nnz + nnz / 4 + 64;
        int64_t *col = realloc(v->A.col, cap * sizeof *col);
        if (col)
            v->A.col = col;
        double *val = realloc(v->A.val, cap * sizeof *val);
        if (val)
            v->A.val = val;
        if (!col || !val)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu matrix entries", nnz);
        v->cap_nnz = cap;
    }
    return 0;
}

/* The pair term of row i: dt c mu_ij w_ij (mu_ij = nu with one fluid). */
static inline double pair_coef(const mps_data *d, size_t i, size_t j, bool j_fluid, double nu,
                               double dtc, double w)
{
    if (!d->mu)
        return dtc * nu * w;
    const double mu_ij = j_fluid ? mps_mu_pair(d->mu[i], d->mu[j], d->mu_average) : d->mu[i];
    return dtc * mu_ij * w;
}

/* Matrix of the fluid rows and, in dirichlet (3 per row), the wall
 * contributions dt c mu_ij w_ij u_j. */
static int assemble(mps_data *d, const mf_sim *sim, double dt, double *dirichlet)
{
    mps_viscosity *v = d->visc;
    const mf_particles *p = sim->p;
    const mf_nlist *nl = d->k_lap.re >= d->nl_max.radius ? &d->nl_max : &d->nl_lap;
    const double re = nl->radius, nu = sim->fluid[0].nu;
    const double dtc = dt * 2.0 * d->k_lap.dim / (d->k_lap.lambda * d->k_lap.n0);
    mf_csr *A = &v->A;
    size_t pos = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->is_fluid[i])
            continue;
        size_t r = (size_t)(v->row[i] - A->row_offset);
        A->rowptr[r] = pos;
        size_t diag = pos++;
        A->col[diag] = v->row[i];
        double sum = 0.0, known[3] = {0.0, 0.0, 0.0};
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            size_t j = nl->j[k];
            double dx = p->pos[3 * j] - p->pos[3 * i], dy = p->pos[3 * j + 1] - p->pos[3 * i + 1],
                   dz = p->pos[3 * j + 2] - p->pos[3 * i + 2];
            double w = mf_weight(sqrt(dx * dx + dy * dy + dz * dz), re);
            if (w <= 0.0)
                continue;
            const bool fluid = d->is_fluid[j];
            double a = pair_coef(d, i, j, fluid, nu, dtc, w);
            sum += a;
            if (fluid) {
                A->col[pos] = v->row[j]; /* global: a copy holds its owner's */
                A->val[pos++] = -a;
            } else {
                for (int c = 0; c < 3; c++)
                    known[c] += a * p->vel[3 * j + c];
            }
        }
        A->val[diag] = (d->rho ? d->rho[i] : 1.0) + sum;
        memcpy(&dirichlet[3 * r], known, sizeof known);
    }
    A->rowptr[A->nrows] = pos;
    return 0;
}

int mps_viscosity_implicit(mps_data *d, mf_sim *sim, double dt)
{
    mps_viscosity *v = d->visc;
    mf_particles *p = sim->p;
    const mf_nlist *nl = d->k_lap.re >= d->nl_max.radius ? &d->nl_max : &d->nl_lap;
    size_t rows = 0, nnz = 0;
    MF_CALL(reserve(v, p->n, 0, 0));
    for (size_t i = 0; i < p->n_owned; i++) {
        v->row[i] = d->is_fluid[i] ? (long)rows++ : -1;
        if (d->is_fluid[i])
            nnz += 1 + (nl->start[i + 1] - nl->start[i]);
    }
    /* Global rows; copies (images, other ranks' particles) take their owners'. */
    int64_t offset = 0, nglobal = 0;
    MF_CALL(mps_global_rows(d, sim, v->row, rows, &offset, &nglobal));
    MF_CALL(reserve(v, p->n, rows, nnz));
    v->A.nrows = rows;
    v->A.row_offset = offset;
    v->A.nglobal = nglobal;
    double *dirichlet = malloc(3 * (rows ? rows : 1) * sizeof *dirichlet);
    if (!dirichlet)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu viscous unknowns", rows);
    int rc = assemble(d, sim, dt, dirichlet);
    static const char *const names[3] = {"Ux", "Uy", "Uz"};
    const double t0 = mf_wall_seconds();
    for (int c = 0; rc == 0 && c < sim->dim; c++) {
        /* b = rho_i (u^n + dt a) + walls; the guess: u^n + dt a. */
        for (size_t i = 0; i < p->n_owned; i++) {
            if (v->row[i] < 0)
                continue;
            const long r = v->row[i] - (long)offset;
            const double ut = p->vel[3 * i + c] + dt * d->acc[3 * i + c];
            v->x[r] = ut;
            v->b[r] = (d->rho ? d->rho[i] : 1.0) * ut + dirichlet[3 * r + c];
        }
        mf_solve_report rep;
        rc = v->ops->solve(v->solver.data, &v->A, v->b, v->x, &rep);
        mf_log_printf(sim->log, MF_LOG_STEP,
                      "%s:  Solving for %s, Initial residual = %g, Final residual = %g, No "
                      "Iterations %d\n",
                      v->solver.info->name, names[c], rep.initial_residual, rep.final_residual,
                      rep.iterations);
        v->solves++;
        v->iterations += rep.iterations;
        if (rc == 0)
            for (size_t i = 0; i < p->n_owned; i++)
                if (v->row[i] >= 0)
                    p->vel[3 * i + c] = v->x[v->row[i] - offset];
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
