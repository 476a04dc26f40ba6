/* test_operators.c: the MPS operators against analytic fields.
 *
 * On a full square (2-D) or cubic (3-D) lattice the operators are exact for
 * an interior particle: n = n0, the gradient of a linear field, the
 * divergence of a linear velocity and the Laplacian of a quadratic are
 * reproduced to round-off (the lattice's symmetry cancels the odd moments,
 * and lambda is defined on the same lattice). On a jittered lattice they are
 * not exact; the measured error is printed, and must shrink as the jitter
 * does (first order in the jitter amplitude). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_kernel.h"
#include "mf_neighbours.h"
#include "mf_operators.h"
#include "mf_test.h"

static unsigned long long rng = 12345;
static double uniform(void) /* deterministic, in [-1, 1) */
{
    rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
    return ((rng >> 11) * (1.0 / 9007199254740992.0)) * 2.0 - 1.0;
}

static mf_particles *lattice(int dim, int m, double l0, double jitter)
{
    mf_particles *p = NULL;
    if (mf_particles_create(dim, 1024, &p) != 0)
        return NULL;
    int mz = dim == 3 ? m : 1;
    for (int k = 0; k < mz; k++)
        for (int j = 0; j < m; j++)
            for (int i = 0; i < m; i++) {
                double x[3] = {i * l0, j * l0, dim == 3 ? k * l0 : 0};
                for (int c = 0; c < dim; c++)
                    x[c] += jitter * l0 * uniform();
                double v[3] = {0, 0, 0};
                mf_particles_add(p, MF_FLUID, x, v, NULL);
            }
    return p;
}

typedef struct errors {
    double nd, grad, div, lap;
} errors;

/* Relative errors at the particles farther than re from the lattice edge. */
static errors measure(int dim, int m, double re_l0, double jitter, bool print, int shape)
{
    const double l0 = 0.01;
    mf_particles *p = lattice(dim, m, l0, jitter);
    mf_kernel k;
    CHECK_OK(mf_kernel_init(&k, dim, l0, re_l0 * l0));
    CHECK_OK(mf_kernel_set_gradient_weight(&k, shape)); /* eq. 5 only */
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    CHECK_OK(mf_grid_build(&g, p, k.re));
    CHECK_OK(mf_nlist_build(&nl, &g, p, k.re));
    size_t n = p->n;
    double *f = malloc(n * sizeof *f), *q = malloc(n * sizeof *q), *u = malloc(3 * n * sizeof *u);
    double *nd = malloc(n * sizeof *nd), *grad = malloc(3 * n * sizeof *grad),
           *div = malloc(n * sizeof *div), *lap = malloc(n * sizeof *lap);
    const double a[3] = {2.0, -3.0, 0.5};
    for (size_t i = 0; i < n; i++) {
        const double *x = &p->pos[3 * i];
        f[i] = 1.0 + a[0] * x[0] + a[1] * x[1] + (dim == 3 ? a[2] * x[2] : 0); /* linear */
        q[i] = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];                     /* lap q = 2d */
        u[3 * i] = x[0];
        u[3 * i + 1] = x[1];
        u[3 * i + 2] = x[2]; /* div u = d */
    }
    const mf_pairs v = mf_pairs_of_list(p, &nl, k.re);
    mf_number_density(&v, NULL, NULL, nd);
    mf_gradient(&v, &k, f, false, NULL, NULL, grad);
    mf_divergence(&v, &k, u, NULL, NULL, div);
    mf_laplacian(&v, &k, q, 1, NULL, NULL, lap);
    errors e = {0, 0, 0, 0};
    const double margin = (ceil(re_l0) + 1) * l0, hi = (m - 1) * l0 - margin;
    size_t counted = 0;
    for (size_t i = 0; i < n; i++) {
        const double *x = &p->pos[3 * i];
        bool interior = true;
        for (int c = 0; c < dim; c++)
            interior = interior && x[c] > margin && x[c] < hi;
        if (!interior)
            continue;
        counted++;
        double ge = 0, gn = 0;
        for (int c = 0; c < dim; c++) {
            ge += (grad[3 * i + c] - a[c]) * (grad[3 * i + c] - a[c]);
            gn += a[c] * a[c];
        }
        e.nd = fmax(e.nd, fabs(nd[i] - k.n0) / k.n0);
        e.grad = fmax(e.grad, sqrt(ge / gn));
        e.div = fmax(e.div, fabs(div[i] - dim) / dim);
        e.lap = fmax(e.lap, fabs(lap[i] - 2.0 * dim) / (2.0 * dim));
    }
    CHECK(counted > 0);
    if (print)
        printf("%d-D re = %.1f l0, jitter %.3f l0, gradient weight %d, %zu interior particles: "
               "max relative error n %.2e, grad %.2e, div %.2e, lap %.2e\n",
               dim, re_l0, jitter, shape, counted, e.nd, e.grad, e.div, e.lap);
    free(f); free(q); free(u); free(nd); free(grad); free(div); free(lap);
    mf_grid_free(&g);
    mf_nlist_free(&nl);
    mf_particles_destroy(p);
    return e;
}

static void test_kernel_constants(void)
{
    /* 2-D square lattice, re = 2.1 l0: the 12 neighbours within 2.1 l0 are
     * 4 at l0, 4 at sqrt(2) l0, 4 at 2 l0. */
    mf_kernel k;
    CHECK_OK(mf_kernel_init(&k, 2, 1.0, 2.1));
    double n0 = 4 * (2.1 - 1) + 4 * (2.1 / sqrt(2) - 1) + 4 * (2.1 / 2 - 1);
    double lam = (4 * 1 * (2.1 - 1) + 4 * 2 * (2.1 / sqrt(2) - 1) + 4 * 4 * (2.1 / 2 - 1)) / n0;
    CHECK_NEAR(k.n0, n0, 1e-12);
    CHECK_NEAR(k.lambda, lam, 1e-12);
    CHECK(mf_kernel_init(&k, 2, 1.0, 0.5) == MF_ERR_INPUT); /* re below l0 */
    mf_error_clear();
    CHECK(mf_kernel_init(&k, 4, 1.0, 2.1) == MF_ERR_INPUT);
    mf_error_clear();
    CHECK(mf_weight(0.0, 2.0) == 0.0 && mf_weight(2.0, 2.0) == 0.0);
    CHECK_NEAR(mf_weight(1.0, 2.0), 1.0, 0);
}

static void test_exact_on_lattice(void)
{
    const double radii[] = {2.1, 3.1, 4.0};
    /* eq. 5 is exact for a linear field with any gradient weight scaled by
     * its own lattice sum n0_g (mf_kernel_set_gradient_weight) */
    const int shapes[] = {MF_GRAD_WEIGHT_PAPER, MF_GRAD_WEIGHT_WENDLAND, MF_GRAD_WEIGHT_WENDLAND_W};
    for (int w = 0; w < 3; w++) {
        for (int r = 0; r < 3; r++) {
            errors e2 = measure(2, 24, radii[r], 0.0, true, shapes[w]);
            CHECK(e2.nd < 1e-12 && e2.grad < 1e-10 && e2.div < 1e-10 && e2.lap < 1e-10);
        }
        errors e3 = measure(3, 12, 2.1, 0.0, true, shapes[w]);
        CHECK(e3.nd < 1e-12 && e3.grad < 1e-10 && e3.div < 1e-10 && e3.lap < 1e-10);
    }
}

/* The gradient weights (mf_kernel.h): the paper's n0_grad is n0; the
 * Wendland C2 -r W'(r) = 20 q^2 (1 - q)^3 and W = (1 - q)^4 (1 + 4q) summed
 * by hand over the 12 neighbours within 2.1 l0 (4 at 1, 4 at sqrt 2, 4 at
 * 2). The pair force of the wendland weight, w_g / r, is -W' up to the
 * constant: it vanishes at r -> 0 and at re, where the paper's diverges. */
static void test_gradient_weights(void)
{
    mf_kernel k;
    CHECK_OK(mf_kernel_init(&k, 2, 1.0, 2.1));
    CHECK(k.grad_weight == MF_GRAD_WEIGHT_PAPER && k.n0_grad == k.n0);
    const double r[3] = {1.0, sqrt(2.0), 2.0};
    double drw = 0, ww = 0;
    for (int s = 0; s < 3; s++) {
        double q = r[s] / 2.1;
        drw += 4 * 20 * q * q * pow(1 - q, 3);
        ww += 4 * pow(1 - q, 4) * (1 + 4 * q);
    }
    CHECK_OK(mf_kernel_set_gradient_weight(&k, MF_GRAD_WEIGHT_WENDLAND));
    CHECK_NEAR(k.n0_grad, drw, 1e-12);
    CHECK_OK(mf_kernel_set_gradient_weight(&k, MF_GRAD_WEIGHT_WENDLAND_W));
    CHECK_NEAR(k.n0_grad, ww, 1e-12);
    CHECK_NEAR(k.n0, 4 * (2.1 - 1) + 4 * (2.1 / sqrt(2) - 1) + 4 * (2.1 / 2 - 1), 1e-12);
    /* -r W'(r) from W by a central difference */
    const double q = 0.37, h = 1e-6;
    double dW = (mf_weight_wendland((q + h) * 2.1, 2.1) - mf_weight_wendland((q - h) * 2.1, 2.1)) /
                (2 * h * 2.1);
    CHECK_NEAR(mf_weight_wendland_drw(q * 2.1, 2.1), -q * 2.1 * dW, 1e-8);
    CHECK(mf_weight_gradient(0.0, 2.1, MF_GRAD_WEIGHT_WENDLAND) == 0.0);
    CHECK(mf_weight_gradient(2.1, 2.1, MF_GRAD_WEIGHT_WENDLAND) == 0.0);
    CHECK(mf_weight_gradient(1.3, 2.1, MF_GRAD_WEIGHT_PAPER) == mf_weight(1.3, 2.1));
    CHECK(mf_kernel_set_gradient_weight(&k, 7) == MF_ERR_INPUT);
    mf_error_clear();
}

static void test_jittered_lattice(void)
{
    /* The error is driven by the irregularity: halving the jitter must
     * roughly halve it (first order), and it stays moderate. */
    rng = 7;
    errors big = measure(2, 30, 3.1, 0.10, true, MF_GRAD_WEIGHT_PAPER);
    rng = 7;
    errors small = measure(2, 30, 3.1, 0.05, true, MF_GRAD_WEIGHT_PAPER);
    rng = 7;
    errors tiny = measure(2, 30, 3.1, 0.025, true, MF_GRAD_WEIGHT_PAPER);
    CHECK(small.grad < 0.7 * big.grad && tiny.grad < 0.7 * small.grad);
    CHECK(small.div < 0.7 * big.div && tiny.div < 0.7 * small.div);
    CHECK(small.nd < 0.7 * big.nd && tiny.nd < 0.7 * small.nd);
    CHECK(tiny.grad < 0.1 && tiny.div < 0.1);
}

static void test_free_surface(void)
{
    /* A block's corner and edge particles are surface, the middle is not. */
    const double l0 = 1.0;
    mf_particles *p = lattice(2, 10, l0, 0.0);
    mf_kernel k;
    CHECK_OK(mf_kernel_init(&k, 2, l0, 2.1));
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    CHECK_OK(mf_grid_build(&g, p, k.re));
    CHECK_OK(mf_nlist_build(&nl, &g, p, k.re));
    double nd[100];
    uint8_t flag[100];
    const mf_pairs v = mf_pairs_of_list(p, &nl, k.re);
    mf_number_density(&v, NULL, NULL, nd);
    mf_free_surface(nd, p->n, 0.97, k.n0, flag);
    int surface = 0;
    for (size_t i = 0; i < p->n; i++) {
        int ix = (int)lround(p->pos[3 * i]), iy = (int)lround(p->pos[3 * i + 1]);
        bool edge = ix == 0 || iy == 0 || ix == 9 || iy == 9;
        bool deep = ix >= 2 && iy >= 2 && ix <= 7 && iy <= 7;
        if (edge) CHECK(flag[i]);
        if (deep) CHECK(!flag[i]);
        surface += flag[i];
    }
    printf("free surface: %d of 100 particles of a 10 x 10 block\n", surface);
    mf_grid_free(&g);
    mf_nlist_free(&nl);
    mf_particles_destroy(p);
}

int main(void)
{
    test_kernel_constants();
    test_exact_on_lattice();
    test_gradient_weights();
    test_jittered_lattice();
    test_free_surface();
    return mf_test_summary("operators");
}
