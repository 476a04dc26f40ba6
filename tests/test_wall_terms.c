/* test_wall_terms.c: the wall terms of the MPS step (core/particles/
 * mf_wall_terms.h, from a solid's wall weight sums, walls_sums.c) against
 * the same operators summed by brute force over an explicit wall lattice:
 * the lattice of wall particles the table stands for (every lattice point
 * (j + 1/2) l0 behind a closed face of a tank, aligned with the particle
 * along the face).
 *
 * For a fluid particle beside a face (on the lattice and between lattice
 * offsets), at an edge (2-D corner) and at a 3-D corner of a tank:
 *   number density   zn            = sum w_nd
 *   divergence       d/n0 (u_w - u_i).g = d/n0 sum (u_w - u_i).v/|v|^2 w_grad
 *   gradient         of the continued pressure p_v = p_i + rho a.v, with p^
 *   viscous term     (face) no slip: u_v = u_w - (s_v/d)(u_i - u_w)
 * equal to 1e-12 relative on the lattice, to the tables' interpolation
 * (1e-3 of the operator's scale) between; and the face collision. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_kernel.h"
#include "mf_test.h"
#include "mf_wall_terms.h"
#include "mf_walls.h"

static const double L0 = 0.01, RHO = 1000, NU = 1e-3;

typedef struct brute {
    double zn, div, grad[3], visc[3];
} brute;

/* Brute force over the wall lattice of a tank whose closed faces are the
 * planes x_a = 0 for a < nfaces (the solid is the union of x_a < 0). */
static void brute_sums(int dim, int nfaces, const double x[3], const mf_kernel *kn,
                       const mf_kernel *kg, const mf_kernel *kl, const double u_i[3],
                       const double u_w[3], double p_i, double phat, const double a[3],
                       brute *b)
{
    memset(b, 0, sizeof *b);
    const long J = (long)ceil(kn->re / L0) + 3;
    long lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int q = 0; q < dim; q++) {
        lo[q] = -J;
        hi[q] = J;
    }
    for (long k = lo[2]; k <= hi[2]; k++)
        for (long j = lo[1]; j <= hi[1]; j++)
            for (long i = lo[0]; i <= hi[0]; i++) {
                const long idx[3] = {i, j, k};
                double y[3] = {0, 0, 0}, v[3] = {0, 0, 0};
                bool wall = false;
                for (int q = 0; q < dim; q++) {
                    /* on the global lattice across a face, aligned with x along it */
                    y[q] = q < nfaces ? (floor(x[q] / L0) + (double)idx[q] + 0.5) * L0
                                      : x[q] + (double)idx[q] * L0;
                    v[q] = y[q] - x[q];
                    wall = wall || (q < nfaces && y[q] < 0);
                }
                if (!wall)
                    continue;
                const double r = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
                const double re = fmax(r, 0.25 * L0);
                const double wn = mf_weight(re, kn->re), wg = mf_weight(re, kg->re),
                             wl = mf_weight(re, kl->re);
                b->zn += wn;
                double du = 0, pv = p_i;
                for (int q = 0; q < 3; q++) {
                    du += (u_w[q] - u_i[q]) * v[q];
                    pv += RHO * a[q] * v[q];
                }
                b->div += kg->dim / kg->n0 * du / (re * re) * wg;
                for (int q = 0; q < 3; q++)
                    b->grad[q] += kg->dim / kg->n0 * (pv - phat) * v[q] / (re * re) * wg;
                if (nfaces == 1) { /* Morris et al.: u_v = u_w - (s_v/d)(u_i - u_w) */
                    const double d = fmax(x[0], 0.25 * L0), s_v = -y[0];
                    for (int q = 0; q < 3; q++) {
                        const double uv = u_w[q] - s_v / d * (u_i[q] - u_w[q]);
                        b->visc[q] += NU * 2.0 * kl->dim / (kl->lambda * kl->n0) * (uv - u_i[q]) * wl;
                    }
                }
            }
}

static double rel(double a, double b, double scale) { return fabs(a - b) / scale; }

static void check_case(const char *name, int dim, int nfaces, const double x[3], double tol)
{
    mf_kernel kn, kg, kl;
    mf_kernel_init(&kn, dim, L0, 3.1 * L0);
    mf_kernel_init(&kg, dim, L0, 2.1 * L0);
    mf_kernel_init(&kl, dim, L0, 3.1 * L0);
    mf_wall_tables *t = NULL;
    CHECK(mf_wall_tables_create(dim, L0, kn.re, kg.re, kl.re, &t) == 0);
    if (!t)
        return;
    mf_wall tank;
    memset(&tank, 0, sizeof tank);
    tank.shape = MF_SOLID_TANK;
    tank.dim = dim;
    for (int q = 0; q < 3; q++) {
        tank.min[q] = 0;
        tank.max[q] = 10; /* far */
        tank.open[q][0] = q >= nfaces || q >= dim;
        tank.open[q][1] = true;
    }
    mf_motion_state(&tank.motion, 0, &tank.state);
    mf_wall_sums s;
    CHECK(mf_wall_sums_of(&tank, t, dim, L0, x, &s));
    const double u_i[3] = {0.3, -0.2, dim == 3 ? 0.1 : 0}, u_w[3] = {0.05, 0, 0};
    const double a[3] = {0.4, -9.81, dim == 3 ? 0.7 : 0};
    const double p_i = 2000, phat = 1900;
    brute b;
    brute_sums(dim, nfaces, x, &kn, &kg, &kl, u_i, u_w, p_i, phat, a, &b);
    /* the operators' scales: n0; the divergence of a unit velocity over l0;
     * the gradient of rho |a|; the viscous term of a unit velocity */
    const double s_div = kg.dim / L0, s_grad = RHO * 9.81, s_visc = NU / (L0 * L0);
    double worst = rel(mf_wall_number_density(&s), b.zn, kn.n0);
    worst = fmax(worst, rel(mf_wall_divergence(&s, &kg, u_i, u_w), b.div, s_div));
    double g[3] = {0, 0, 0};
    mf_wall_gradient_add(&s, &kg, p_i, phat, RHO, a, g);
    for (int q = 0; q < dim; q++)
        worst = fmax(worst, rel(g[q], b.grad[q], s_grad));
    if (nfaces == 1) {
        double acc[3] = {0, 0, 0}, visc_u[3];
        for (int q = 0; q < 3; q++)
            visc_u[q] = s.visc * u_w[q];
        mf_wall_viscous_add(&s, &kl, NU, u_i, visc_u, acc);
        for (int q = 0; q < dim; q++)
            worst = fmax(worst, rel(acc[q], b.visc[q], s_visc));
    }
    printf("%-34s zn %.6g (brute %.6g), largest relative difference %.2e (tolerance %.0e)\n",
           name, s.zn, b.zn, worst, tol);
    CHECK_MSG(worst < tol, "%s: %g", name, worst);
    CHECK_MSG(b.zn > 0.05 * kn.n0, "%s: the wall is within reach", name);
    mf_wall_tables_destroy(t);
}

static void test_collision(void)
{
    const double n[3] = {0, 1, 0}, uw[3] = {0.1, 0, 0};
    double du[3];
    const double toward[3] = {0.1, -1, 0}, away[3] = {0, 1, 0};
    CHECK(mf_wall_collision(0.2 * L0, n, uw, 0.25 * L0, 0.2, toward, du));
    CHECK_MSG(fabs(toward[1] + du[1] - 0.2) < 1e-14 && du[0] == 0,
              "approaching at 1 m/s leaves at e = 0.2 m/s: %g", toward[1] + du[1]);
    CHECK(!mf_wall_collision(0.2 * L0, n, uw, 0.25 * L0, 0.2, away, du));
    CHECK(!mf_wall_collision(0.3 * L0, n, uw, 0.25 * L0, 0.2, toward, du));
}

int main(void)
{
    const double on = 1e-12, between = 1e-3;
    check_case("2-D face, on the lattice", 2, 1, (double[3]){0.5 * L0, 3.3 * L0, 0}, on);
    check_case("2-D face, 1.5 l0 away", 2, 1, (double[3]){1.5 * L0, 0.1 * L0, 0}, on);
    check_case("2-D face, 0.8 l0 (between nodes)", 2, 1, (double[3]){0.8 * L0, 0, 0}, between);
    check_case("2-D face, 0.3 l0 (between nodes)", 2, 1, (double[3]){0.3 * L0, 0, 0}, between);
    check_case("2-D corner", 2, 2, (double[3]){0.5 * L0, 1.5 * L0, 0}, on);
    check_case("3-D face", 3, 1, (double[3]){0.5 * L0, 0.2 * L0, 0.7 * L0}, on);
    check_case("3-D face, 1.2 l0 (between nodes)", 3, 1, (double[3]){1.2 * L0, 0, 0}, between);
    check_case("3-D edge", 3, 2, (double[3]){0.5 * L0, 1.5 * L0, 0.4 * L0}, on);
    check_case("3-D corner", 3, 3, (double[3]){1.5 * L0, 0.5 * L0, 0.5 * L0}, on);
    test_collision();
    return mf_test_summary("wall_terms");
}
