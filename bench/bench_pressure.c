/* bench_pressure: setup and solve times of the hypre pressure solvers on
 * MPS-like pressure matrices.
 *
 *   bench_pressure          3-D 100,000 and 1,000,000 unknowns, 2-D 5,000
 *   bench_pressure small    without the 1,000,000 case
 *
 * The matrix mimics the MPS pressure Poisson equation on a lattice of
 * particles (spacing 1) filling a tank: every pair closer than r_e (2.1
 * spacings in 3-D, 32 neighbours; 3.1 in 2-D, 28 neighbours) is coupled
 * with the MPS weight w = r_e / r - 1: a_ij = -w_ij, and
 * a_ii = sum_j w_ij over the neighbours that are unknowns, plus the weights
 * of the neighbours beyond the free surface (the top face). Those are the
 * Dirichlet particles (p = 0) of MPS: a small shift of the diagonal on the
 * top layers only, which is what makes the matrix definite. The walls and
 * the bottom are Neumann (neighbours simply missing). The right-hand side
 * is rough (deterministic noise in [-1, 1], as the density-deviation source
 * term of MPS is); zero initial guess; relative tolerance 1e-8.
 *
 * Rows are split over the MPI ranks in lexicographic blocks (mpirun works;
 * timings are from rank 0).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <HYPRE_config.h>
#include <HYPRE_utilities.h>
#include <mpi.h>

#include "mf_error.h"
#include "mf_params.h"
#include "pressure/pressure_hypre.h"

#define TOLERANCE 1e-8

static int rank = 0, nprocs = 1;

static void die(const char *what)
{
    fprintf(stderr, "bench_pressure: %s failed\n", what);
    mf_error_print(stderr);
    MPI_Abort(MPI_COMM_WORLD, 1);
}

typedef struct lattice_case {
    const char *label;
    int dim, n[3];
    double re; /* interaction radius in spacings */
    double strong_threshold; /* AMG: 0.25 in 2-D, 0.5 in 3-D */
} lattice_case;

typedef struct offset {
    int d[3];
    double w;
} offset;

/* Build this rank's rows of the lattice matrix and a rough right-hand side. */
static void build(const lattice_case *c, mf_csr *A, double **b)
{
    const int nx = c->n[0], ny = c->n[1], nz = c->dim == 3 ? c->n[2] : 1;
    const int64_t N = (int64_t)nx * ny * nz;
    const int R = (int)floor(c->re);
    offset off[512];
    int noff = 0;
    for (int k = c->dim == 3 ? -R : 0; k <= (c->dim == 3 ? R : 0); k++)
        for (int j = -R; j <= R; j++)
            for (int i = -R; i <= R; i++) {
                const double r = sqrt((double)(i * i + j * j + k * k));
                if (r == 0.0 || r >= c->re)
                    continue;
                off[noff++] = (offset){{i, j, k}, c->re / r - 1.0};
            }

    const int64_t lo = N * rank / nprocs, hi = N * (rank + 1) / nprocs;
    const size_t nrows = (size_t)(hi - lo);
    memset(A, 0, sizeof *A);
    A->nrows = nrows;
    A->row_offset = lo;
    A->nglobal = N;
    A->rowptr = malloc((nrows + 1) * sizeof *A->rowptr);
    A->col = malloc(nrows * (size_t)(noff + 1) * sizeof *A->col);
    A->val = malloc(nrows * (size_t)(noff + 1) * sizeof *A->val);
    *b = malloc((nrows + 1) * sizeof **b);
    if (!A->rowptr || !A->col || !A->val || !*b)
        die("allocating the matrix");

    /* The vertical axis: z in 3-D, y in 2-D. Beyond its top is the free surface. */
    const int up = c->dim == 3 ? 2 : 1;
    size_t k = 0;
    for (size_t r = 0; r < nrows; r++) {
        const int64_t g = lo + (int64_t)r;
        const int p[3] = {(int)(g % nx), (int)(g / nx % ny), (int)(g / ((int64_t)nx * ny))};
        const int size[3] = {nx, ny, nz};
        double diag = 0.0;
        A->rowptr[r] = k;
        size_t kdiag = k++; /* the diagonal first; its value is known at the end */
        A->col[kdiag] = g;
        for (int o = 0; o < noff; o++) {
            int q[3];
            bool inside = true, above = false;
            for (int a = 0; a < 3; a++) {
                q[a] = p[a] + off[o].d[a];
                if (q[a] < 0 || q[a] >= size[a])
                    inside = false;
            }
            above = q[up] >= size[up];
            if (inside) {
                A->col[k] = q[0] + (int64_t)nx * (q[1] + (int64_t)ny * q[2]);
                A->val[k++] = -off[o].w;
                diag += off[o].w;
            } else if (above) {
                bool others_inside = true;
                for (int a = 0; a < 3; a++)
                    if (a != up && (q[a] < 0 || q[a] >= size[a]))
                        others_inside = false;
                if (others_inside)
                    diag += off[o].w; /* a Dirichlet (free-surface) neighbour */
            }
        }
        A->val[kdiag] = diag;
        uint64_t h = (uint64_t)(g + 1) * 0x9E3779B97F4A7C15ull;
        h ^= h >> 31;
        h *= 0xBF58476D1CE4E5B9ull;
        h ^= h >> 27;
        (*b)[r] = (double)(h % 2000001) / 1000000.0 - 1.0;
    }
    A->rowptr[nrows] = k;
}

static void free_case(mf_csr *A, double *b)
{
    free(A->rowptr);
    free(A->col);
    free(A->val);
    free(b);
}

typedef struct result {
    double setup, solve, residual;
    int iterations;
    int rc;
} result;

static result run(const mf_pressure_ops *ops, const void *settings, const mf_csr *A,
                  const double *b, int repeats)
{
    result best = {0};
    double *x = malloc((A->nrows + 1) * sizeof *x);
    if (!x)
        die("allocating x");
    for (int t = 0; t < repeats; t++) {
        void *data = NULL;
        mf_solve_report rep;
        if (ops->create(settings, &data))
            die(ops->info.name);
        memset(x, 0, A->nrows * sizeof *x);
        int rc = ops->solve(data, A, b, x, &rep);
        ops->destroy(data);
        if (rc < 0)
            die(ops->info.name);
        if (rc > 0)
            mf_error_clear();
        /* The fastest of the repeats: the others measured interference. */
        if (t == 0 || rep.setup_seconds + rep.solve_seconds < best.setup + best.solve)
            best = (result){rep.setup_seconds, rep.solve_seconds, rep.final_residual,
                            rep.iterations, rc};
    }
    free(x);
    return best;
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    HYPRE_Init();
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
    const bool small = argc > 1 && strcmp(argv[1], "small") == 0;

    const lattice_case cases[] = {
        {"3-D 50x50x40, r_e 2.1", 3, {50, 50, 40}, 2.1, 0.5},
        {"3-D 100x100x100, r_e 2.1", 3, {100, 100, 100}, 2.1, 0.5},
        {"2-D 100x50, r_e 3.1", 2, {100, 50, 1}, 3.1, 0.25},
    };

    if (rank == 0) {
        printf("bench_pressure: hypre %s, %d MPI rank(s), relative tolerance %g, zero guess\n",
               HYPRE_RELEASE_VERSION, nprocs, TOLERANCE);
        printf("setup = checks + IJ assembly + preconditioner setup; solve = PCG + residual check\n\n");
        printf("%-26s %9s %7s  %-30s %9s %9s %6s %10s\n", "matrix", "unknowns", "nnz/row",
               "solver", "setup s", "solve s", "iters", "residual");
    }
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        if (small && cases[c].n[0] * cases[c].n[1] * cases[c].n[2] >= 1000000)
            continue;
        mf_csr A;
        double *b = NULL;
        build(&cases[c], &A, &b);
        double nnz_local = (double)A.rowptr[A.nrows], nnz = 0.0;
        MPI_Allreduce(&nnz_local, &nnz, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
        const int repeats = A.nglobal >= 1000000 ? 1 : 3;

        for (int variant = 0; variant < 3; variant++) {
            const mf_pressure_ops *ops;
            char name[64];
            union {
                mf_pcg_boomeramg_settings amg;
                mf_pcg_diagonal_settings diag;
            } s;
            if (variant < 2) {
                ops = &mf_pressure_PCG_BoomerAMG;
                if (mf_params_defaults(ops->info.params, ops->info.nparams, &s.amg))
                    die("mf_params_defaults");
                s.amg.tolerance = TOLERANCE;
                s.amg.strong_threshold = cases[c].strong_threshold;
                s.amg.aggressive_levels = variant;
                snprintf(name, sizeof name, "PCG_BoomerAMG agg %d thr %.2f", variant,
                         cases[c].strong_threshold);
            } else {
                ops = &mf_pressure_PCG_diagonal;
                if (mf_params_defaults(ops->info.params, ops->info.nparams, &s.diag))
                    die("mf_params_defaults");
                s.diag.tolerance = TOLERANCE;
                s.diag.max_iter = 20000; /* report the count, however large */
                snprintf(name, sizeof name, "PCG_diagonal");
            }
            result r = run(ops, &s, &A, b, repeats);
            if (rank == 0) {
                printf("%-26s %9lld %7.1f  %-30s %9.3f %9.3f %6d %10.2e%s\n", cases[c].label,
                       (long long)A.nglobal, nnz / (double)A.nglobal, name, r.setup, r.solve,
                       r.iterations, r.residual, r.rc ? "  NOT CONVERGED" : "");
                fflush(stdout);
            }
        }
        free_case(&A, b);
    }
    HYPRE_Finalize();
    MPI_Finalize();
    return 0;
}
