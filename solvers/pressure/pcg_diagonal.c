/* pcg_diagonal.c: PCG_diagonal, conjugate gradients with diagonal (Jacobi)
 * scaling (hypre). No setup cost and cheap iterations, but the iteration
 * count grows with the resolution (like the square root of the condition
 * number): the baseline PCG_BoomerAMG is measured against.
 */
#define MF_PRESSURE_HYPRE_INTERNAL
#include "pressure_hypre.h"

#include <inttypes.h>
#include <stdlib.h>

#include "mf_error.h"

static const char module_name[] = "PCG_diagonal";

#define P(field) offsetof(mf_pcg_diagonal_settings, field)
static const mf_param params[] = {
    {"tolerance", MF_PARAM_SCALAR, "1e-8", 1e-16, 1.0, NULL, P(tolerance),
     "relative residual ||b - A x|| / ||b|| to reach"},
    {"maxIter", MF_PARAM_INT, "500", 1, 1e7, NULL, P(max_iter),
     "PCG iteration limit (not converged by then: the step is retried)"},
};
#undef P

static int pcg_diagonal_create(const void *settings, void **data)
{
    const mf_pcg_diagonal_settings *s = settings;
    *data = NULL;
    if (s == NULL)
        return MF_ERROR(MF_ERR_INPUT, "%s: no settings", module_name);
    MF_CALL(mf_hypre_check_pcg_settings(module_name, s->tolerance, s->max_iter));
    mf_pcg_diagonal_settings *d = malloc(sizeof *d);
    if (d == NULL)
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory", module_name);
    *d = *s;
    *data = d;
    return 0;
}

/* Scaling by 1/a_ii needs a positive diagonal (as any SPD matrix has); say
 * which row breaks that rather than let hypre divide by zero. */
static int precond_prepare(void *ctx, const mf_csr *A, const mf_row_names *rows, mf_hypre_precond *pc)
{
    (void)ctx;
    (void)rows;
    for (size_t i = 0; i < A->nrows; i++) {
        const int64_t row = A->row_offset + (int64_t)i;
        double diag = 0.0;
        for (size_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            if (A->col[k] == row)
                diag += A->val[k];
        if (!(diag > 0.0))
            return MF_ERROR(MF_ERR_NUMERIC,
                            "%s: diagonal entry %g of row %" PRId64
                            " is not positive (the matrix must be SPD)",
                            module_name, diag, row);
    }
    *pc = (mf_hypre_precond){HYPRE_ParCSRDiagScale, HYPRE_ParCSRDiagScaleSetup, NULL, NULL, NULL};
    return 0;
}

static int pcg_diagonal_solve(void *data, const mf_csr *A, const double *b, double *x,
                              mf_solve_report *rep)
{
    const mf_pcg_diagonal_settings *s = data;
    const mf_hypre_pcg pcg = {
        .name = module_name,
        .tolerance = s->tolerance,
        .max_iter = s->max_iter,
        .rows = NULL,
        .precond_prepare = precond_prepare,
        .precond_release = NULL,
        .ctx = NULL,
    };
    MF_CALL(mf_hypre_pcg_solve(&pcg, A, b, x, rep));
    return 0;
}

static void pcg_diagonal_destroy(void *data) { free(data); }

const mf_pressure_ops mf_pressure_PCG_diagonal = {
    .info = {MF_ABI_VERSION, MF_KIND_PRESSURE, "PCG_diagonal",
             "conjugate gradients with diagonal scaling (hypre); the cheap baseline", params,
             sizeof params / sizeof *params, sizeof(mf_pcg_diagonal_settings)},
    .create = pcg_diagonal_create,
    .solve = pcg_diagonal_solve,
    .destroy = pcg_diagonal_destroy,
};
