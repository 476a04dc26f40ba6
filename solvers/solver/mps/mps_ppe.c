/* mps_ppe.c: the pressure Poisson equation (eq. 14) and its solve.
 *
 * Unknowns: fluid and wall particles that are not on the free surface.
 * Surface particles are Dirichlet p = 0 (eq. 18); dummy particles take part
 * only in the number density. With the sign flipped, -<lap p> = rhs is
 * symmetric positive definite:
 *   A_ii = c sum_j w_ij (j fluid or wall),  A_ij = -c w_ij (j unknown),
 *   c = 2d / (lambda n0),  rhs_i = relaxation (rho/dt^2) (n*_i - n0)/n0.
 * A group of unknowns with no Dirichlet neighbour anywhere (a closed box
 * filled to the lid) makes A singular; its diagonal is doubled there, as the
 * Koshizuka lab's codes do, and the log says so at verbose level.
 *
 * With a density per particle (mps_data.rho, the multi-fluid solver) the
 * equation is div((1/rho) grad p) = (1/dt^2)(n* - n0)/n0, discretised as
 *   A_ii = c sum_j w_ij / rho_ij,  A_ij = -c w_ij / rho_ij,
 *   rhs_i = relaxation (1/dt^2) (n*_i - n0)/n0,
 * still symmetric since 1/rho_ij is a symmetric pair average
 * (mps_inv_rho_pair). Non-unknown neighbours with a given pressure
 * (mps_data.p_dirichlet: the light fluid's pressure held on the heavy fluid's
 * interface) move c w_ij p_j / rho_ij to the right-hand side.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_hash.h"
#include "mf_run.h"
#include "mps.h"

/* Room for rows unknowns and nnz entries; 1/16 headroom (the counts drift
 * little from step to step, and the matrix is the largest array of a run). */
static int reserve_system(mps_data *d, size_t rows, size_t nnz)
{
    if (rows + 1 > d->cap_rows) {
        size_t cap = rows + rows / 16 + 64;
        if (mf_resize(&d->A.rowptr, cap + 1, sizeof *d->A.rowptr) ||
            mf_resize(&d->rhs, cap, sizeof *d->rhs) || mf_resize(&d->x, cap, sizeof *d->x))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu pressure unknowns", rows);
        d->cap_rows = cap;
    }
    if (nnz > d->cap_nnz) {
        size_t cap = nnz + nnz / 16 + 64;
        if (mf_resize(&d->A.col, cap, sizeof *d->A.col) ||
            mf_resize(&d->A.val, cap, sizeof *d->A.val))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu matrix entries", nnz);
        d->cap_nnz = cap;
    }
    return 0;
}

/* Rows reachable from a row that touches a Dirichlet particle are fine;
 * the rest form closed groups. Breadth-first over the matrix graph. */
static size_t regularise_closed_groups(mps_data *d, const uint8_t *touches_dirichlet)
{
    const size_t nrows = d->A.nrows;
    uint8_t *seen = calloc(nrows ? nrows : 1, 1);
    size_t *queue = malloc((nrows ? nrows : 1) * sizeof *queue);
    if (!seen || !queue) {
        free(seen);
        free(queue);
        return 0;
    }
    size_t head = 0, tail = 0;
    for (size_t r = 0; r < nrows; r++)
        if (touches_dirichlet[r]) {
            seen[r] = 1;
            queue[tail++] = r;
        }
    while (head < tail) {
        size_t r = queue[head++];
        for (size_t k = d->A.rowptr[r]; k < d->A.rowptr[r + 1]; k++) {
            size_t c = (size_t)(d->A.col[k] - d->A.row_offset);
            if (c < nrows && !seen[c]) {
                seen[c] = 1;
                queue[tail++] = c;
            }
        }
    }
    size_t fixed = 0;
    for (size_t r = 0; r < nrows; r++)
        if (!seen[r]) {
            /* The diagonal entry is stored first in each row. */
            d->A.val[d->A.rowptr[r]] *= 2.0;
            fixed++;
        }
    free(seen);
    free(queue);
    return fixed;
}

/* One PPE row (the header's A_ii, A_ij, rhs_i) from the pair engine's
 * assemble sink: the coefficient kernel is c w_ij (1/rho_ij), a Dirichlet
 * neighbour's known pressure goes to the right-hand side. */
typedef struct ppe_ctx {
    mps_data *d;
    const mf_sim *sim;
    mf_pairs v;
    mf_rows rows;
    double c, dt, rho, n0, re;
    const double *rho_p, *pd, *n, *pressure;
    const double *src; /* the scheme's source (mps_source.c), NULL: eq. 14 */
    bool hl;           /* the higher-order Laplacian's weight (Khayyer & Gotoh 2010) */
    bool walls_push;   /* wall unknowns' sources clipped at zero */
    int dim;
    int avg;
    uint8_t *touches;
} ppe_ctx;

typedef struct ppe_acc {
    double known;   /* sum of c w_ij p_j / rho_ij over the Dirichlet neighbours */
    bool touches;   /* a Dirichlet neighbour with w > 0 */
} ppe_acc;

static inline double ppe_coef(const void *ctx, const mf_pair *pr)
{
    const ppe_ctx *c = ctx;
    double cw = c->hl ? c->c * mf_weight_hl(pr->len, c->re, c->dim)
                      : c->c * mf_weight(pr->len, c->re);
    if (c->rho_p)
        cw *= mf_inv_rho_pair(c->rho_p[pr->i], c->rho_p[pr->j], c->avg);
    return cw;
}

static inline void ppe_known(void *acc, const void *ctx, const mf_pair *pr, double a)
{
    const ppe_ctx *c = ctx;
    ppe_acc *k = acc;
    if (mf_weight(pr->len, c->re) > 0) {
        k->touches = true;
        if (c->pd)
            k->known += a * c->pd[pr->j];
    }
}

/* false: a fluid particle with no non-dummy neighbour (reported by the caller). */
static bool ppe_row(const void *ctx, size_t i, size_t r)
{
    const ppe_ctx *c = ctx;
    mps_data *d = c->d;
    ppe_acc acc = {0.0, false};
    const size_t diag = c->rows.rowptr[r];
    const double sum = mf_pairs_row_assemble(&c->v, i, d->not_dummy, NULL, ppe_coef, ppe_known,
                                             c, &acc, &c->rows, r);
    if (!(sum > 0) && d->is_fluid[i])
        return false;
    const double dt2 = c->dt * c->dt;
    /* n* - n0, or against a per-particle reference (mps_data.n_offset) */
    const double dn = d->n_offset ? c->n[i] - c->n0 - d->n_offset[i] : c->n[i] - c->n0;
    double *val = d->A.val;
    if (c->rho_p) {
        val[diag] = sum + d->s.compressibility / dt2;
        d->rhs[r] = c->src ? c->src[i] : d->s.relaxation / dt2 * dn / c->n0;
    } else {
        val[diag] = sum + d->s.compressibility * c->rho / dt2;
        d->rhs[r] = c->src ? c->rho * c->src[i] : d->s.relaxation * c->rho / dt2 * dn / c->n0;
    }
    if (c->walls_push && !d->is_fluid[i] && d->rhs[r] < 0)
        d->rhs[r] = 0; /* surfaceDetection asymmetry: a wall pushes, never pulls */
    if (c->pd)
        d->rhs[r] += acc.known;
    c->touches[r] = acc.touches;
    if (!(sum > 0) && d->s.compressibility <= 0) {
        /* A wall particle with only dummies within re: no equation
         * couples it, so it takes p = 0 (a zero row is singular). */
        val[diag] = c->c;
        d->rhs[r] = 0;
        c->touches[r] = 1;
    }
    if (d->s.compressibility > 0)
        c->touches[r] = 1;
    d->x[r] = c->pressure[i]; /* warm start from the last step */
    return true;
}

static size_t ppe_count(const void *ctx, size_t i)
{
    const ppe_ctx *c = ctx;
    return mf_pairs_row_count(&c->v, i, c->d->not_dummy, NULL, c, c->rows.col_of);
}

/* Between the count and the fill: room for the entries. */
static int ppe_sized(void *ctx, size_t nnz)
{
    ppe_ctx *c = ctx;
    MF_CALL(reserve_system(c->d, c->d->A.nrows, nnz));
    c->rows.col = c->d->A.col;
    c->rows.val = c->d->A.val;
    c->rows.rowptr = c->d->A.rowptr;
    return 0;
}

int mps_assemble_ppe(mps_data *d, const mf_sim *sim, double dt)
{
    double t0 = mf_wall_seconds();
    const mf_particles *p = sim->p;
    size_t nrows = 0;
    for (size_t i = 0; i < p->n_owned; i++)
        d->row[i] = d->in_ppe[i] ? (long)nrows++ : -1;
    if (d->periodic) /* an image is its owner's unknown */
        mps_periodic_sync(d, p, d->row, sizeof *d->row);
    if (p->global_offset + (int64_t)nrows > MF_CSR_MAX_GLOBAL)
        return MF_ERROR(MF_ERR_INPUT,
                        "%zu pressure unknowns: the matrix's columns are 32-bit (hypre's "
                        "HYPRE_BigInt), at most %d in all",
                        nrows, MF_CSR_MAX_GLOBAL);
    MF_CALL(reserve_system(d, nrows, 0));
    uint8_t *touches = calloc(nrows ? nrows : 1, 1);
    if (!touches)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    mf_csr *A = &d->A;
    A->nrows = nrows;
    A->row_offset = p->global_offset;
    A->nglobal = (int64_t)nrows; /* one rank */
    ppe_ctx c = {
        .d = d,
        .sim = sim,
        .rows = {d->row, A->row_offset, A->rowptr, A->col, A->val},
        .c = 2.0 * d->k_lap.dim / (d->k_lap.lambda * d->k_lap.n0),
        .dt = dt,
        .rho = sim->fluid[0].rho,
        .n0 = d->k_nd.n0,
        .rho_p = d->rho,
        .pd = d->p_dirichlet,
        .n = mf_particles_fd(p, d->f_number_density),
        .pressure = mf_particles_fd(p, d->f_pressure),
        .avg = d->rho_average,
        .touches = touches,
        .dim = d->k_lap.dim,
        .walls_push = d->sc.detection == MPS_DETECT_ASYMMETRY,
    };
    /* The scheme's source and Laplacian (a composing solver's per-particle
     * density reference, MAFL's densityReference, keeps eq. 14's source). */
    int rc = d->n_offset ? 0 : mps_source_terms(d, sim, dt);
    if (rc == 0 && d->sc.source != MPS_SOURCE_DENSITY && !d->n_offset)
        c.src = d->src;
    if (d->sc.laplacian != MPS_LAPLACIAN_PAPER) { /* higherOrder, and leastSquares' PPE */
        c.hl = true;
        c.c = d->k_lap.hl_coef;
    }
    if (rc == 0)
        rc = mps_pairs(d, sim, d->h_lap, &c.v);
    c.re = c.v.radius;
    size_t failed = SIZE_MAX;
    if (rc == 0)
        rc = mf_pairs_assemble(&c.v, d->row, A->rowptr, nrows, ppe_count, ppe_sized, ppe_row, &c,
                               &failed);
    if (rc == 0 && failed != SIZE_MAX) {
        /* n* counts dummy particles, the Laplacian does not: a fluid
         * particle with only dummies within re is inside a wall, and its
         * row would be zero (BoomerAMG stops on the singular system).
         * Seen on a mesh wall, which the run's watch does not check. */
        const size_t i = failed;
        rc = MF_ERROR(MF_ERR_NUMERIC,
                      "unstable (throughWall) at time %g, step %ld: fluid particle id "
                      "%lld at (%g %g %g) has only dummy particles within re: it is "
                      "inside a wall",
                      sim->time, sim->step, (long long)p->id[i], p->pos[3 * i],
                      p->pos[3 * i + 1], p->pos[3 * i + 2]);
    }
    if (rc != 0) {
        free(touches);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    size_t closed = regularise_closed_groups(d, touches);
    free(touches);
    if (closed)
        mf_log_printf(sim->log, MF_LOG_VERBOSE,
                      "PPE: %zu unknowns have no free surface to refer to: diagonal doubled\n",
                      closed);
    d->ppe_rows = (long)nrows;
    d->t_assembly += mf_wall_seconds() - t0;
    return 0;
}

/* The pressure solve did not converge (MF_RETRY from the pressure module):
 * name it as the run's watch names its criteria (pressureSolve), with the
 * time, the residuals and the particle of the largest residual, so that a
 * run stopped by it says where. Stays MF_RETRY: a smaller step may fix it. */
static int solve_failed(const mps_data *d, const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    const mf_csr *A = &d->A;
    size_t worst = 0;
    double rmax = -1;
    for (size_t r = 0; r < A->nrows; r++) {
        double res = d->rhs[r];
        for (size_t k = A->rowptr[r]; k < A->rowptr[r + 1]; k++)
            res -= A->val[k] * d->x[A->col[k] - A->row_offset];
        if (!(fabs(res) <= rmax)) {
            rmax = fabs(res);
            worst = r;
        }
    }
    size_t i = 0;
    while (i < p->n_owned && d->row[i] != (long)worst)
        i++;
    const char *why = d->last.final_residual > d->last.initial_residual ||
                              !isfinite(d->last.final_residual)
                          ? ", diverging"
                          : "";
    if (i == p->n_owned)
        return MF_ERROR(MF_RETRY,
                        "unstable (pressureSolve) at time %g, step %ld: %s not converged after "
                        "%d iterations (relative residual %g, from %g%s)",
                        sim->time + sim->dt, sim->step + 1, d->pressure.info->name,
                        d->last.iterations, d->last.final_residual, d->last.initial_residual,
                        why);
    const double *x = &p->pos[3 * i];
    return MF_ERROR(MF_RETRY,
                    "unstable (pressureSolve) at time %g, step %ld: %s not converged after %d "
                    "iterations (relative residual %g, from %g%s); largest residual at %s "
                    "particle id %lld at (%g %g %g)",
                    sim->time + sim->dt, sim->step + 1, d->pressure.info->name,
                    d->last.iterations, d->last.final_residual, d->last.initial_residual, why,
                    mf_particle_kind_name(p->kind[i]), (long long)p->id[i], x[0], x[1], x[2]);
}

/* The rows' names for the pressure module (mf_row_names): slot = the particle's
 * rank among the non-dummy particles (the PPE's possible unknowns), the
 * epoch a fingerprint of which particles those are, in which order, and of
 * what is solved for (multiFluid's two-step solve alternates two equations
 * on one module: each its own epoch) and of the snapshots written (see
 * mf_sim.snapshot_epoch). A module may then keep its
 * preconditioner from step to step while the free surface and the neighbour
 * pairs change (pcg_boomeramg.c). */
static int name_rows(mps_data *d, const mf_sim *sim, mf_row_names *rows)
{
    const mf_particles *p = sim->p;
    if (d->A.nrows > d->cap_slot) {
        size_t cap = d->A.nrows + d->A.nrows / 4 + 64;
        if (mf_resize(&d->slot, cap, sizeof *d->slot))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu pressure unknowns", cap);
        d->cap_slot = cap;
    }
    uint64_t h = mf_hash_word(MF_HASH_START, p->n_owned);
    h = mf_hash_word(h, (uint64_t)sim->snapshot_epoch); /* restarts repeat runs exactly */
    for (const char *c = d->solve_name; c && *c; c++)
        h = mf_hash_word(h, (uint64_t)(unsigned char)*c);
    int64_t k = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->not_dummy[i])
            continue;
        h = mf_hash_word(h, (uint64_t)p->id[i]);
        if (d->row[i] >= 0)
            d->slot[d->row[i]] = k;
        k++;
    }
    *rows = (mf_row_names){d->slot, k, h};
    return 0;
}

int mps_solve_ppe(mps_data *d, mf_sim *sim)
{
    double t0 = mf_wall_seconds();
    mf_particles *p = sim->p;
    mf_row_names rows;
    MF_CALL(name_rows(d, sim, &rows));
    int rc = mf_pressure_solve_rows(&d->pressure, sim, d->solve_name ? d->solve_name : "p",
                                    &d->A, &rows, d->rhs, d->x, &d->last);
    sim->pressure_iterations += d->last.iterations;
    d->solves++;
    d->t_setup += d->last.setup_seconds;
    d->t_pcg += d->last.solve_seconds;
    d->t_solve += mf_wall_seconds() - t0;
    if (rc == MF_RETRY)
        return solve_failed(d, sim);
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    double *pressure = mf_particles_fd(p, d->f_pressure);
    for (size_t i = 0; i < p->n_owned; i++) {
        double v = d->row[i] >= 0 ? d->x[d->row[i]] : (d->p_dirichlet ? d->p_dirichlet[i] : 0.0);
        pressure[i] = (d->s.clip_negative_pressure && v < 0) ? 0.0 : v;
    }
    if (d->periodic)
        mps_periodic_sync(d, p, pressure, sizeof *pressure);
    return 0;
}
