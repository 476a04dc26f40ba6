/* test_pressure.c: the hypre pressure solvers (PCG_BoomerAMG, PCG_diagonal)
 * on the 2-D 5-point Poisson matrix with Dirichlet boundaries, whose
 * spectrum is known: eigenvalues 4 - 2 cos(i pi h) - 2 cos(j pi h), h = 1/(n+1),
 * so kappa = cot^2(pi h / 2). The error bound used below is the standard
 * ||x - x*|| / ||x*|| <= kappa * ||b - A x|| / ||b||.
 *
 * Each rank builds its own block of rows, so the test also runs under
 * `mpirun -np K` (meson runs it on one rank).
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <HYPRE_utilities.h>
#include <mpi.h>

#include "mf_test.h"
/* Also the internal part, for the pattern fingerprint behind reuseSetup. */
#define MF_PRESSURE_HYPRE_INTERNAL
#include "pressure/pressure_hypre.h"
#include "pressure/amg_vcycle.h"

#include <HYPRE_IJ_mv.h>
#include <omp.h>

static int rank = 0, nprocs = 1;

/* ---- the test system ------------------------------------------------------ */

typedef struct poisson {
    mf_csr A;
    double *x_exact, *b, *x;
} poisson;

/* This rank's block of rows of the n*n grid (row = i + n j), in CSR. */
static void poisson_build_part(poisson *p, int n, int part, int nparts)
{
    const int64_t N = (int64_t)n * n;
    const int64_t lo = N * part / nparts, hi = N * (part + 1) / nparts;
    const size_t nrows = (size_t)(hi - lo);
    memset(p, 0, sizeof *p);
    p->A.nrows = nrows;
    p->A.row_offset = lo;
    p->A.nglobal = N;
    p->A.rowptr = malloc((nrows + 1) * sizeof *p->A.rowptr);
    p->A.col = malloc((5 * nrows + 1) * sizeof *p->A.col);
    p->A.val = malloc((5 * nrows + 1) * sizeof *p->A.val);
    p->x_exact = malloc((nrows + 1) * sizeof(double));
    p->b = malloc((nrows + 1) * sizeof(double));
    p->x = calloc(nrows + 1, sizeof(double));
    if (!p->A.rowptr || !p->A.col || !p->A.val || !p->x_exact || !p->b || !p->x) {
        fprintf(stderr, "out of memory\n");
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    size_t k = 0;
    for (size_t r = 0; r < nrows; r++) {
        const int64_t g = lo + (int64_t)r;
        const int i = (int)(g % n), j = (int)(g / n);
        p->A.rowptr[r] = k;
        /* Neighbours first and the diagonal in the middle: hypre must not
         * depend on the diagonal coming first. */
        if (j > 0) { p->A.col[k] = g - n; p->A.val[k++] = -1.0; }
        if (i > 0) { p->A.col[k] = g - 1; p->A.val[k++] = -1.0; }
        p->A.col[k] = g; p->A.val[k++] = 4.0;
        if (i < n - 1) { p->A.col[k] = g + 1; p->A.val[k++] = -1.0; }
        if (j < n - 1) { p->A.col[k] = g + n; p->A.val[k++] = -1.0; }
        /* A smooth field plus a deterministic rough part: exercises all
         * frequencies, not only the ones AMG finds easy. */
        const double sx = (i + 1.0) / (n + 1.0), sy = (j + 1.0) / (n + 1.0);
        uint64_t h = (uint64_t)g * 0x9E3779B97F4A7C15ull;
        h ^= h >> 29;
        const double noise = (double)(h % 2001) / 1000.0 - 1.0;
        p->x_exact[r] = sin(3.0 * sx) * cos(2.0 * sy) + 0.3 * noise;
    }
    p->A.rowptr[nrows] = k;
}

static void poisson_build(poisson *p, int n)
{
    poisson_build_part(p, n, rank, nprocs);
}

/* Variable coefficients: a symmetric matrix less regular than the 5-point
 * stencil, its diagonal the off-diagonal sums plus a little (by global
 * rows and columns: the same matrix on any number of ranks). */
static void vary_coefficients(poisson *p)
{
    const size_t n = p->A.nrows;
    for (size_t r = 0; r < n; r++) {
        const int64_t g = p->A.row_offset + (int64_t)r;
        double dsum = 0.0;
        size_t kd = 0;
        for (size_t k = p->A.rowptr[r]; k < p->A.rowptr[r + 1]; k++) {
            const int64_t c = p->A.col[k];
            if (c != g) {
                const int64_t lo = g < c ? g : c, hi = g < c ? c : g;
                p->A.val[k] = -(1.0 + 0.5 * sin(0.37 * (double)lo + 0.11 * (double)hi));
                dsum -= p->A.val[k];
            } else
                kd = k;
        }
        p->A.val[kd] = dsum + 0.01;
    }
}

static void poisson_free(poisson *p)
{
    free(p->A.rowptr);
    free(p->A.col);
    free(p->A.val);
    free(p->x_exact);
    free(p->b);
    free(p->x);
}

static double global_sum(double local)
{
    double s = 0.0;
    MPI_Allreduce(&local, &s, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    return s;
}

/* b = A x_exact (x gathered from all ranks, fine for test sizes). */
static void make_rhs(poisson *p)
{
    const int64_t N = p->A.nglobal;
    double *xg = malloc((size_t)N * sizeof *xg);
    int *counts = malloc((size_t)nprocs * sizeof *counts), *displs = malloc((size_t)nprocs * sizeof *displs);
    for (int q = 0; q < nprocs; q++) {
        displs[q] = (int)(N * q / nprocs);
        counts[q] = (int)(N * (q + 1) / nprocs) - displs[q];
    }
    MPI_Allgatherv(p->x_exact, (int)p->A.nrows, MPI_DOUBLE, xg, counts, displs, MPI_DOUBLE,
                   MPI_COMM_WORLD);
    for (size_t r = 0; r < p->A.nrows; r++) {
        double s = 0.0;
        for (size_t k = p->A.rowptr[r]; k < p->A.rowptr[r + 1]; k++)
            s += p->A.val[k] * xg[p->A.col[k]];
        p->b[r] = s;
    }
    free(xg);
    free(counts);
    free(displs);
}

static double rel_error(const poisson *p)
{
    double e = 0.0, n = 0.0;
    for (size_t r = 0; r < p->A.nrows; r++) {
        e += (p->x[r] - p->x_exact[r]) * (p->x[r] - p->x_exact[r]);
        n += p->x_exact[r] * p->x_exact[r];
    }
    return sqrt(global_sum(e) / global_sum(n));
}

static double kappa_poisson(int n)
{
    const double t = tan(M_PI / (2.0 * (n + 1)));
    return 1.0 / (t * t);
}

/* ---- helpers for the modules ----------------------------------------------- */

static void defaults(const mf_pressure_ops *ops, void *settings)
{
    memset(settings, 0, ops->info.settings_size);
    CHECK_OK(mf_params_defaults(ops->info.params, ops->info.nparams, settings));
}

/* Create, solve once, destroy. */
static int solve_once(const mf_pressure_ops *ops, const void *settings, poisson *p,
                      mf_solve_report *rep)
{
    void *data = NULL;
    int rc = ops->create(settings, &data);
    if (rc != 0)
        return rc;
    rc = ops->solve(data, &p->A, p->b, p->x, rep);
    ops->destroy(data);
    return rc;
}

/* ---- tests ------------------------------------------------------------------- */

static void test_tables(void)
{
    const mf_pressure_ops *all[] = {&mf_pressure_PCG_BoomerAMG, &mf_pressure_PCG_diagonal};
    const char *names[] = {"PCG_BoomerAMG", "PCG_diagonal"};
    for (int m = 0; m < 2; m++) {
        const mf_module_info *info = &all[m]->info;
        CHECK(info->abi_version == MF_ABI_VERSION);
        CHECK(info->kind == MF_KIND_PRESSURE);
        CHECK(strcmp(info->name, names[m]) == 0);
        CHECK(info->summary && info->summary[0]);
        CHECK(info->params && info->nparams >= 2);
        CHECK(all[m]->create && all[m]->solve && all[m]->destroy);
        /* Every default lies inside its declared range. */
        char settings[256];
        CHECK(info->settings_size <= sizeof settings);
        defaults(all[m], settings);
        for (size_t i = 0; i < info->nparams; i++) {
            const mf_param *par = &info->params[i];
            /* each field read as its own type: a bool is one byte, anywhere */
            double v = 0;
            bool ranged = true;
            if (par->type == MF_PARAM_SCALAR) {
                memcpy(&v, settings + par->offset, sizeof v);
            } else if (par->type == MF_PARAM_INT) {
                long l;
                memcpy(&l, settings + par->offset, sizeof l);
                v = (double)l;
            } else if (par->type == MF_PARAM_BOOL) {
                bool b;
                memcpy(&b, settings + par->offset, sizeof b);
                v = b;
            } else {
                ranged = false; /* words, vectors, dictionaries: no range */
            }
            CHECK_MSG(!ranged || par->min > par->max || (v >= par->min && v <= par->max),
                      "%s.%s = %g", info->name, par->name, v);
            CHECK_MSG(par->doc && par->doc[0], "%s.%s has no doc", info->name, par->name);
        }
        void *data = NULL;
        CHECK_OK(all[m]->create(settings, &data));
        all[m]->destroy(data);
    }
    mf_pcg_boomeramg_settings s;
    defaults(&mf_pressure_PCG_BoomerAMG, &s);
    CHECK(s.coarsen_type == 10 && s.interp_type == 17 && s.p_max_elmts == 4 && s.relax_type == 3);
    CHECK(s.strong_threshold == 0.25 && s.aggressive_levels == 1 && s.reuse_setup == 0);
    CHECK(s.tolerance == 1e-8 && s.max_iter == 500);

    /* A smoother that makes a non-symmetric cycle (backward GS on both
     * ways) would break PCG: refused at create. */
    void *data = NULL;
    s.relax_type = 4;
    CHECK(mf_pressure_PCG_BoomerAMG.create(&s, &data) == MF_ERR_INPUT && data == NULL);
    mf_error_clear();
    mf_pcg_diagonal_settings ds = {.tolerance = 0.0, .max_iter = 10};
    CHECK(mf_pressure_PCG_diagonal.create(&ds, &data) == MF_ERR_INPUT && data == NULL);
    mf_error_clear();
}

/* Zero guess, tol 1e-10 on 64x64 (kappa ~ 1.7e3): the error bound
 * kappa * 1e-10 ~ 2e-7 is below the asserted 1e-5 with room to spare. */
static void test_accuracy(const mf_pressure_ops *ops, void *settings, double *tol)
{
    const int n = 64;
    poisson p;
    poisson_build(&p, n);
    make_rhs(&p);
    *tol = 1e-10;
    mf_solve_report rep;
    CHECK_OK(solve_once(ops, settings, &p, &rep));
    const double err = rel_error(&p), kappa = kappa_poisson(n);
    if (rank == 0)
        printf("%-14s 64x64 tol 1e-10: %3d iterations, residual %.2e -> %.2e, error %.2e "
               "(bound %.2e), setup %.4f s, solve %.4f s\n",
               ops->info.name, rep.iterations, rep.initial_residual, rep.final_residual, err,
               kappa * rep.final_residual, rep.setup_seconds, rep.solve_seconds);
    CHECK(rep.converged);
    CHECK(rep.iterations > 0);
    CHECK_NEAR(rep.initial_residual, 1.0, 1e-14); /* zero guess: r0 = b */
    CHECK(rep.final_residual <= 1e-10);
    CHECK(err <= kappa * rep.final_residual * 1.01 + 1e-14);
    CHECK(err <= 1e-5);
    CHECK(rep.setup_seconds >= 0.0 && rep.solve_seconds >= 0.0);
    CHECK(rep.setup_seconds + rep.solve_seconds < 60.0);
    poisson_free(&p);
}

/* On 128x128 (kappa ~ 6.7e3) diagonal PCG needs hundreds of iterations;
 * one V-cycle per iteration is nearly grid-independent (about 10). */
static void test_amg_beats_diagonal(void)
{
    poisson p;
    poisson_build(&p, 128);
    make_rhs(&p);
    mf_pcg_boomeramg_settings as;
    defaults(&mf_pressure_PCG_BoomerAMG, &as);
    mf_pcg_diagonal_settings ds;
    defaults(&mf_pressure_PCG_diagonal, &ds);
    ds.max_iter = 5000; /* the comparison must not hinge on the limit */
    mf_solve_report ra, rd;
    CHECK_OK(solve_once(&mf_pressure_PCG_BoomerAMG, &as, &p, &ra));
    CHECK(rel_error(&p) <= kappa_poisson(128) * ra.final_residual * 1.01 + 1e-14);
    memset(p.x, 0, p.A.nrows * sizeof *p.x);
    CHECK_OK(solve_once(&mf_pressure_PCG_diagonal, &ds, &p, &rd));
    if (rank == 0)
        printf("128x128 tol 1e-8: PCG_BoomerAMG %d iterations (%.4f + %.4f s), PCG_diagonal %d "
               "iterations (%.4f + %.4f s)\n",
               ra.iterations, ra.setup_seconds, ra.solve_seconds, rd.iterations,
               rd.setup_seconds, rd.solve_seconds);
    CHECK(ra.converged && rd.converged);
    CHECK(ra.final_residual <= 1e-8 && rd.final_residual <= 1e-8);
    CHECK(ra.iterations < rd.iterations);
    CHECK(ra.iterations <= 30);
    CHECK(rd.iterations >= 100);
    poisson_free(&p);
}

/* Too few iterations: MF_RETRY (recoverable) with the report filled. */
static void test_not_converged(const mf_pressure_ops *ops, void *settings, long *max_iter)
{
    poisson p;
    poisson_build(&p, 64);
    make_rhs(&p);
    *max_iter = 2;
    mf_solve_report rep;
    mf_error_clear();
    int rc = solve_once(ops, settings, &p, &rep);
    CHECK_MSG(rc == MF_RETRY, "%s returned %d", ops->info.name, rc);
    CHECK(!rep.converged);
    CHECK(rep.iterations == 2);
    CHECK_NEAR(rep.initial_residual, 1.0, 1e-14);
    CHECK(rep.final_residual > 1e-8 && rep.final_residual < 1.0);
    CHECK(strstr(mf_error_message(), "not converged after 2 iterations") != NULL);
    CHECK(strstr(mf_error_message(), ops->info.name) != NULL);
    mf_error_clear();
    *max_iter = 500;
    poisson_free(&p);
}

/* b = 0: x = 0 exactly, whatever the guess, without iterating. */
static void test_zero_rhs(const mf_pressure_ops *ops, const void *settings)
{
    poisson p;
    poisson_build(&p, 16);
    for (size_t r = 0; r < p.A.nrows; r++) {
        p.b[r] = 0.0;
        p.x[r] = 1.0 + (double)r;
    }
    mf_solve_report rep;
    CHECK_OK(solve_once(ops, settings, &p, &rep));
    bool zero = true;
    for (size_t r = 0; r < p.A.nrows; r++)
        zero = zero && p.x[r] == 0.0;
    CHECK(zero);
    CHECK(rep.iterations == 0 && rep.converged);
    CHECK(rep.initial_residual == 0.0 && rep.final_residual == 0.0);
    poisson_free(&p);
}

/* Starting from the exact solution: 0 or 1 iterations. */
static void test_warm_start(const mf_pressure_ops *ops, const void *settings)
{
    poisson p;
    poisson_build(&p, 64);
    make_rhs(&p);
    memcpy(p.x, p.x_exact, p.A.nrows * sizeof *p.x);
    mf_solve_report rep;
    CHECK_OK(solve_once(ops, settings, &p, &rep));
    CHECK(rep.converged);
    CHECK(rep.iterations <= 1);
    CHECK(rep.initial_residual < 1e-14);
    CHECK(rel_error(&p) < 1e-12);
    poisson_free(&p);
}

/* reuseSetup: the same pattern with new values, a changed pattern, and
 * values far from those the hierarchy was built for: all must converge. */
static void test_reuse(void)
{
    mf_pcg_boomeramg_settings s;
    defaults(&mf_pressure_PCG_BoomerAMG, &s);
    s.reuse_setup = 3;
    void *data = NULL;
    CHECK_OK(mf_pressure_PCG_BoomerAMG.create(&s, &data));
    mf_solve_report rep;
    const double scales[] = {1.0, 1.5, 0.5};
    int its[3] = {0, 0, 0};
    poisson p;
    poisson_build(&p, 64);
    for (int t = 0; t < 3; t++) {
        /* Scale the matrix; same pattern, so the hierarchy is reused. */
        for (size_t k = 0; k < p.A.rowptr[p.A.nrows]; k++)
            p.A.val[k] *= t == 0 ? 1.0 : scales[t] / scales[t - 1];
        make_rhs(&p);
        memset(p.x, 0, p.A.nrows * sizeof *p.x);
        CHECK_OK(mf_pressure_PCG_BoomerAMG.solve(data, &p.A, p.b, p.x, &rep));
        CHECK(rep.converged && rep.final_residual <= 1e-8);
        CHECK(rel_error(&p) <= kappa_poisson(64) * rep.final_residual * 1.01 + 1e-14);
        its[t] = rep.iterations;
    }
    if (rank == 0)
        printf("reuseSetup: %d, %d, %d iterations\n", its[0], its[1], its[2]);

    /* A diagonal shift of 20: the kept hierarchy (with its l1 norms) no
     * longer fits; whatever happens inside, the answer must be right. */
    for (size_t r = 0; r < p.A.nrows; r++)
        for (size_t k = p.A.rowptr[r]; k < p.A.rowptr[r + 1]; k++)
            if (p.A.col[k] == p.A.row_offset + (int64_t)r)
                p.A.val[k] += 20.0;
    make_rhs(&p);
    memset(p.x, 0, p.A.nrows * sizeof *p.x);
    CHECK_OK(mf_pressure_PCG_BoomerAMG.solve(data, &p.A, p.b, p.x, &rep));
    CHECK(rep.converged && rel_error(&p) < 1e-6);
    poisson_free(&p);

    /* A new size: a new hierarchy. */
    poisson_build(&p, 48);
    make_rhs(&p);
    CHECK_OK(mf_pressure_PCG_BoomerAMG.solve(data, &p.A, p.b, p.x, &rep));
    CHECK(rep.converged && rel_error(&p) <= kappa_poisson(48) * rep.final_residual * 1.01 + 1e-14);
    poisson_free(&p);
    mf_pressure_PCG_BoomerAMG.destroy(data);
}

/* Named rows (mf_row_names, reuseHierarchy): a sequence of systems on one
 * grid whose unknowns change (a band of Dirichlet rows that moves, as a
 * free surface does), solved in slot space with the hierarchy kept: each
 * answer as accurate as a solve in rows, the kept hierarchy's iterations
 * within rebuildRatio of a fresh one's; a new epoch (the slots renumbered)
 * and bad slots. On several ranks each rank holds a block of grid points
 * (its slots: the block's points, its rows the unknowns among them, global
 * rows numbered in grid order), and from solve 8 on rank 0 alone renumbers
 * its slots: every rank must then set a new hierarchy up together. */
static double masked_exact(int n, int64_t g)
{
    const int i = (int)(g % n), j = (int)(g / n);
    return sin(0.1 * i) * cos(0.07 * j) + 0.01 * (double)((g * 7919) % 13);
}

static void masked_system(int n, int t, bool renumber, poisson *p, int64_t *slot,
                          int64_t *nslots)
{
    /* Unknowns: grid points (i, j) outside the band j in [t, t + 3) mod n. */
    const int64_t N = (int64_t)n * n;
    const int64_t lo = N * rank / nprocs, hi = N * (rank + 1) / nprocs, nloc = hi - lo;
    memset(p, 0, sizeof *p);
    p->A.rowptr = malloc((nloc + 1) * sizeof *p->A.rowptr);
    p->A.col = malloc((5 * nloc + 1) * sizeof *p->A.col);
    p->A.val = malloc((5 * nloc + 1) * sizeof *p->A.val);
    p->x_exact = malloc((nloc + 1) * sizeof(double));
    p->b = malloc((nloc + 1) * sizeof(double));
    p->x = calloc(nloc + 1, sizeof(double));
    int64_t *row = malloc(N * sizeof *row); /* global row of each point, -1 if masked */
    int64_t nglobal = 0;
    for (int64_t g = 0; g < N; g++) {
        const int j = (int)(g / n);
        row[g] = ((j - t) % n + n) % n < 3 ? -1 : nglobal++;
    }
    size_t k = 0, nrows = 0;
    p->A.row_offset = -1;
    for (int64_t g = lo; g < hi; g++) {
        if (row[g] < 0)
            continue;
        if (p->A.row_offset < 0)
            p->A.row_offset = row[g];
        const size_t r = nrows++;
        const int i = (int)(g % n), j = (int)(g / n);
        const int64_t nb[4] = {j > 0 ? g - n : -1, i > 0 ? g - 1 : -1, i < n - 1 ? g + 1 : -1,
                               j < n - 1 ? g + n : -1};
        double acc = 4.0 * masked_exact(n, g);
        p->A.rowptr[r] = k;
        p->A.col[k] = (int32_t)row[g];
        p->A.val[k++] = 4.0;
        for (int q = 0; q < 4; q++)
            if (nb[q] >= 0 && row[nb[q]] >= 0) {
                p->A.col[k] = (int32_t)row[nb[q]];
                p->A.val[k++] = -1.0;
                acc -= masked_exact(n, nb[q]);
            }
        p->x_exact[r] = masked_exact(n, g);
        p->b[r] = acc;
        /* The renumbering: 2654435761 is prime to the block's size. */
        slot[r] = renumber ? ((g - lo) * 2654435761) % nloc : g - lo;
    }
    if (p->A.row_offset < 0) { /* no unknowns here: the rows of the points before */
        p->A.row_offset = 0;
        for (int64_t g = 0; g < lo; g++)
            p->A.row_offset += row[g] >= 0;
    }
    p->A.rowptr[nrows] = k;
    p->A.nrows = nrows;
    p->A.nglobal = nglobal;
    *nslots = nloc;
    free(row);
}

/* A matrix that lends its arrays (mf_csr.lent_capacity: the AMG set-up's
 * fine matrix made in them, fine_in_place.c) is solved exactly as one that
 * does not, bit for bit, and comes back as it was. One rank (the in-place
 * set-up is our V-cycle's). */
static void test_lent_rows(void)
{
    if (nprocs != 1)
        return;
    const int n = 48;
    int64_t *slot = malloc((size_t)n * n * sizeof *slot), nslots = 0;
    for (int t = 0; t < 12; t += 5) {
        poisson p, q;
        mf_pcg_boomeramg_settings s;
        defaults(&mf_pressure_PCG_BoomerAMG, &s);
        void *a = NULL, *b = NULL;
        CHECK_OK(mf_pressure_PCG_BoomerAMG.create(&s, &a));
        CHECK_OK(mf_pressure_PCG_BoomerAMG.create(&s, &b));
        masked_system(n, t, false, &p, slot, &nslots);
        masked_system(n, t, false, &q, slot, &nslots);
        const mf_row_names rows = {slot, nslots, 1};
        const size_t nnz = q.A.rowptr[q.A.nrows];
        q.A.lent_capacity = 5 * (size_t)nslots + 1; /* masked_system's room */
        CHECK(nnz + (size_t)nslots - q.A.nrows <= q.A.lent_capacity);
        for (size_t k = nnz; k < q.A.lent_capacity; k++)
            q.A.val[k] = NAN; /* the room: written only if the arrays were used */
        mf_solve_report rp, rq;
        CHECK_OK(mf_pressure_PCG_BoomerAMG.solve_rows(a, &p.A, &rows, p.b, p.x, &rp));
        CHECK_OK(mf_pressure_PCG_BoomerAMG.solve_rows(b, &q.A, &rows, q.b, q.x, &rq));
        CHECK_MSG(rp.iterations == rq.iterations &&
                      memcmp(p.x, q.x, p.A.nrows * sizeof *p.x) == 0,
                  "band at %d: lent rows solved differently (%d against %d iterations)", t,
                  rq.iterations, rp.iterations);
        CHECK_MSG(memcmp(p.A.col, q.A.col, nnz * sizeof *p.A.col) == 0 &&
                      memcmp(p.A.val, q.A.val, nnz * sizeof *p.A.val) == 0,
                  "band at %d: the lent rows did not come back as they were", t);
        size_t used = 0;
        for (size_t k = nnz; k < q.A.lent_capacity; k++)
            used += !isnan(q.A.val[k]);
        CHECK_MSG(used > 0, "band at %d: the lent arrays were not used for the set-up", t);
        mf_pressure_PCG_BoomerAMG.destroy(a);
        mf_pressure_PCG_BoomerAMG.destroy(b);
        poisson_free(&p);
        poisson_free(&q);
    }
    free(slot);
}

static void test_named_rows(void)
{
    const int n = 64;
    const int64_t N = (int64_t)n * n;
    mf_pcg_boomeramg_settings s;
    defaults(&mf_pressure_PCG_BoomerAMG, &s);
    CHECK(s.reuse_hierarchy && s.rebuild_ratio == 2);
    void *kept = NULL, *fresh = NULL;
    CHECK_OK(mf_pressure_PCG_BoomerAMG.create(&s, &kept));
    CHECK_OK(mf_pressure_PCG_BoomerAMG.create(&s, &fresh));
    int64_t *slot = malloc(N * sizeof *slot), nslots = 0;
    int its[12], its_fresh[12], setups[12];
    for (int t = 0; t < 12; t++) {
        poisson p;
        const bool renumbered = t >= 8 && rank == 0;
        masked_system(n, t, renumbered, &p, slot, &nslots);
        const mf_row_names rows = {slot, nslots, renumbered ? 2u : 1u};
        mf_solve_report rep, rep_fresh;
        CHECK_OK(mf_pressure_PCG_BoomerAMG.solve_rows(kept, &p.A, &rows, p.b, p.x, &rep));
        CHECK(rep.converged && rep.final_residual <= 1e-8);
        const double err = rel_error(&p);
        memset(p.x, 0, p.A.nrows * sizeof *p.x);
        CHECK_OK(mf_pressure_PCG_BoomerAMG.solve(fresh, &p.A, p.b, p.x, &rep_fresh));
        const double err_fresh = rel_error(&p);
        CHECK_MSG(err <= 10 * err_fresh + 1e-12 && err < 1e-5,
                  "step %d: error %g in slot space, %g in rows", t, err, err_fresh);
        its[t] = rep.iterations;
        its_fresh[t] = rep_fresh.iterations;
        setups[t] = rep.setups;
        CHECK_MSG(rep_fresh.setups == 1, "step %d: %d set-ups in rows", t, rep_fresh.setups);
        CHECK_MSG(its[t] <= fmax(2.0 * its_fresh[t], its_fresh[t] + 2.0) + 1,
                  "step %d: %d iterations with the kept hierarchy, %d fresh", t, its[t],
                  its_fresh[t]);
        poisson_free(&p);
    }
    /* Set up at the first solve and at the new epoch (on every rank, though
     * only rank 0's slots changed); kept between, but for at most one
     * rebuild in each run of solves when the iterations grow (rebuildRatio). */
    int between = 0, after = 0;
    for (int t = 1; t < 8; t++)
        between += setups[t];
    for (int t = 9; t < 12; t++)
        after += setups[t];
    CHECK_MSG(setups[0] == 1 && setups[8] == 1 && between <= 1 && after <= 1,
              "set-ups: first %d, at the new epoch %d, kept between %d and after %d",
              setups[0], setups[8], between, after);
    if (rank == 0) {
        printf("named rows on %d rank(s), a moving Dirichlet band on a %dx%d grid: iterations "
               "kept/fresh (set-ups):", nprocs, n, n);
        for (int t = 0; t < 12; t++)
            printf(" %d/%d (%d)", its[t], its_fresh[t], setups[t]);
        printf("\n");
    }

    /* Bad names: a slot twice, fewer slots than rows (on rank 0 only: the
     * others must be told, not left waiting). */
    poisson p;
    masked_system(n, 0, false, &p, slot, &nslots);
    if (rank == 0)
        slot[1] = slot[0];
    mf_row_names bad = {slot, nslots, 3};
    mf_solve_report rep;
    CHECK(mf_pressure_PCG_BoomerAMG.solve_rows(kept, &p.A, &bad, p.b, p.x, &rep) ==
          MF_ERR_INPUT);
    if (rank == 0)
        printf("a slot twice: %s\n", mf_error_message());
    mf_error_clear();
    bad.nslots = rank == 0 ? (int64_t)p.A.nrows - 1 : nslots;
    CHECK(mf_pressure_PCG_BoomerAMG.solve_rows(kept, &p.A, &bad, p.b, p.x, &rep) ==
          MF_ERR_INPUT);
    mf_error_clear();
    poisson_free(&p);
    free(slot);
    mf_pressure_PCG_BoomerAMG.destroy(kept);
    mf_pressure_PCG_BoomerAMG.destroy(fresh);
}

/* Our V-cycle (amg_vcycle.c) is hypre's in exact arithmetic: over the same
 * hierarchy, one cycle from each on the same residual agree to rounding;
 * and PCG around ours takes hypre's PCG's iterations (within one) to the
 * same tolerance. One rank, one thread (hypre's hybrid Gauss-Seidel on
 * several threads is Jacobi between the threads' blocks: another cycle). */
static void test_own_vcycle(void)
{
    if (nprocs > 1)
        return;
    const int saved_threads = omp_get_max_threads();
    omp_set_num_threads(1);
    poisson p;
    poisson_build(&p, 48);
    vary_coefficients(&p);
    const size_t n = p.A.nrows;

    /* hypre's matrix and vectors. */
    HYPRE_IJMatrix ij = NULL;
    HYPRE_IJVector ijr = NULL, ijz = NULL;
    HYPRE_ParCSRMatrix parA = NULL;
    HYPRE_ParVector parr = NULL, parz = NULL;
    void *obj = NULL;
    const HYPRE_BigInt up = (HYPRE_BigInt)n - 1;
    HYPRE_Int *ncols = malloc(n * sizeof *ncols);
    HYPRE_BigInt *rows = malloc(n * sizeof *rows), *cols = malloc(p.A.rowptr[n] * sizeof *cols);
    double *r = malloc(n * sizeof *r), *zh = malloc(n * sizeof *zh), *zo = malloc(n * sizeof *zo);
    for (size_t i = 0; i < n; i++) {
        rows[i] = (HYPRE_BigInt)i;
        ncols[i] = (HYPRE_Int)(p.A.rowptr[i + 1] - p.A.rowptr[i]);
        r[i] = cos(0.3 * (double)i) + 0.2 * (double)(i % 7);
        zh[i] = 0.0;
    }
    for (size_t k = 0; k < p.A.rowptr[n]; k++)
        cols[k] = (HYPRE_BigInt)p.A.col[k];
    CHECK(HYPRE_IJMatrixCreate(MPI_COMM_WORLD, 0, up, 0, up, &ij) == 0);
    HYPRE_IJMatrixSetObjectType(ij, HYPRE_PARCSR);
    HYPRE_IJMatrixInitialize(ij);
    HYPRE_IJMatrixSetValues(ij, (HYPRE_Int)n, ncols, rows, cols, p.A.val);
    CHECK(HYPRE_IJMatrixAssemble(ij) == 0);
    HYPRE_IJMatrixGetObject(ij, &obj);
    parA = obj;
    HYPRE_IJVector *vecs[2] = {&ijr, &ijz};
    HYPRE_ParVector *pars[2] = {&parr, &parz};
    for (int v = 0; v < 2; v++) {
        HYPRE_IJVectorCreate(MPI_COMM_WORLD, 0, up, vecs[v]);
        HYPRE_IJVectorSetObjectType(*vecs[v], HYPRE_PARCSR);
        HYPRE_IJVectorInitialize(*vecs[v]);
        HYPRE_IJVectorSetValues(*vecs[v], (HYPRE_Int)n, rows, v == 0 ? r : zh);
        HYPRE_IJVectorAssemble(*vecs[v]);
        HYPRE_IJVectorGetObject(*vecs[v], &obj);
        *pars[v] = obj;
    }

    mf_pcg_boomeramg_settings s;
    defaults(&mf_pressure_PCG_BoomerAMG, &s);
    HYPRE_Solver amg = NULL;
    CHECK_OK(mf_boomeramg_create(&s, &amg));
    CHECK(HYPRE_BoomerAMGSetup(amg, parA, parr, parz) == 0);
    /* hypre's cycle: z = M r from z = 0; then ours takes the hierarchy. */
    CHECK(HYPRE_BoomerAMGSolve(amg, parA, parr, parz) == 0);
    HYPRE_IJVectorGetValues(ijz, (HYPRE_Int)n, rows, zh);
    mf_amg_vcycle *cycle = NULL;
    CHECK_OK(mf_amg_vcycle_take(amg, &cycle));
    CHECK_MSG(cycle != NULL, "the default settings' hierarchy is not one our cycle runs");
    if (cycle != NULL) {
        mf_split_csr fine = {0};
        CHECK_OK(mf_split_csr_set(&fine, &p.A));
        mf_amg_vcycle_apply(cycle, &fine, NULL, r, zo);
        double dmax = 0.0, zmax = 0.0;
        for (size_t i = 0; i < n; i++) {
            dmax = fmax(dmax, fabs(zo[i] - zh[i]));
            zmax = fmax(zmax, fabs(zh[i]));
        }
        printf("own V-cycle against hypre's: max |difference| %.3g of max |z| %.3g\n", dmax,
               zmax);
        CHECK_MSG(zmax > 0.0 && dmax <= 1e-12 * zmax, "V-cycles differ by %g (max |z| %g)",
                  dmax, zmax);
        mf_split_csr_free(&fine);
    }
    mf_amg_vcycle_free(cycle);
    HYPRE_BoomerAMGDestroy(amg);

    /* PCG: the module's (our PCG and cycle, the default relaxType 3) against
     * hypre's PCG around hypre's cycle, same settings, same tolerance. */
    make_rhs(&p);
    memset(p.x, 0, n * sizeof *p.x);
    mf_solve_report rep;
    CHECK_OK(solve_once(&mf_pressure_PCG_BoomerAMG, &s, &p, &rep));
    CHECK(rep.converged && rep.final_residual <= 1e-8);
    HYPRE_Solver pcg = NULL;
    CHECK_OK(mf_boomeramg_create(&s, &amg));
    HYPRE_ParCSRPCGCreate(MPI_COMM_WORLD, &pcg);
    HYPRE_PCGSetTol(pcg, 1e-8);
    HYPRE_PCGSetMaxIter(pcg, 500);
    HYPRE_PCGSetTwoNorm(pcg, 1);
    HYPRE_PCGSetRecomputeResidual(pcg, 1);
    HYPRE_ParCSRPCGSetPrecond(pcg, HYPRE_BoomerAMGSolve, HYPRE_BoomerAMGSetup, amg);
    HYPRE_IJVectorSetValues(ijr, (HYPRE_Int)n, rows, p.b);
    memset(zh, 0, n * sizeof *zh);
    HYPRE_IJVectorSetValues(ijz, (HYPRE_Int)n, rows, zh);
    HYPRE_ParCSRPCGSetup(pcg, parA, parr, parz);
    CHECK(HYPRE_ParCSRPCGSolve(pcg, parA, parr, parz) == 0);
    HYPRE_Int its = 0;
    HYPRE_ParCSRPCGGetNumIterations(pcg, &its);
    printf("PCG iterations: %d with our V-cycle, %d with hypre's; error %.3g\n",
           rep.iterations, (int)its, rel_error(&p));
    CHECK_MSG(abs(rep.iterations - (int)its) <= 1, "%d iterations against hypre's %d",
              rep.iterations, (int)its);
    CHECK(rel_error(&p) <= kappa_poisson(48) * 100 * rep.final_residual);
    HYPRE_ParCSRPCGDestroy(pcg);
    HYPRE_BoomerAMGDestroy(amg);

    HYPRE_IJMatrixDestroy(ij);
    HYPRE_IJVectorDestroy(ijr);
    HYPRE_IJVectorDestroy(ijz);
    free(ncols);
    free(rows);
    free(cols);
    free(r);
    free(zh);
    free(zo);
    poisson_free(&p);
    omp_set_num_threads(saved_threads);
}

/* On several ranks: our V-cycle over hypre's hierarchy across the ranks is
 * hypre's cycle (relaxType 3 down, 4 up: Gauss-Seidel within a rank's rows,
 * Jacobi across), our PCG takes hypre's iterations within 2, and the
 * solution is the serial one within the tolerance. */
static void test_own_vcycle_ranks(void)
{
    if (nprocs == 1)
        return;
    const int saved_threads = omp_get_max_threads();
    omp_set_num_threads(1);
    enum { NGRID = 48 };
    poisson p;
    poisson_build(&p, NGRID);
    vary_coefficients(&p);
    const size_t n = p.A.nrows;
    const HYPRE_BigInt lo = (HYPRE_BigInt)p.A.row_offset, up = lo + (HYPRE_BigInt)n - 1;

    HYPRE_IJMatrix ij = NULL;
    HYPRE_IJVector ijr = NULL, ijz = NULL, ijo = NULL;
    HYPRE_ParVector parr = NULL, parz = NULL, paro = NULL;
    void *obj = NULL;
    HYPRE_Int *ncols = malloc((n + 1) * sizeof *ncols);
    HYPRE_BigInt *rows = malloc((n + 1) * sizeof *rows);
    HYPRE_BigInt *cols = malloc((p.A.rowptr[n] + 1) * sizeof *cols);
    double *r = malloc((n + 1) * sizeof *r), *zh = calloc(n + 1, sizeof *zh);
    double *zo = calloc(n + 1, sizeof *zo);
    for (size_t i = 0; i < n; i++) {
        rows[i] = lo + (HYPRE_BigInt)i;
        ncols[i] = (HYPRE_Int)(p.A.rowptr[i + 1] - p.A.rowptr[i]);
        r[i] = cos(0.3 * (double)rows[i]) + 0.2 * (double)(rows[i] % 7);
    }
    for (size_t k = 0; k < p.A.rowptr[n]; k++)
        cols[k] = (HYPRE_BigInt)p.A.col[k];
    CHECK(HYPRE_IJMatrixCreate(MPI_COMM_WORLD, lo, up, lo, up, &ij) == 0);
    HYPRE_IJMatrixSetObjectType(ij, HYPRE_PARCSR);
    HYPRE_IJMatrixInitialize(ij);
    HYPRE_IJMatrixSetValues(ij, (HYPRE_Int)n, ncols, rows, cols, p.A.val);
    CHECK(HYPRE_IJMatrixAssemble(ij) == 0);
    HYPRE_IJMatrixGetObject(ij, &obj);
    HYPRE_ParCSRMatrix parA = obj;
    HYPRE_IJVector *vecs[3] = {&ijr, &ijz, &ijo};
    HYPRE_ParVector *pars[3] = {&parr, &parz, &paro};
    for (int v = 0; v < 3; v++) {
        HYPRE_IJVectorCreate(MPI_COMM_WORLD, lo, up, vecs[v]);
        HYPRE_IJVectorSetObjectType(*vecs[v], HYPRE_PARCSR);
        HYPRE_IJVectorInitialize(*vecs[v]);
        HYPRE_IJVectorSetValues(*vecs[v], (HYPRE_Int)n, rows, v == 0 ? r : zh);
        HYPRE_IJVectorAssemble(*vecs[v]);
        HYPRE_IJVectorGetObject(*vecs[v], &obj);
        *pars[v] = obj;
    }

    /* One cycle: hypre's z = M r from z = 0, and ours. */
    mf_pcg_boomeramg_settings s;
    defaults(&mf_pressure_PCG_BoomerAMG, &s);
    HYPRE_Solver amg = NULL;
    CHECK_OK(mf_boomeramg_create(&s, &amg));
    CHECK(HYPRE_BoomerAMGSetup(amg, parA, parr, parz) == 0);
    CHECK(HYPRE_BoomerAMGSolve(amg, parA, parr, parz) == 0);
    HYPRE_IJVectorGetValues(ijz, (HYPRE_Int)n, rows, zh);
    mf_amg_par *cycle = NULL;
    const char *why = NULL;
    CHECK_OK(mf_amg_par_take(amg, &cycle, &why));
    CHECK_MSG(cycle != NULL, "the default settings' hierarchy is not one our cycle runs: %s",
              why ? why : "?");
    if (cycle != NULL) {
        CHECK_OK(mf_amg_par_apply(cycle, parA, parr, paro));
        HYPRE_IJVectorGetValues(ijo, (HYPRE_Int)n, rows, zo);
        double dmax = 0.0, zmax = 0.0;
        for (size_t i = 0; i < n; i++) {
            dmax = fmax(dmax, fabs(zo[i] - zh[i]));
            zmax = fmax(zmax, fabs(zh[i]));
        }
        double m[2] = {dmax, zmax}, g[2];
        MPI_Allreduce(m, g, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        if (rank == 0)
            printf("own V-cycle against hypre's on %d ranks: max |difference| %.3g of max |z| "
                   "%.3g\n", nprocs, g[0], g[1]);
        CHECK_MSG(g[1] > 0.0 && g[0] <= 1e-12 * g[1], "V-cycles differ by %g (max |z| %g)", g[0],
                  g[1]);
    }
    mf_amg_par_free(cycle);
    HYPRE_BoomerAMGDestroy(amg);

    /* PCG: the module's (ours) against the module's with ownCycle no
     * (hypre's PCG and cycle), the same settings and tolerance. */
    make_rhs(&p);
    mf_solve_report own, hyp;
    memset(p.x, 0, n * sizeof *p.x);
    CHECK_OK(solve_once(&mf_pressure_PCG_BoomerAMG, &s, &p, &own));
    double *x_own = malloc((n + 1) * sizeof *x_own);
    memcpy(x_own, p.x, n * sizeof *x_own);
    const double err_own = rel_error(&p);
    mf_pcg_boomeramg_settings sh = s;
    sh.own_cycle = false;
    memset(p.x, 0, n * sizeof *p.x);
    CHECK_OK(solve_once(&mf_pressure_PCG_BoomerAMG, &sh, &p, &hyp));
    CHECK(own.converged && own.final_residual <= s.tolerance);
    CHECK(hyp.converged && hyp.final_residual <= s.tolerance);
    CHECK_MSG(abs(own.iterations - hyp.iterations) <= 2, "%d iterations against hypre's %d",
              own.iterations, hyp.iterations);
    CHECK(err_own <= kappa_poisson(NGRID) * 100 * own.final_residual);

    /* The serial solution: the whole matrix on each rank alone (hypre's PCG
     * and cycle on one rank: ours there is the same, test_own_vcycle). */
    poisson w;
    poisson_build_part(&w, NGRID, 0, 1);
    vary_coefficients(&w);
    const size_t N = w.A.nrows;
    HYPRE_IJMatrix wij = NULL;
    HYPRE_IJVector wb = NULL, wx = NULL;
    HYPRE_Int *wn = malloc((N + 1) * sizeof *wn);
    HYPRE_BigInt *wrows = malloc((N + 1) * sizeof *wrows);
    HYPRE_BigInt *wcols = malloc((w.A.rowptr[N] + 1) * sizeof *wcols);
    double *wbv = malloc((N + 1) * sizeof *wbv), *wxv = calloc(N + 1, sizeof *wxv);
    int *counts = malloc((size_t)nprocs * sizeof *counts);
    int *displs = malloc((size_t)nprocs * sizeof *displs);
    for (int q = 0; q < nprocs; q++) {
        displs[q] = (int)((int64_t)N * q / nprocs);
        counts[q] = (int)((int64_t)N * (q + 1) / nprocs) - displs[q];
    }
    MPI_Allgatherv(p.b, (int)n, MPI_DOUBLE, wbv, counts, displs, MPI_DOUBLE, MPI_COMM_WORLD);
    for (size_t i = 0; i < N; i++) {
        wrows[i] = (HYPRE_BigInt)i;
        wn[i] = (HYPRE_Int)(w.A.rowptr[i + 1] - w.A.rowptr[i]);
    }
    for (size_t k = 0; k < w.A.rowptr[N]; k++)
        wcols[k] = (HYPRE_BigInt)w.A.col[k];
    const HYPRE_BigInt wup = (HYPRE_BigInt)N - 1;
    HYPRE_IJMatrixCreate(MPI_COMM_SELF, 0, wup, 0, wup, &wij);
    HYPRE_IJMatrixSetObjectType(wij, HYPRE_PARCSR);
    HYPRE_IJMatrixInitialize(wij);
    HYPRE_IJMatrixSetValues(wij, (HYPRE_Int)N, wn, wrows, wcols, w.A.val);
    CHECK(HYPRE_IJMatrixAssemble(wij) == 0);
    HYPRE_IJMatrixGetObject(wij, &obj);
    HYPRE_ParCSRMatrix wA = obj;
    HYPRE_ParVector wpb = NULL, wpx = NULL;
    HYPRE_IJVector *wv[2] = {&wb, &wx};
    HYPRE_ParVector *wp[2] = {&wpb, &wpx};
    for (int v = 0; v < 2; v++) {
        HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, wup, wv[v]);
        HYPRE_IJVectorSetObjectType(*wv[v], HYPRE_PARCSR);
        HYPRE_IJVectorInitialize(*wv[v]);
        HYPRE_IJVectorSetValues(*wv[v], (HYPRE_Int)N, wrows, v == 0 ? wbv : wxv);
        HYPRE_IJVectorAssemble(*wv[v]);
        HYPRE_IJVectorGetObject(*wv[v], &obj);
        *wp[v] = obj;
    }
    HYPRE_Solver pcg = NULL;
    CHECK_OK(mf_boomeramg_create(&s, &amg));
    HYPRE_ParCSRPCGCreate(MPI_COMM_SELF, &pcg);
    HYPRE_PCGSetTol(pcg, s.tolerance);
    HYPRE_PCGSetMaxIter(pcg, 500);
    HYPRE_PCGSetTwoNorm(pcg, 1);
    HYPRE_PCGSetRecomputeResidual(pcg, 1);
    HYPRE_ParCSRPCGSetPrecond(pcg, HYPRE_BoomerAMGSolve, HYPRE_BoomerAMGSetup, amg);
    HYPRE_ParCSRPCGSetup(pcg, wA, wpb, wpx);
    CHECK(HYPRE_ParCSRPCGSolve(pcg, wA, wpb, wpx) == 0);
    HYPRE_Int its = 0;
    HYPRE_ParCSRPCGGetNumIterations(pcg, &its);
    HYPRE_IJVectorGetValues(wx, (HYPRE_Int)N, wrows, wxv);
    double d2 = 0.0, x2 = 0.0;
    for (size_t i = 0; i < n; i++) {
        const double xs = wxv[(size_t)p.A.row_offset + i];
        d2 += (x_own[i] - xs) * (x_own[i] - xs);
        x2 += xs * xs;
    }
    const double diff = sqrt(global_sum(d2) / global_sum(x2));
    /* Both residuals at most tol: each error at most kappa tol. */
    const double bound = 2.0 * kappa_poisson(NGRID) * s.tolerance;
    if (rank == 0)
        printf("PCG on %d ranks: %d iterations with our V-cycle, %d with hypre's, %d serially; "
               "|x - x_serial| / |x_serial| %.3g (bound %.3g)\n",
               nprocs, own.iterations, hyp.iterations, (int)its, diff, bound);
    CHECK_MSG(diff <= bound, "the solution on %d ranks is %g from the serial one", nprocs, diff);
    HYPRE_ParCSRPCGDestroy(pcg);
    HYPRE_BoomerAMGDestroy(amg);
    HYPRE_IJMatrixDestroy(wij);
    HYPRE_IJVectorDestroy(wb);
    HYPRE_IJVectorDestroy(wx);
    free(wn);
    free(wrows);
    free(wcols);
    free(wbv);
    free(wxv);
    free(counts);
    free(displs);
    poisson_free(&w);

    HYPRE_IJMatrixDestroy(ij);
    for (int v = 0; v < 3; v++)
        HYPRE_IJVectorDestroy(*vecs[v]);
    free(ncols);
    free(rows);
    free(cols);
    free(r);
    free(zh);
    free(zo);
    free(x_own);
    poisson_free(&p);
    omp_set_num_threads(saved_threads);
}

/* The view of rows already split (the diagonal, then lower columns, then
 * upper ones in order: the MPS rows) reads the CSR in place and holds what
 * the copy holds; one row out of that order makes it a copy. */
static void test_split_view(void)
{
    enum { N = 300, W = 7 };
    size_t rowptr[N + 1];
    int32_t col[N * (2 * W + 1)];
    double val[N * (2 * W + 1)];
    size_t k = 0;
    for (int i = 0; i < N; i++) {
        rowptr[i] = k;
        col[k] = i;
        val[k++] = 10.0 + (double)(i % 5);
        for (int j = i - W; j <= i + W; j++)
            if (j >= 0 && j < N && j != i && (i * 31 + j * 17) % 3 != 0) {
                col[k] = j;
                val[k++] = -1.0 / (1.0 + (double)((i + 2 * j) % 11));
            }
    }
    rowptr[N] = k;
    mf_csr A = {.nrows = N, .nglobal = N, .rowptr = rowptr, .col = col, .val = val};
    mf_split_csr copy = {0}, view = {0};
    CHECK_OK(mf_split_csr_set(&copy, &A));
    CHECK_OK(mf_split_csr_fine(&view, &A));
    CHECK_MSG(view.gap == 1 && view.col == col && view.val == val,
              "rows already split: the view should read them in place");
    size_t bad = 0;
    for (int32_t i = 0; i < N; i++) {
        const int32_t len = mf_split_end(&copy, i) - copy.ptr[i];
        bad += mf_split_end(&view, i) - view.ptr[i] != len ||
               view.mid[i] - view.ptr[i] != copy.mid[i] - copy.ptr[i] ||
               view.diag[i] != copy.diag[i] || view.dinv[i] != copy.dinv[i];
        for (int32_t e = 0; e < len && bad == 0; e++)
            bad += view.col[view.ptr[i] + e] != copy.col[copy.ptr[i] + e] ||
                   view.val[view.ptr[i] + e] != copy.val[copy.ptr[i] + e];
    }
    CHECK_MSG(bad == 0, "the view differs from the copy in %zu rows", bad);
    double p[N], q1[N], q2[N];
    for (int i = 0; i < N; i++)
        p[i] = sin(0.1 * i);
    const double d1 = mf_split_csr_matvec_dot(&copy, p, q1);
    const double d2 = mf_split_csr_matvec_dot(&view, p, q2);
    CHECK(d1 == d2 && memcmp(q1, q2, sizeof q1) == 0);
    /* Row 5 with an upper column before a lower one: a copy. */
    const size_t r5 = rowptr[5] + 1, last = rowptr[6] - 1;
    CHECK(col[r5] < 5 && col[last] > 5);
    int32_t c = col[r5];
    col[r5] = col[last];
    col[last] = c;
    mf_split_csr_free(&view);
    CHECK_OK(mf_split_csr_fine(&view, &A));
    CHECK_MSG(view.gap == 0 && view.col != col, "a row out of order must make a copy");
    mf_split_csr_free(&view);
    /* The same rows lent: split in them, the copy's layout, and put back. */
    int32_t col0[sizeof col / sizeof *col];
    double val0[sizeof val / sizeof *val];
    memcpy(col0, col, sizeof col);
    memcpy(val0, val, sizeof val);
    A.lent_capacity = k;
    mf_split_csr_free(&copy);
    CHECK_OK(mf_split_csr_set(&copy, &A));
    CHECK_OK(mf_split_csr_fine(&view, &A));
    CHECK_MSG(view.gap == 1 && view.col == col, "lent rows: the split should be made in them");
    for (int32_t i = 0; i < N; i++) {
        const int32_t len = mf_split_end(&copy, i) - copy.ptr[i];
        bad += mf_split_end(&view, i) - view.ptr[i] != len ||
               view.mid[i] - view.ptr[i] != copy.mid[i] - copy.ptr[i];
        for (int32_t e = 0; e < len && bad == 0; e++)
            bad += view.col[view.ptr[i] + e] != copy.col[copy.ptr[i] + e] ||
                   view.val[view.ptr[i] + e] != copy.val[copy.ptr[i] + e];
    }
    CHECK_MSG(bad == 0, "the split in place differs from the copy in %zu rows", bad);
    mf_split_csr_restore(&view);
    CHECK_MSG(memcmp(col, col0, sizeof col) == 0 && memcmp(val, val0, sizeof val) == 0,
              "the rows lent for the split did not come back as they were");
    mf_split_csr_free(&view);
    mf_split_csr_free(&copy);
}

/* The fingerprint that decides reuse: blind to values, not to the pattern. */
/* The split layout of rows in any column order, a diagonal given twice and
 * a row longer than the one-pass stage: lower entries then upper ones, each
 * in the row's order, the diagonal summed. */
static void test_split_layout(void)
{
    enum { N = 400 };
    size_t rowptr[N + 1];
    int32_t *col = malloc(4 * N * N * sizeof *col);
    double *val = malloc(4 * N * N * sizeof *val);
    size_t k = 0;
    unsigned long long seed = 7;
    for (int i = 0; i < N; i++) {
        rowptr[i] = k;
        const int len = i == 17 ? N : 1 + (int)(i % 9); /* row 17: every column */
        for (int e = 0; e < len; e++) {
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
            col[k] = i == 17 ? (int32_t)((e * 7919) % N) : (int32_t)((seed >> 33) % N);
            val[k++] = (double)(seed >> 40) / 16777216.0 + 0.5;
        }
        col[k] = i; /* a second diagonal entry */
        val[k++] = 2.0;
    }
    rowptr[N] = k;
    mf_csr A = {.nrows = N, .nglobal = N, .rowptr = rowptr, .col = col, .val = val};
    mf_split_csr sp = {0};
    CHECK_OK(mf_split_csr_set(&sp, &A));
    size_t bad = 0;
    for (int i = 0; i < N; i++) {
        int32_t q = sp.ptr[i];
        double d = 0.0;
        for (size_t e = rowptr[i]; e < rowptr[i + 1]; e++) /* lower, in order */
            if (col[e] < i)
                bad += q >= sp.mid[i] || sp.col[q] != col[e] || sp.val[q++] != val[e];
        bad += q != sp.mid[i];
        for (size_t e = rowptr[i]; e < rowptr[i + 1]; e++) { /* upper, in order */
            if (col[e] > i)
                bad += q >= sp.ptr[i + 1] || sp.col[q] != col[e] || sp.val[q++] != val[e];
            else if (col[e] == i)
                d += val[e];
        }
        bad += q != sp.ptr[i + 1] || sp.diag[i] != d || sp.dinv[i] != 1.0 / d;
    }
    CHECK_MSG(bad == 0, "the split layout differs from the rows in %zu places", bad);
    CHECK(sp.ptr[18] - sp.ptr[17] == N - 1); /* the long row: every column but its own */
    mf_split_csr_free(&sp);
    /* Lent, but rows with their diagonal last and twice: a copy, the rows
     * untouched. */
    int32_t *col0 = malloc(k * sizeof *col0);
    memcpy(col0, col, k * sizeof *col0);
    A.lent_capacity = k;
    CHECK_OK(mf_split_csr_fine(&sp, &A));
    CHECK(sp.gap == 0 && memcmp(col0, col, k * sizeof *col0) == 0);
    mf_split_csr_free(&sp);
    free(col0);
    free(col);
    free(val);
}

static void test_pattern_hash(void)
{
    poisson p, q;
    poisson_build(&p, 16);
    poisson_build(&q, 17);
    uint64_t h0, h1, h2, h3;
    CHECK_OK(mf_hypre_pattern_hash(&p.A, &h0));
    for (size_t k = 0; k < p.A.rowptr[p.A.nrows]; k++)
        p.A.val[k] *= 3.0;
    CHECK_OK(mf_hypre_pattern_hash(&p.A, &h1));
    CHECK(h1 == h0);
    /* Move one off-diagonal entry of the last row to another column. */
    const size_t last = p.A.rowptr[p.A.nrows] - 1;
    const int64_t saved = p.A.col[last];
    p.A.col[last] = p.A.col[last] == 0 ? 1 : 0;
    CHECK_OK(mf_hypre_pattern_hash(&p.A, &h2));
    CHECK(h2 != h0);
    p.A.col[last] = saved;
    CHECK_OK(mf_hypre_pattern_hash(&q.A, &h3));
    CHECK(h3 != h0);
    poisson_free(&p);
    poisson_free(&q);
}

/* Bad input: clear errors, nothing from hypre. */
static void test_bad_input(void)
{
    mf_pcg_diagonal_settings ds;
    defaults(&mf_pressure_PCG_diagonal, &ds);
    mf_pcg_boomeramg_settings as;
    defaults(&mf_pressure_PCG_BoomerAMG, &as);
    mf_solve_report rep;
    poisson p;
    poisson_build(&p, 8);
    make_rhs(&p);

    /* A column outside the matrix (on rank 0; the other ranks agree to fail). */
    int64_t saved = p.A.col[0];
    if (rank == 0)
        p.A.col[0] = p.A.nglobal + 5;
    mf_error_clear();
    CHECK(solve_once(&mf_pressure_PCG_BoomerAMG, &as, &p, &rep) == MF_ERR_INPUT);
    if (rank == 0)
        CHECK(strstr(mf_error_message(), "outside") != NULL);
    mf_error_clear();
    p.A.col[0] = saved;
    /* A negative one, at the last entry (the range check's tail). */
    const size_t last = p.A.rowptr[p.A.nrows] - 1;
    saved = p.A.col[last];
    if (rank == 0)
        p.A.col[last] = -1;
    CHECK(solve_once(&mf_pressure_PCG_BoomerAMG, &as, &p, &rep) == MF_ERR_INPUT);
    if (rank == 0)
        CHECK(strstr(mf_error_message(), "outside") != NULL);
    mf_error_clear();
    p.A.col[last] = saved;

    /* More rows than a 32-bit HYPRE_BigInt holds. */
    if (sizeof(HYPRE_BigInt) == 4 && nprocs == 1) {
        mf_csr big = p.A;
        big.nglobal = (int64_t)1 << 33;
        CHECK(solve_once(&mf_pressure_PCG_diagonal, &ds, &(poisson){.A = big, .b = p.b, .x = p.x},
                         &rep) == MF_ERR_INPUT);
        CHECK(strstr(mf_error_message(), "HYPRE_BigInt") != NULL);
        mf_error_clear();
    }

    /* NaN in the right-hand side. */
    double b0 = p.b[0];
    if (rank == 0)
        p.b[0] = NAN;
    CHECK(solve_once(&mf_pressure_PCG_diagonal, &ds, &p, &rep) == MF_ERR_NUMERIC);
    mf_error_clear();
    p.b[0] = b0;

    /* A zero diagonal entry: diagonal scaling cannot work. */
    for (size_t k = p.A.rowptr[0]; k < p.A.rowptr[1]; k++)
        if (p.A.col[k] == p.A.row_offset)
            p.A.val[k] = 0.0;
    memset(p.x, 0, p.A.nrows * sizeof *p.x);
    int rc = solve_once(&mf_pressure_PCG_diagonal, &ds, &p, &rep);
    CHECK_MSG(rc == MF_ERR_NUMERIC, "rc %d", rc);
    mf_error_clear();
    poisson_free(&p);
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    HYPRE_Init();
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &nprocs);

    test_tables();

    mf_pcg_boomeramg_settings as;
    defaults(&mf_pressure_PCG_BoomerAMG, &as);
    mf_pcg_diagonal_settings ds;
    defaults(&mf_pressure_PCG_diagonal, &ds);

    test_accuracy(&mf_pressure_PCG_BoomerAMG, &as, &as.tolerance);
    test_accuracy(&mf_pressure_PCG_diagonal, &ds, &ds.tolerance);
    as.tolerance = ds.tolerance = 1e-8;
    test_amg_beats_diagonal();
    test_not_converged(&mf_pressure_PCG_BoomerAMG, &as, &as.max_iter);
    test_not_converged(&mf_pressure_PCG_diagonal, &ds, &ds.max_iter);
    test_zero_rhs(&mf_pressure_PCG_BoomerAMG, &as);
    test_zero_rhs(&mf_pressure_PCG_diagonal, &ds);
    test_warm_start(&mf_pressure_PCG_BoomerAMG, &as);
    test_warm_start(&mf_pressure_PCG_diagonal, &ds);
    test_reuse();
    test_named_rows();
    test_lent_rows();
    test_own_vcycle();
    test_own_vcycle_ranks();
    test_split_layout();
    test_split_view();
    test_pattern_hash();
    test_bad_input();

    int status = mf_test_summary("pressure");
    /* Fail on every rank if any rank failed. */
    int any = status != EXIT_SUCCESS, all = 0;
    MPI_Allreduce(&any, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    HYPRE_Finalize();
    MPI_Finalize();
    return all ? EXIT_FAILURE : EXIT_SUCCESS;
}
