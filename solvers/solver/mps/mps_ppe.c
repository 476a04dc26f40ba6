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
 * the rest form closed groups. Breadth-first over the matrix graph; on
 * several ranks in rounds: each rank searches its rows, the copies learn
 * whether their owners were reached, and a row next to a reached copy
 * starts the next round, until no rank reaches a new row. */
static int regularise_closed_groups(mps_data *d, const mf_sim *sim, const mf_nlist *nl,
                                    const uint8_t *touches_dirichlet, size_t *nfixed)
{
    const mf_particles *p = sim->p;
    const size_t nrows = d->A.nrows;
    const int64_t offset = d->A.row_offset;
    const bool across = sim->par != NULL;
    uint8_t *seen = calloc(nrows ? nrows : 1, 1);
    size_t *queue = malloc((nrows ? nrows : 1) * sizeof *queue);
    uint8_t *flag = across ? calloc(p->n ? p->n : 1, 1) : NULL;
    int rc = !seen || !queue || (across && !flag)
                 ? MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu pressure rows", nrows)
                 : 0;
    if (rc != 0 && !across)
        goto done;
    size_t head = 0, tail = 0;
    for (size_t r = 0; rc == 0 && r < nrows; r++)
        if (touches_dirichlet[r]) {
            seen[r] = 1;
            queue[tail++] = r;
        }
    for (int round = 0;; round++) {
        while (head < tail) {
            size_t r = queue[head++];
            for (size_t k = d->A.rowptr[r]; k < d->A.rowptr[r + 1]; k++) {
                size_t c = (size_t)(d->A.col[k] - offset);
                if (c < nrows && !seen[c]) {
                    seen[c] = 1;
                    queue[tail++] = c;
                }
            }
        }
        if (!across)
            break;
        if (round == 0) { /* the usual case: every row reached on every rank */
            double open[2] = {(double)(nrows - tail), rc != 0};
            if (rc != 0)
                open[0] = 0;
            mf_parallel_sum(sim->par, open, 2);
            if (open[1] > 0) {
                rc = mf_parallel_agree(sim->par, rc);
                goto done;
            }
            if (open[0] == 0)
                break;
        }
        for (size_t i = 0; i < p->n_owned; i++)
            flag[i] = d->row[i] >= 0 && seen[d->row[i] - offset];
        MF_CALL_GOTO(rc, mps_halo_sync(d, sim, flag, 1), done);
        double reached = 0;
        for (size_t i = 0; i < p->n_owned; i++) {
            if (d->row[i] < 0 || seen[d->row[i] - offset])
                continue;
            for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
                size_t j = nl->j[k];
                if (j >= p->n_owned && d->in_ppe[j] && flag[j]) {
                    seen[d->row[i] - offset] = 1;
                    queue[tail++] = (size_t)(d->row[i] - offset);
                    reached++;
                    break;
                }
            }
        }
        mf_parallel_sum(sim->par, &reached, 1);
        if (reached == 0)
            break;
    }
    size_t fixed = 0;
    for (size_t r = 0; r < nrows; r++)
        if (!seen[r]) {
            /* The diagonal entry is stored first in each row. */
            d->A.val[d->A.rowptr[r]] *= 2.0;
            fixed++;
        }
    *nfixed = fixed;
done:
    free(seen);
    free(queue);
    free(flag);
    return rc;
}

int mps_assemble_ppe(mps_data *d, const mf_sim *sim, double dt)
{
    double t0 = mf_wall_seconds();
    const mf_particles *p = sim->p;
    const mf_nlist *nl = d->k_lap.re >= d->nl_max.radius ? &d->nl_max : &d->nl_lap;
    const double *n = mf_particles_fd(p, d->f_number_density);
    /* Which copies are unknowns: their owners decided (a composing solver
     * may have changed the owned ones since the surface phase). */
    MF_CALL(mps_halo_sync(d, sim, d->in_ppe, 1));
    size_t nrows = 0, nnz = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        d->row[i] = d->in_ppe[i] ? (long)nrows++ : -1;
        if (d->in_ppe[i]) {
            nnz++;
            for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++)
                nnz += d->in_ppe[nl->j[k]];
        }
    }
    /* Global rows: a copy is its owner's unknown (an image, or a particle of
     * another rank). */
    int64_t offset = 0, nglobal = 0;
    MF_CALL(mps_global_rows(d, sim, d->row, nrows, &offset, &nglobal));
    MF_CALL(reserve_system(d, nrows, nnz));
    uint8_t *touches = calloc(nrows ? nrows : 1, 1);
    if (!touches)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    mf_csr *A = &d->A;
    A->nrows = nrows;
    A->row_offset = offset;
    A->nglobal = nglobal;
    const double c = 2.0 * d->k_lap.dim / (d->k_lap.lambda * d->k_lap.n0);
    const double rho = sim->fluid[0].rho, n0 = d->k_nd.n0, re = nl->radius;
    const double *rho_p = d->rho, *pd = d->p_dirichlet;
    const int avg = d->rho_average;
    const double *pressure = mf_particles_fd(p, d->f_pressure);
    size_t pos = 0;
    int wall_rc = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->in_ppe[i])
            continue;
        size_t r = (size_t)(d->row[i] - offset);
        A->rowptr[r] = pos;
        size_t diag = pos++;
        A->col[diag] = d->row[i];
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
                A->col[pos] = d->row[j];
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
            wall_rc = MF_ERROR(MF_ERR_NUMERIC,
                               "unstable (throughWall) at time %g, step %ld: fluid particle id "
                               "%lld at (%g %g %g) has only dummy particles within re: it is "
                               "inside a wall",
                               sim->time, sim->step, (long long)p->id[i], p->pos[3 * i],
                               p->pos[3 * i + 1], p->pos[3 * i + 2]);
            break;
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
    /* Every rank learns of a particle inside a wall before the solve. */
    wall_rc = mf_parallel_agree(sim->par, wall_rc);
    if (wall_rc != 0) {
        free(touches);
        return mf_error_trace(wall_rc, __FILE__, __LINE__, __func__);
    }
    A->rowptr[nrows] = pos;
    size_t closed = 0;
    int rc = regularise_closed_groups(d, sim, nl, touches, &closed);
    free(touches);
    MF_CALL(rc);
    double nclosed = (double)closed;
    mf_parallel_sum(sim->par, &nclosed, 1);
    closed = (size_t)nclosed;
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
/* x of another rank's row, from the copies' (global row, value) pairs. */
typedef struct row_value {
    int64_t row;
    double x;
} row_value;

static int by_row(const void *a, const void *b)
{
    int64_t x = ((const row_value *)a)->row, y = ((const row_value *)b)->row;
    return (x > y) - (x < y);
}

static double remote_x(const row_value *t, size_t n, int64_t row)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (t[mid].row < row)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < n && t[lo].row == row ? t[lo].x : NAN;
}

/* The largest residual |b - A x| of this rank's rows and its particle
 * (SIZE_MAX when there is none). Other ranks' x come through the copies. */
static int worst_row(mps_data *d, const mf_sim *sim, double *rmax, size_t *particle)
{
    const mf_particles *p = sim->p;
    const mf_csr *A = &d->A;
    const int64_t offset = A->row_offset;
    double *xp = d->grad; /* scratch, n values: the step is lost anyway */
    for (size_t i = 0; i < p->n_owned; i++)
        xp[i] = d->row[i] >= 0 ? d->x[d->row[i] - offset] : 0.0;
    MF_CALL(mps_halo_sync(d, sim, xp, sizeof *xp));
    size_t nt = 0;
    row_value *t = malloc((p->n - p->n_owned + 1) * sizeof *t);
    int rc = mf_parallel_agree(sim->par, t ? 0 : MF_ERROR(MF_ERR_MEMORY, "out of memory"));
    if (rc != 0) {
        free(t);
        return rc;
    }
    for (size_t j = p->n_owned; j < p->n; j++)
        if (d->row[j] >= 0 && (d->row[j] < offset || d->row[j] >= offset + (int64_t)A->nrows))
            t[nt++] = (row_value){d->row[j], xp[j]};
    qsort(t, nt, sizeof *t, by_row);
    *rmax = -1;
    *particle = SIZE_MAX;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (d->row[i] < 0)
            continue;
        const size_t r = (size_t)(d->row[i] - offset);
        double res = d->rhs[r];
        for (size_t k = A->rowptr[r]; k < A->rowptr[r + 1]; k++) {
            const int64_t c = A->col[k];
            const double xc = c >= offset && c < offset + (int64_t)A->nrows
                                  ? d->x[c - offset]
                                  : remote_x(t, nt, c);
            res -= A->val[k] * xc;
        }
        if (!(fabs(res) <= *rmax)) {
            *rmax = isfinite(res) ? fabs(res) : INFINITY;
            *particle = i;
        }
    }
    free(t);
    return 0;
}

/* The pressure solve did not converge (MF_RETRY from the pressure module,
 * on every rank): name it as the run's watch names its criteria
 * (pressureSolve), with the time, the residuals and the particle of the
 * largest residual over all ranks, so that a run stopped by it says where.
 * Stays MF_RETRY: a smaller step may fix it. */
static int solve_failed(mps_data *d, const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    double rmax = -1;
    size_t i = SIZE_MAX;
    MF_CALL(worst_row(d, sim, &rmax, &i));
    int who = 0;
    mf_parallel_maxloc(sim->par, &rmax, &who);
    struct {
        int found, kind;
        long long id;
        double x[3];
    } w = {0, 0, 0, {0, 0, 0}};
    if (mf_parallel_rank(sim->par) == who && i != SIZE_MAX) {
        w.found = 1;
        w.kind = p->kind[i];
        w.id = (long long)p->id[i];
        memcpy(w.x, &p->pos[3 * i], sizeof w.x);
    }
    mf_parallel_bcast(sim->par, &w, sizeof w, who);
    const char *why = d->last.final_residual > d->last.initial_residual ||
                              !isfinite(d->last.final_residual)
                          ? ", diverging"
                          : "";
    if (!w.found)
        return MF_ERROR(MF_RETRY,
                        "unstable (pressureSolve) at time %g, step %ld: %s not converged after "
                        "%d iterations (relative residual %g, from %g%s)",
                        sim->time + sim->dt, sim->step + 1, d->pressure.info->name,
                        d->last.iterations, d->last.final_residual, d->last.initial_residual,
                        why);
    return MF_ERROR(MF_RETRY,
                    "unstable (pressureSolve) at time %g, step %ld: %s not converged after %d "
                    "iterations (relative residual %g, from %g%s); largest residual at %s "
                    "particle id %lld at (%g %g %g)",
                    sim->time + sim->dt, sim->step + 1, d->pressure.info->name,
                    d->last.iterations, d->last.final_residual, d->last.initial_residual, why,
                    mf_particle_kind_name(w.kind), w.id, w.x[0], w.x[1], w.x[2]);
}

int mps_solve_ppe(mps_data *d, mf_sim *sim)
{
    double t0 = mf_wall_seconds();
    mf_particles *p = sim->p;
    int rc = d->pressure_ops->solve(d->pressure.data, &d->A, d->rhs, d->x, &d->last);
    mf_log_printf(sim->log, MF_LOG_STEP,
                  "%s:  Solving for %s, Initial residual = %g, Final residual = %g, No "
                  "Iterations %d\n",
                  d->pressure.info->name, d->solve_name ? d->solve_name : "p",
                  d->last.initial_residual, d->last.final_residual,
                  d->last.iterations);
    sim->pressure_iterations += d->last.iterations;
    d->solves++;
    d->t_setup += d->last.setup_seconds;
    d->t_pcg += d->last.solve_seconds;
    d->t_solve += mf_wall_seconds() - t0;
    if (rc == MF_RETRY)
        return solve_failed(d, sim); /* every rank gets MF_RETRY: the solve is collective */
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    double *pressure = mf_particles_fd(p, d->f_pressure);
    const int64_t offset = d->A.row_offset;
    for (size_t i = 0; i < p->n_owned; i++) {
        double v = d->row[i] >= 0 ? d->x[d->row[i] - offset]
                                  : (d->p_dirichlet ? d->p_dirichlet[i] : 0.0);
        pressure[i] = (d->s.clip_negative_pressure && v < 0) ? 0.0 : v;
    }
    MF_CALL(mps_halo_sync(d, sim, pressure, sizeof *pressure));
    return 0;
}
