/* attraction.c: fluid drawn into a target shape by control particles, in the
 * manner of Thuerey, Keiser, Pauly & Ruede, "Detail-preserving fluid
 * control", Proc. ACM SIGGRAPH/Eurographics Symposium on Computer Animation
 * (SCA) 2006, 7-12 (and Graphical Models 71(6), 2009).
 *
 * Control particles c_j sample the target (the lattice points of its region
 * at spacing h = `spacing` l0); each acts on the fluid within its radius R =
 * `radius` l0 through the kernel W(r) = (1 - r^2/R^2)^3. Two forces, as in
 * the paper:
 *
 *   attraction  a_A(x_i) = alpha_A sum_j (1 - rho_j)_+ W(|c_j - x_i|) e_ij / W_c
 *               toward the control particles (e_ij the unit vector from x_i
 *               to c_j), weakened where the target is already full: rho_j =
 *               sum_i W(|x_i - c_j|) / W_f is the fluid's density at c_j
 *               over that of fluid at rest on the lattice (W_f), so that the
 *               attraction fills the target instead of heaping the fluid on
 *               its control particles;
 *   velocity    a_V(x_i) = alpha_V min(1, S_i / W_c) (v_c - u~_i), S_i =
 *               sum_j W(|c_j - x_i|): the fluid near the control particles
 *               aligned with their velocity v_c (rest, for a still target).
 *               The paper's detail-preserving step: u~_i is the fluid's
 *               velocity low-pass filtered over its neighbours (radius
 *               `smoothing` l0, the same kernel), so the control acts on the
 *               coarse motion and leaves the small-scale detail free.
 *
 * W_c is the sum of W over a full control lattice (the value of S deep in
 * the target), so alpha_A and alpha_V are accelerations per unit of a full
 * neighbourhood: alpha_A in m/s^2, alpha_V in 1/s. The paper's influence
 * fields are normalised differently (per control particle, with weights from
 * the target's animation); the structure (attraction scaled by the missing
 * density, velocity alignment on the low-pass velocity) is theirs.
 *
 * Cost: nothing outside R of the target (a point query returns at once); the
 * densities rho_j are one scatter over the fluid near the target, summed
 * over ranks by control_allreduce_sum. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "control.h"
#include "force/forces.h"
#include "mf_error.h"
#include "mf_pairs.h"

typedef struct attraction_settings {
    control_shape_settings target;
    double spacing, radius, smoothing;
    double alpha_a, alpha_v;
    double velocity[3];
} attraction_settings;

static const mf_param attraction_params[] = {
    CONTROL_SHAPE_PARAMS(attraction_settings, target, "target shape"),
    {"spacing", MF_PARAM_SCALAR, "2", 0.5, 100, NULL, offsetof(attraction_settings, spacing),
     "spacing h of the control particles that sample the target, in l0"},
    {"influenceRadius", MF_PARAM_SCALAR, "4", 1, 1000, NULL, offsetof(attraction_settings, radius),
     "influence radius R of a control particle, in l0"},
    {"smoothing", MF_PARAM_SCALAR, "2.1", 1.01, 10, NULL,
     offsetof(attraction_settings, smoothing),
     "radius of the low-pass filter of the fluid's velocity (u~), in l0"},
    {"attraction", MF_PARAM_SCALAR, "20", 0, 1e6, NULL, offsetof(attraction_settings, alpha_a),
     "attraction strength alpha_A, m/s^2 (per full control neighbourhood)"},
    {"velocityAlignment", MF_PARAM_SCALAR, "5", 0, 1e6, NULL,
     offsetof(attraction_settings, alpha_v),
     "velocity alignment rate alpha_V, 1/s: u~ relaxed toward the control velocity"},
    {"velocity", MF_PARAM_VECTOR, "(0 0 0)", -1e6, 1e6, NULL,
     offsetof(attraction_settings, velocity), "velocity v_c of the control particles, m/s"},
};
#define ATTRACTION_NPARAMS (sizeof attraction_params / sizeof attraction_params[0])

typedef struct attraction_data {
    attraction_settings s;
    control_shape target;
    mf_particles *cp;  /* the control particles */
    mf_grid grid;      /* their cells, of side R */
    double R, R2, Rs, Rs2;
    double w_fluid, w_control; /* full-neighbourhood sums at l0 and at h */
    double *rho;       /* per control particle: the fluid's density, of w_fluid */
    int pairs;         /* the low-pass filter's neighbour request */
} attraction_data;

static void attraction_destroy(void *data)
{
    attraction_data *d = data;
    if (!d)
        return;
    control_shape_free(&d->target);
    mf_grid_free(&d->grid);
    mf_particles_destroy(d->cp);
    free(d->rho);
    free(d);
}

static int sample_target(attraction_data *d, const mf_sim *sim)
{
    const double h = d->s.spacing * sim->l0;
    const size_t n = control_shape_lattice(&d->target, h, NULL, 0);
    if (n == 0)
        return MF_ERROR(MF_ERR_INPUT, "force attraction: the target holds no control particle "
                        "at spacing %g l0 (a target smaller than %g m?)", d->s.spacing, h);
    double *xyz = malloc(3 * n * sizeof *xyz);
    if (!xyz)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    control_shape_lattice(&d->target, h, xyz, n);
    int rc = mf_particles_create(sim->dim, n, &d->cp);
    for (size_t k = 0; k < n && rc == 0; k++)
        rc = mf_particles_add(d->cp, MF_FLUID, &xyz[3 * k], d->s.velocity, NULL);
    free(xyz);
    if (rc == 0)
        rc = mf_grid_build(&d->grid, d->cp, d->R);
    if (rc == 0) {
        mf_grid_release_scratch(&d->grid);
        d->rho = calloc(n, sizeof *d->rho);
        if (!d->rho)
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    }
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    return 0;
}

static int attraction_create(const void *settings, mf_sim *sim, void **data)
{
    attraction_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    mf_grid_init(&d->grid);
    d->s = *(const attraction_settings *)settings;
    d->R = d->s.radius * sim->l0;
    d->R2 = d->R * d->R;
    d->Rs = d->s.smoothing * sim->l0;
    d->Rs2 = d->Rs * d->Rs;
    d->w_fluid = control_kernel_lattice_sum(sim->dim, sim->l0, d->R);
    d->w_control = control_kernel_lattice_sum(sim->dim, d->s.spacing * sim->l0, d->R);
    int rc = control_shape_create(&d->s.target, "attraction", sim, &d->target);
    if (rc == 0)
        rc = sample_target(d, sim);
    if (rc == 0)
        rc = mf_neighbours_request(sim->neighbours, d->Rs, 0, &d->pairs);
    if (rc != 0) {
        attraction_destroy(d);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "attraction: %zu control particles in the %s target (spacing %g l0, radius "
                  "%g l0), alpha_A = %g m/s^2, alpha_V = %g 1/s\n",
                  d->cp->n, d->s.target.shape, d->s.spacing, d->s.radius, d->s.alpha_a,
                  d->s.alpha_v);
    *data = d;
    return 0;
}

/* ---- the fluid's density at the control particles ------------------------ */

typedef struct density_ctx {
    double R2;
    double *rho;
} density_ctx;

static bool density_point(void *acc, const void *ctx, size_t j, const double r[3], double d2)
{
    (void)acc;
    (void)r;
    const density_ctx *c = ctx;
    c->rho[j] += control_kernel(d2, c->R2);
    return true;
}

static int fluid_density(attraction_data *d, const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    memset(d->rho, 0, d->cp->n * sizeof *d->rho);
    const density_ctx c = {d->R2, d->rho};
    for (size_t i = 0; i < p->n_owned; i++) /* serial: a fixed order of the sums */
        if (p->kind[i] == MF_FLUID)
            mf_grid_near(&d->grid, &p->pos[3 * i], density_point, &c, NULL);
    MF_CALL(control_allreduce_sum(sim, d->rho, d->cp->n));
    for (size_t j = 0; j < d->cp->n; j++)
        d->rho[j] /= d->w_fluid;
    return 0;
}

/* ---- the forces on one fluid particle ------------------------------------ */

typedef struct attraction_ctx {
    const attraction_data *d;
    const mf_particles *p;
    const mf_pairs *v;
    double *acc;
} attraction_ctx;

typedef struct control_acc {
    double s;     /* sum_j W */
    double a[3];  /* sum_j (1 - rho_j)_+ W e_ij */
} control_acc;

static bool control_point(void *acc, const void *ctx, size_t j, const double r[3], double d2)
{
    const attraction_data *d = ctx;
    control_acc *a = acc;
    const double w = control_kernel(d2, d->R2);
    if (w == 0)
        return true;
    a->s += w;
    const double len = sqrt(d2), missing = 1 - d->rho[j];
    if (missing > 0 && len > 0)
        for (int q = 0; q < 3; q++)
            a->a[q] += missing * w * r[q] / len;
    return true;
}

typedef struct lowpass_acc {
    double sw, su[3];
} lowpass_acc;

static bool lowpass_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const attraction_ctx *c = ctx;
    lowpass_acc *a = acc;
    if (c->p->kind[pr->j] != MF_FLUID)
        return true;
    const double w = control_kernel(pr->r2, c->d->Rs2);
    a->sw += w;
    for (int q = 0; q < 3; q++)
        a->su[q] += w * c->p->vel[3 * pr->j + q];
    return true;
}

static void attraction_row(const void *ctx, size_t i)
{
    const attraction_ctx *c = ctx;
    const attraction_data *d = c->d;
    const mf_particles *p = c->p;
    if (p->kind[i] != MF_FLUID)
        return;
    control_acc a = {0, {0, 0, 0}};
    mf_grid_near(&d->grid, &p->pos[3 * i], control_point, d, &a);
    if (!(a.s > 0))
        return; /* beyond every control particle's reach */
    /* u~_i: the fluid's velocity low-pass filtered (the particle itself has W = 1). */
    lowpass_acc lp = {1, {p->vel[3 * i], p->vel[3 * i + 1], p->vel[3 * i + 2]}};
    mf_pairs_row(c->v, i, NULL, lowpass_pair, c, &lp);
    const double reach = fmin(1, a.s / d->w_control);
    for (int q = 0; q < p->dim; q++)
        c->acc[3 * i + q] += d->s.alpha_a * a.a[q] / d->w_control +
                             d->s.alpha_v * reach * (d->s.velocity[q] - lp.su[q] / lp.sw);
}

static int attraction_accumulate(void *data, const mf_sim *sim, double *acc)
{
    attraction_data *d = data;
    MF_CALL(fluid_density(d, sim));
    mf_pairs v;
    MF_CALL(mf_neighbours_pairs(sim->neighbours, sim->p, d->pairs, &v));
    const attraction_ctx c = {d, sim->p, &v, acc};
    mf_pairs_each(&v, NULL, attraction_row, &c);
    return 0;
}

/* Explicit integration of the two: the velocity relaxation needs
 * alpha_V dt <= 1 (no overshoot of v_c), the attraction (a spring of
 * stiffness about alpha_A / R) dt <= sqrt(R / alpha_A) / 2. */
static int attraction_stable_dt(void *data, const mf_sim *sim, double *dt)
{
    (void)sim;
    const attraction_data *d = data;
    *dt = INFINITY;
    if (d->s.alpha_v > 0)
        *dt = 1 / d->s.alpha_v;
    if (d->s.alpha_a > 0)
        *dt = fmin(*dt, 0.5 * sqrt(d->R / d->s.alpha_a));
    return 0;
}

const mf_force_ops mf_force_attraction = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "attraction",
             "fluid drawn into a target shape by control particles (Thuerey et al. 2006)",
             attraction_params, ATTRACTION_NPARAMS, sizeof(attraction_settings)},
    .create = attraction_create,
    .accumulate = attraction_accumulate,
    .destroy = attraction_destroy,
    .stable_dt = attraction_stable_dt,
};
