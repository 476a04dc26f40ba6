/* test_ppe: the pressure Poisson matrix of the MPS solver (mps_ppe.c, eq.
 * 14), assembled by the pair engine, against a brute-force assembly.
 *
 * A tank of fluid with a free surface, walls and dummy layers (2-D and 3-D),
 * the fluid moved a little so that n* differs from n0, through the solver's
 * own phases (neighbours, masks, surface, assembly). Checked:
 *   - the unknowns are the non-dummy particles off the free surface, one row
 *     each, the diagonal first;
 *   - A_ij = -c w_ij for the unknown neighbours within re (c = 2d/(lambda
 *     n0)), in the neighbour list's order, and A is symmetric;
 *   - a Dirichlet row (beside the free surface) keeps the missing
 *     neighbours' c w_ij on its diagonal: A_ii - sum_j |A_ij| equals the sum
 *     over its Dirichlet neighbours, and it is strictly diagonally dominant;
 *   - rhs_i = relaxation (rho/dt^2) (n*_i - n0)/n0;
 * and with a density per particle and a pressure held on the Dirichlet
 * particles (the multi-fluid solver's case): A_ij = -c w_ij / rho_ij, still
 * symmetric, and rhs_i gains sum_j c w_ij p_j / rho_ij over them. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_modules.h"
#include "mf_solvers.h"
#include "mf_test.h"
#include "solver/mps/mps.h"

static unsigned long long rng = 99991;
static double uniform(void)
{
    rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}

#define L0 0.01

typedef struct world {
    mf_registry *reg;
    mf_log log;
    mf_sim sim;
    mf_module solver;
} world;

/* A tank m wide (and deep in 3-D) with fluid up to height h: two dummy
 * layers and a wall layer at the sides and the floor, nothing on top. */
static void build_tank(world *w, int dim, int m, int h)
{
    memset(w, 0, sizeof *w);
    CHECK_OK(mf_registry_create(&w->reg));
    CHECK_OK(mf_solvers_register_all(w->reg));
    mf_log_init(&w->log, stdout, MF_LOG_QUIET);
    mf_sim *sim = &w->sim;
    sim->dim = dim;
    sim->l0 = L0;
    sim->reg = w->reg;
    sim->log = &w->log;
    sim->nfluids = 1;
    snprintf(sim->fluid[0].name, sizeof sim->fluid[0].name, "water");
    sim->fluid[0].rho = 1000;
    sim->fluid[0].nu = 1e-6;
    CHECK_OK(mf_particles_create(dim, 4096, &sim->p));
    CHECK_OK(mf_neighbours_create(&sim->neighbours));
    const int mz = dim == 3 ? m : 1;
    for (int k = 0; k < mz; k++)
        for (int j = 0; j < h; j++)
            for (int i = 0; i < m; i++) {
                const int edge_x = i < 3 ? i : m - 1 - i < 3 ? m - 1 - i : 3;
                const int edge_z = dim == 3 ? (k < 3 ? k : mz - 1 - k < 3 ? mz - 1 - k : 3) : 3;
                int layer = j < edge_x ? j : edge_x;
                layer = edge_z < layer ? edge_z : layer;
                int kind = layer < 2 ? MF_DUMMY : layer == 2 ? MF_WALL : MF_FLUID;
                double x[3] = {i * L0, j * L0, dim == 3 ? k * L0 : 0}, v[3] = {0, 0, 0};
                if (kind == MF_FLUID)
                    for (int c = 0; c < dim; c++)
                        x[c] += 0.02 * L0 * (uniform() - 0.5); /* r*: not the lattice */
                CHECK_OK(mf_particles_add(sim->p, kind, x, v, NULL));
            }
    /* The solver as a case would make it (defaults: radii 3.1, 2.1, 3.1 l0). */
    CHECK_OK(mf_module_prepare(w->reg, MF_KIND_SOLVER, "MPS", NULL, NULL, NULL, &w->solver));
    /* The paper's scheme: the brute-force assembly below is eqs. 14 and 18 as
     * printed (the default scheme adds the asymmetry test and its own source). */
    ((mps_settings *)w->solver.settings)->scheme = "paper";
    const mf_solver_ops *ops = (const mf_solver_ops *)w->solver.info;
    CHECK_OK(ops->create(w->solver.settings, sim, NULL, &w->solver.data));
}

static void free_tank(world *w)
{
    const mf_solver_ops *ops = (const mf_solver_ops *)w->solver.info;
    if (w->solver.data)
        ops->destroy(w->solver.data);
    mf_module_release(&w->solver);
    mf_particles_destroy(w->sim.p);
    mf_neighbours_destroy(w->sim.neighbours);
    mf_registry_destroy(w->reg);
}

static double weight_of(const mf_particles *p, size_t i, size_t j, double re)
{
    double r[3];
    for (int c = 0; c < 3; c++)
        r[c] = p->pos[3 * j + c] - p->pos[3 * i + c];
    return mf_weight(sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]), re);
}

/* The entry of row r in column col, and whether there is one. */
static bool entry(const mf_csr *A, size_t r, int64_t col, double *val)
{
    for (size_t k = A->rowptr[r]; k < A->rowptr[r + 1]; k++)
        if (A->col[k] == col) {
            *val = A->val[k];
            return true;
        }
    return false;
}

static void check_matrix(world *w, bool variable_density, const char *what)
{
    mf_sim *sim = &w->sim;
    mps_data *d = w->solver.data;
    mf_particles *p = sim->p;
    const size_t n = p->n;
    const double dt = 1e-4;
    double *rho = NULL, *pd = NULL;
    CHECK_OK(mps_reserve(d, n));
    CHECK_OK(mps_build_neighbours(d, sim, false));
    mps_set_masks(d, p);
    if (variable_density) { /* two fluids: every other column heavy */
        rho = malloc(n * sizeof *rho);
        pd = malloc(n * sizeof *pd);
        for (size_t i = 0; i < n; i++) {
            rho[i] = ((int)lround(p->pos[3 * i] / L0)) % 2 ? 1000.0 : 1.2;
            pd[i] = 100 * uniform();
        }
        d->rho = rho;
        d->rho_average = MF_AVERAGE_HARMONIC;
        d->p_dirichlet = pd;
    }
    CHECK_OK(mps_surface_phase(d, sim));
    CHECK_OK(mps_assemble_ppe(d, sim, dt));
    const mf_csr *A = &d->A;
    const double *nd = mf_particles_fd(p, d->f_number_density);
    const double re = d->k_lap.re, c = 2.0 * d->k_lap.dim / (d->k_lap.lambda * d->k_lap.n0);
    const double n0 = d->k_nd.n0;

    size_t unknowns = 0, surface = 0, bad_rows = 0, asym = 0, bad_dirichlet = 0, bad_rhs = 0,
           dominant = 0, beside_surface = 0;
    for (size_t i = 0; i < n; i++) {
        const bool dummy = p->kind[i] == MF_DUMMY;
        /* eq. 18: the free surface, from the number density at r* */
        double ni = 0;
        for (size_t j = 0; j < n; j++)
            if (j != i)
                ni += mf_weight(sqrt(pow(p->pos[3 * j] - p->pos[3 * i], 2) +
                                     pow(p->pos[3 * j + 1] - p->pos[3 * i + 1], 2) +
                                     pow(p->pos[3 * j + 2] - p->pos[3 * i + 2], 2)),
                                d->k_nd.re);
        const bool free_surface = !dummy && ni < d->s.beta * n0;
        const bool unknown = !dummy && !free_surface;
        surface += free_surface;
        if (!unknown) {
            bad_rows += d->row[i] != -1;
            continue;
        }
        CHECK_NEAR(nd[i], ni, 1e-9 * n0);
        if (d->row[i] != (long)unknowns) {
            bad_rows++;
            continue;
        }
        const size_t r = unknowns++;
        bool ok = A->col[A->rowptr[r]] == A->row_offset + (int64_t)r;
        double diag = 0, off = 0, held = 0, known = 0;
        size_t cols = 1;
        for (size_t j = 0; j < n; j++) {
            if (j == i || p->kind[j] == MF_DUMMY)
                continue;
            const double wij = weight_of(p, i, j, re);
            if (!(wij > 0))
                continue;
            double a = c * wij;
            if (variable_density)
                a *= 0.5 * (1.0 / rho[i] + 1.0 / rho[j]);
            diag += a;
            double v = 0;
            if (d->row[j] >= 0) {
                cols++;
                off += a;
                ok = ok && entry(A, r, A->row_offset + d->row[j], &v) &&
                     fabs(v + a) <= 1e-12 * a;
                /* symmetric: the same value in row j, column i */
                double t = 0;
                asym += !(entry(A, (size_t)d->row[j], A->row_offset + (int64_t)r, &t) && t == v);
            } else {
                held += a;
                known += a * (variable_density ? pd[j] : 0.0);
            }
        }
        ok = ok && cols == A->rowptr[r + 1] - A->rowptr[r];
        const double aii = A->val[A->rowptr[r]];
        ok = ok && fabs(aii - diag) <= 1e-12 * diag;
        bad_rows += !ok;
        /* The Dirichlet neighbours' share stays on the diagonal. */
        bad_dirichlet += !(fabs((aii - off) - held) <= 1e-10 * diag);
        if (held > 0) {
            beside_surface++;
            dominant += aii > off;
        }
        const double rho0 = sim->fluid[0].rho;
        const double want = variable_density
                                ? d->sc.relaxation / (dt * dt) * (nd[i] - n0) / n0 + known
                                : d->sc.relaxation * rho0 / (dt * dt) * (nd[i] - n0) / n0;
        bad_rhs += !(fabs(d->rhs[r] - want) <= 1e-9 * (fabs(want) + rho0 / (dt * dt) * 1e-9));
    }
    CHECK_MSG(unknowns == A->nrows && unknowns > 0, "%s: %zu unknowns, %zu rows", what,
              unknowns, A->nrows);
    CHECK_MSG(surface > 0 && beside_surface > 0, "%s: %zu free-surface particles, %zu rows "
              "beside them", what, surface, beside_surface);
    CHECK_MSG(bad_rows == 0, "%s: %zu rows differ from the brute-force assembly", what, bad_rows);
    CHECK_MSG(asym == 0, "%s: %zu entries not symmetric", what, asym);
    CHECK_MSG(bad_dirichlet == 0, "%s: %zu rows lose their Dirichlet neighbours' share", what,
              bad_dirichlet);
    CHECK_MSG(dominant == beside_surface, "%s: %zu of %zu rows beside the surface strictly "
              "diagonally dominant", what, dominant, beside_surface);
    CHECK_MSG(bad_rhs == 0, "%s: %zu right-hand sides wrong", what, bad_rhs);
    printf("%s: %zu unknowns, %zu free-surface particles, %zu rows beside them, %zu entries\n",
           what, unknowns, surface, beside_surface, A->rowptr[A->nrows]);
    d->rho = NULL;
    d->p_dirichlet = NULL;
    free(rho);
    free(pd);
}

int main(void)
{
    world w;
    build_tank(&w, 2, 24, 16);
    check_matrix(&w, false, "2-D tank");
    check_matrix(&w, true, "2-D tank, density per particle");
    free_tank(&w);
    build_tank(&w, 3, 11, 10);
    check_matrix(&w, false, "3-D tank");
    free_tank(&w);
    return mf_test_summary("ppe");
}
