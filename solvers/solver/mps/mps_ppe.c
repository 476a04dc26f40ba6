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

/* Is j a copy of another rank's unknown that its owner's search reached? */
typedef struct reach_ctx {
    const uint8_t *in_ppe, *flag;
    size_t n_owned;
} reach_ctx;

static inline bool reached_copy(void *acc, const void *ctx, const mf_pair *pr)
{
    const reach_ctx *c = ctx;
    if (pr->j >= c->n_owned && c->in_ppe[pr->j] && c->flag[pr->j]) {
        *(bool *)acc = true;
        return false;
    }
    return true;
}

/* Rows reachable from a row that touches a Dirichlet particle are fine;
 * the rest form closed groups. Breadth-first over the matrix graph; on
 * several ranks in rounds: each rank searches its rows, the copies learn
 * whether their owners were reached, and a row next to a reached copy
 * starts the next round, until no rank reaches a new row. */
static int regularise_closed_groups(mps_data *d, const mf_sim *sim, const mf_pairs *nl,
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
            flag[i] = d->row[i] >= 0 && seen[d->row[i]];
        MF_CALL_GOTO(rc, mps_halo_sync(d, sim, flag, 1), done);
        double reached = 0;
        for (size_t i = 0; i < p->n_owned; i++) {
            if (d->row[i] < 0 || seen[d->row[i]])
                continue;
            const reach_ctx rc_ctx = {d->in_ppe, flag, p->n_owned};
            bool hit = false;
            mf_pairs_row_r2(nl, i, NULL, reached_copy, &rc_ctx, &hit);
            if (hit) {
                seen[d->row[i]] = 1;
                queue[tail++] = (size_t)d->row[i];
                reached++;
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

/* hl: c->hl; rho: c->rho_p != NULL (literals at the call sites: the plain
 * row, eq. 13's with one density, compiles to its own loop without their
 * tests). */
static inline __attribute__((always_inline)) double ppe_coef_as(const void *ctx,
                                                                const mf_pair *pr, bool hl,
                                                                bool rho)
{
    const ppe_ctx *c = ctx;
    double cw = hl ? c->c * mf_weight_hl(pr->len, c->re, c->dim)
                   : c->c * mf_weight(pr->len, c->re);
    if (rho)
        cw *= mf_inv_rho_pair(c->rho_p[pr->i], c->rho_p[pr->j], c->avg);
    return cw;
}

static inline double ppe_coef(const void *ctx, const mf_pair *pr)
{
    const ppe_ctx *c = ctx;
    return ppe_coef_as(ctx, pr, c->hl, c->rho_p != NULL);
}

static inline double ppe_coef_plain(const void *ctx, const mf_pair *pr)
{
    return ppe_coef_as(ctx, pr, false, false);
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

/* The row's entries; 0: a fluid particle with no non-dummy neighbour
 * (reported by the caller). plain (a literal): no higher-order Laplacian,
 * no density per particle. */
static inline __attribute__((always_inline)) size_t ppe_row_as(const void *ctx, size_t i,
                                                               size_t r, bool plain)
{
    const ppe_ctx *c = ctx;
    mps_data *d = c->d;
    ppe_acc acc = {0.0, false};
    const size_t diag = c->rows.rowptr[r];
    size_t entries = 0;
    const double sum =
        plain ? mf_pairs_row_assemble(&c->v, i, d->not_dummy, NULL, ppe_coef_plain, ppe_known,
                                      c, &acc, &c->rows, r, &entries)
              : mf_pairs_row_assemble(&c->v, i, d->not_dummy, NULL, ppe_coef, ppe_known, c,
                                      &acc, &c->rows, r, &entries);
    if (!(sum > 0) && d->is_fluid[i] && !d->wall)
        return 0; /* (wall weight: a particle with only the wall near takes p = 0 below) */
    const double dt2 = c->dt * c->dt;
    /* n* - n0, or against a per-particle reference (mps_data.n_offset) */
    const double dn = d->n_offset ? c->n[i] - c->n0 - d->n_offset[i] : c->n[i] - c->n0;
    double *val = d->A.val;
    if (c->rho_p) {
        val[diag] = sum + d->s.compressibility / dt2;
        d->rhs[r] = c->src ? c->src[i] : d->sc.relaxation / dt2 * dn / c->n0;
    } else {
        val[diag] = sum + d->s.compressibility * c->rho / dt2;
        d->rhs[r] = c->src ? c->rho * c->src[i] : d->sc.relaxation * c->rho / dt2 * dn / c->n0;
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
    return entries;
}

static size_t ppe_row(const void *ctx, size_t i, size_t r)
{
    return ppe_row_as(ctx, i, r, false);
}

static size_t ppe_row_plain(const void *ctx, size_t i, size_t r)
{
    return ppe_row_as(ctx, i, r, true);
}

/* Before the rows: room for the entries (a bound, mf_pairs_assemble). */
static int ppe_sized(void *ctx, size_t nnz)
{
    ppe_ctx *c = ctx;
    MF_CALL(reserve_system(c->d, c->d->A.nrows, nnz));
    /* The pressure module may make its fine matrix in them (fine_in_place.c). */
    c->d->A.lent_capacity = c->d->cap_nnz;
    c->rows.col = c->d->A.col;
    c->rows.val = c->d->A.val;
    c->rows.rowptr = c->d->A.rowptr;
    return 0;
}

int mps_assemble_ppe(mps_data *d, const mf_sim *sim, double dt)
{
    double t0 = mf_wall_seconds();
    const mf_particles *p = sim->p;
    /* Which copies are unknowns: their owners decided (a composing solver
     * may have changed the owned ones since the surface phase). */
    MF_CALL(mps_halo_sync(d, sim, d->in_ppe, 1));
    size_t nrows = 0;
    for (size_t i = 0; i < p->n_owned; i++)
        d->row[i] = d->in_ppe[i] ? (long)nrows++ : -1;
    /* Rows over the ranks: a copy is its owner's unknown (an image, or a
     * particle of another rank). */
    int64_t offset = 0, nglobal = 0;
    const long *global_col = NULL;
    MF_CALL(mps_global_rows(d, sim, d->row, nrows, d->row_global, &offset, &nglobal,
                            &global_col));
    if (nglobal > MF_CSR_MAX_GLOBAL)
        return MF_ERROR(MF_ERR_INPUT,
                        "%lld pressure unknowns: the matrix's columns are 32-bit (hypre's "
                        "HYPRE_BigInt), at most %d in all",
                        (long long)nglobal, MF_CSR_MAX_GLOBAL);
    MF_CALL(reserve_system(d, nrows, 0));
    uint8_t *touches = calloc(nrows ? nrows : 1, 1);
    if (!touches)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    mf_csr *A = &d->A;
    A->nrows = nrows;
    A->row_offset = offset;
    A->nglobal = nglobal;
    ppe_ctx c = {
        .d = d,
        .sim = sim,
        .rows = {d->row, A->row_offset, A->rowptr, A->col, A->val, global_col},
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
    /* What the source was made of (n_start, rate_start, work) is dead until
     * the next step: its pages given back before the matrix is written. */
    if (rc == 0)
        (void)mps_scheme_release(d, false);
    /* higherOrder, and leastSquares' PPE; with wall wallWeight the walls add
     * nothing to it, as to eq. 7's row (p_v = p_i: mps_wall.c), and LSMPS's
     * wall points are the viscous term's only */
    if (d->sc.laplacian != MPS_LAPLACIAN_PAPER) {
        c.hl = true;
        c.c = d->k_lap.hl_coef;
    }
    if (rc == 0)
        rc = mps_pairs(d, sim, d->h_lap, &c.v);
    c.re = c.v.radius;
    size_t failed = SIZE_MAX;
    if (rc == 0)
        rc = mf_pairs_assemble(&c.v, &c.rows, nrows, ppe_sized,
                               !c.hl && !c.rho_p ? ppe_row_plain : ppe_row, &c, &failed);
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
    /* Every rank learns of a particle inside a wall before the solve. */
    rc = mf_parallel_agree(sim->par, rc);
    if (rc != 0) {
        free(touches);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    size_t closed = 0;
    rc = regularise_closed_groups(d, sim, &c.v, touches, &closed);
    free(touches);
    MF_CALL(rc);
    double nclosed = (double)closed; /* over the ranks */
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
        xp[i] = d->row[i] >= 0 ? d->x[d->row[i]] : 0.0;
    MF_CALL(mps_halo_sync(d, sim, xp, sizeof *xp));
    /* A copy's global row (on one rank an image's row is its owner's). */
    const long *grow = sim->par ? d->row_global : d->row;
    size_t nt = 0;
    row_value *t = malloc((p->n - p->n_owned + 1) * sizeof *t);
    int rc = mf_parallel_agree(sim->par, t ? 0 : MF_ERROR(MF_ERR_MEMORY, "out of memory"));
    if (rc != 0) {
        free(t);
        return rc;
    }
    for (size_t j = p->n_owned; j < p->n; j++)
        if (grow[j] >= 0 && (grow[j] < offset || grow[j] >= offset + (int64_t)A->nrows))
            t[nt++] = (row_value){grow[j], xp[j]};
    qsort(t, nt, sizeof *t, by_row);
    *rmax = -1;
    *particle = SIZE_MAX;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (d->row[i] < 0)
            continue;
        const size_t r = (size_t)d->row[i];
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
        return solve_failed(d, sim); /* every rank gets MF_RETRY: the solve is collective */
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    double *pressure = mf_particles_fd(p, d->f_pressure);
    for (size_t i = 0; i < p->n_owned; i++) {
        double v = d->row[i] >= 0 ? d->x[d->row[i]] : (d->p_dirichlet ? d->p_dirichlet[i] : 0.0);
        pressure[i] = (d->s.clip_negative_pressure && v < 0) ? 0.0 : v;
    }
    MF_CALL(mps_halo_sync(d, sim, pressure, sizeof *pressure));
    return 0;
}
