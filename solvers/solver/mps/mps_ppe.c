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

#include "mf_error.h"
#include "mf_hash.h"
#include "mf_run.h"
#include "mps.h"

static int reserve_system(mps_data *d, size_t rows, size_t nnz)
{
    if (rows + 1 > d->cap_rows) {
        size_t cap = rows + rows / 4 + 64;
        d->A.rowptr = realloc(d->A.rowptr, (cap + 1) * sizeof *d->A.rowptr);
        d->rhs = realloc(d->rhs, cap * sizeof *d->rhs);
        d->x = realloc(d->x, cap * sizeof *d->x);
        if (!d->A.rowptr || !d->rhs || !d->x)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu pressure unknowns", rows);
        d->cap_rows = cap;
    }
    if (nnz > d->cap_nnz) {
        size_t cap = nnz + nnz / 4 + 64;
        d->A.col = realloc(d->A.col, cap * sizeof *d->A.col);
        d->A.val = realloc(d->A.val, cap * sizeof *d->A.val);
        if (!d->A.col || !d->A.val)
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

int mps_assemble_ppe(mps_data *d, const mf_sim *sim, double dt)
{
    double t0 = mf_wall_seconds();
    const mf_particles *p = sim->p;
    const mf_nlist *nl = d->k_lap.re >= d->nl_max.radius ? &d->nl_max : &d->nl_lap;
    const double *n = mf_particles_fd(p, d->f_number_density);
    size_t nrows = 0, nnz = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        d->row[i] = d->in_ppe[i] ? (long)nrows++ : -1;
        if (d->in_ppe[i]) {
            nnz++;
            for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++)
                nnz += d->in_ppe[nl->j[k]];
        }
    }
    if (d->periodic) /* an image is its owner's unknown */
        mps_periodic_sync(d, p, d->row, sizeof *d->row);
    MF_CALL(reserve_system(d, nrows, nnz));
    uint8_t *touches = calloc(nrows ? nrows : 1, 1);
    if (!touches)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    mf_csr *A = &d->A;
    A->nrows = nrows;
    A->row_offset = p->global_offset;
    A->nglobal = (int64_t)nrows; /* one rank */
    const double c = 2.0 * d->k_lap.dim / (d->k_lap.lambda * d->k_lap.n0);
    const double rho = sim->fluid[0].rho, n0 = d->k_nd.n0, re = nl->radius;
    const double *rho_p = d->rho, *pd = d->p_dirichlet;
    const int avg = d->rho_average;
    const double *pressure = mf_particles_fd(p, d->f_pressure);
    size_t pos = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->in_ppe[i])
            continue;
        size_t r = (size_t)d->row[i];
        A->rowptr[r] = pos;
        size_t diag = pos++;
        A->col[diag] = A->row_offset + (int64_t)r;
        double sum = 0, known = 0;
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            size_t j = nl->j[k];
            if (!d->not_dummy[j])
                continue;
            double dx = p->pos[3 * j] - p->pos[3 * i], dy = p->pos[3 * j + 1] - p->pos[3 * i + 1],
                   dz = p->pos[3 * j + 2] - p->pos[3 * i + 2];
            double w = mf_weight(sqrt(dx * dx + dy * dy + dz * dz), re);
            double cw = c * w;
            if (rho_p)
                cw *= mps_inv_rho_pair(rho_p[i], rho_p[j], avg);
            sum += cw;
            if (d->in_ppe[j]) {
                A->col[pos] = A->row_offset + d->row[j];
                A->val[pos++] = -cw;
            } else if (w > 0) {
                touches[r] = 1; /* a Dirichlet neighbour */
                if (pd)
                    known += cw * pd[j];
            }
        }
        if (!(sum > 0) && d->is_fluid[i]) {
            /* n* counts dummy particles, the Laplacian does not: a fluid
             * particle with only dummies within re is inside a wall, and its
             * row would be zero (BoomerAMG stops on the singular system).
             * Seen on a mesh wall, which the run's watch does not check. */
            int rc = MF_ERROR(MF_ERR_NUMERIC,
                              "unstable (throughWall) at time %g, step %ld: fluid particle id "
                              "%lld at (%g %g %g) has only dummy particles within re: it is "
                              "inside a wall",
                              sim->time, sim->step, (long long)p->id[i], p->pos[3 * i],
                              p->pos[3 * i + 1], p->pos[3 * i + 2]);
            free(touches);
            return rc;
        }
        /* n* - n0, or against a per-particle reference (mps_data.n_offset) */
        const double dn = d->n_offset ? n[i] - n0 - d->n_offset[i] : n[i] - n0;
        if (rho_p) {
            A->val[diag] = sum + d->s.compressibility / (dt * dt);
            d->rhs[r] = d->s.relaxation / (dt * dt) * dn / n0;
        } else {
            A->val[diag] = sum + d->s.compressibility * rho / (dt * dt);
            d->rhs[r] = d->s.relaxation * rho / (dt * dt) * dn / n0;
        }
        if (pd)
            d->rhs[r] += known;
        if (!(sum > 0) && d->s.compressibility <= 0) {
            /* A wall particle with only dummies within re: no equation
             * couples it, so it takes p = 0 (a zero row is singular). */
            A->val[diag] = c;
            d->rhs[r] = 0;
            touches[r] = 1;
        }
        if (d->s.compressibility > 0)
            touches[r] = 1;
        d->x[r] = pressure[i]; /* warm start from the last step */
    }
    A->rowptr[nrows] = pos;
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

/* The rows' names for the pressure module (mf_rows): slot = the particle's
 * rank among the non-dummy particles (the PPE's possible unknowns), the
 * epoch a fingerprint of which particles those are, in which order, and of
 * what is solved for (multiFluid's two-step solve alternates two equations
 * on one module: each its own epoch) and of the snapshots written (see
 * mf_sim.snapshot_epoch). A module may then keep its
 * preconditioner from step to step while the free surface and the neighbour
 * pairs change (pcg_boomeramg.c). */
static int name_rows(mps_data *d, const mf_sim *sim, mf_rows *rows)
{
    const mf_particles *p = sim->p;
    if (d->A.nrows > d->cap_slot) {
        size_t cap = d->A.nrows + d->A.nrows / 4 + 64;
        int64_t *grown = realloc(d->slot, cap * sizeof *grown);
        if (!grown)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu pressure unknowns", cap);
        d->slot = grown;
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
    *rows = (mf_rows){d->slot, k, h};
    return 0;
}

int mps_solve_ppe(mps_data *d, mf_sim *sim)
{
    double t0 = mf_wall_seconds();
    mf_particles *p = sim->p;
    mf_rows rows;
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
