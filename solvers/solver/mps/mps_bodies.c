/* mps_bodies.c: the force and torque the fluid exerts on each rigid body
 * (core/scene/mf_bodies.h; the force integration of Akinci et al. 2012,
 * "Versatile rigid-fluid coupling for incompressible SPH", ACM TOG 31(4) 62,
 * section 4, with the pressure taken on the body's surface):
 *
 *   viscosity: the opposite of what the fluid particles' momentum equation
 *     received from the body's particles in this step, with the step's own
 *     Laplacian (eq. 7, or the higher-order one) restricted to them (jmask),
 *     F -= sum_i m_i nu <lap u>_i^body, placed at x_i (the pair term is
 *     antisymmetric: the body's momentum gain is the fluid's loss);
 *   pressure (the paper gradient, eq. 5): F = -sum p_s A n over the surface
 *     elements A n that the body's wall particles stand for (mf_body_surface),
 *     p_s the fluid's pressure continued to the element's point on the
 *     surface (Adami, Hu & Adams 2012: surface_pressure below). The wall
 *     particles' own pressure, the first form, is not the fluid's beside
 *     them: floatingBox floated 10.1% (l0 = 0.01 m) and 6.4% (0.005 m) high
 *     with it, 4.7% and 3.0% with p_s (docs/topics/rigid-bodies.md);
 *
 *   pressure with gradient corrected (CMPS, Khayyer & Gotoh 2008): the
 *     reaction of the pairs, as for viscosity, its pair term being
 *     antisymmetric: momentum is exchanged exactly (test_bodies).
 *
 * Why the surface and not the pairs with the paper gradient (eq. 5, the
 * robust scheme's): its pair term (p_j - p^_i) r_ij w / |r_ij|^2 is taken
 * against the neighbourhood's minimum p^_i and is not antisymmetric, so the
 * share a subset of the neighbours gives is not a force: a box held fixed
 * under water received -12 N from its particles' pairs where Archimedes
 * gives +98 N (docs/topics/rigid-bodies.md). */
#include <stdlib.h>
#include <string.h>

#include "mf_bodies.h"
#include "mf_error.h"
#include "mf_operators.h"
#include "mps.h"

/* Rigid bodies work on any number of ranks (each sums over its owned
 * particles, mf_bodies_accept sums over the ranks), without a period, with
 * one fluid and the operators whose sums split over pairs. */
static int check(const mps_data *d, const mf_sim *sim)
{
    (void)sim;
    const char *why = d->s.periodic_length > 0 ? "with a periodic box"
                      : d->rho || d->mu ? "with several fluids"
                      : d->visc         ? "with implicit viscosity (use viscosity explicit)"
                      : d->sc.laplacian == MPS_LAPLACIAN_LEAST_SQUARES
                          ? "with laplacian leastSquares (its sum does not split over pairs: use "
                            "paper or higherOrder)"
                      : d->sc.gradient == MPS_GRADIENT_LEAST_SQUARES
                          ? "with gradient leastSquares (use paper or corrected)"
                          : NULL;
    if (why)
        return MF_ERROR(MF_ERR_INPUT, "rigid bodies (motion type rigid) do not work %s", why);
    return 0;
}

/* The body's particles (WallId = k + 1), dummies included or not. */
static void body_mask(const mf_walls *ws, const mf_particles *p, size_t k, bool dummies,
                      uint8_t *mask)
{
    const int32_t *id = mf_particles_fi(p, ws->f_wall_id);
    for (size_t i = 0; i < p->n; i++)
        mask[i] = id[i] == (int32_t)k + 1 && (dummies || p->kind[i] != MF_DUMMY);
}

/* Adds sign m_i a_i of the fluid particles to body k, a = acc (3 per particle). */
static void add_to_body(const mf_sim *sim, const mps_data *d, mf_wall *w, const double *acc,
                        double sign)
{
    const mf_particles *p = sim->p;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->is_fluid[i])
            continue;
        const double m = sign * mf_sim_particle_mass(sim, -1, i);
        const double f[3] = {m * acc[3 * i], m * acc[3 * i + 1], m * acc[3 * i + 2]};
        if (f[0] != 0 || f[1] != 0 || f[2] != 0)
            mf_body_add_force(w, &p->pos[3 * i], f);
    }
}

typedef struct scratch {
    uint8_t *mask;
    double *acc;
} scratch;

static int scratch_get(scratch *s, size_t n)
{
    s->mask = malloc(n ? n : 1);
    s->acc = malloc(3 * (n ? n : 1) * sizeof *s->acc);
    if (!s->mask || !s->acc) {
        free(s->mask);
        free(s->acc);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory summing the forces on the rigid bodies");
    }
    return 0;
}

static void scratch_free(scratch *s)
{
    free(s->mask);
    free(s->acc);
}

int mps_bodies_halo(mps_data *d, const mf_sim *sim)
{
    const mf_walls *ws = sim->walls;
    if (mf_bodies_count(ws) == 0 || ws->f_wall_id < 0)
        return 0;
    /* body_mask reads the WallId of the neighbours, copies included: at r^n
     * (viscosity) and at r* (the corrected gradient's pairs) */
    MF_CALL(mps_halo_add_field(d, ws->f_wall_id, MPS_HALO_START | MPS_HALO_STAR));
    return 0;
}

void mps_bodies_begin(mps_data *d, mf_sim *sim)
{
    (void)d;
    mf_bodies_clear_forces(sim->walls);
}

int mps_bodies_viscous(mps_data *d, mf_sim *sim)
{
    mf_walls *ws = sim->walls;
    const double nu = sim->fluid[0].nu;
    if (mf_bodies_count(ws) == 0)
        return 0;
    MF_CALL(check(d, sim));
    if (!(nu > 0))
        return 0;
    mf_particles *p = sim->p;
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_lap, &v));
    scratch s;
    MF_CALL(scratch_get(&s, p->n));
    for (size_t k = 0; k < ws->n; k++) {
        if (!ws->w[k].body)
            continue;
        body_mask(ws, p, k, true, s.mask);
        memset(s.acc, 0, 3 * p->n * sizeof *s.acc);
        if (d->sc.laplacian == MPS_LAPLACIAN_HIGHER_ORDER)
            mf_laplacian_hl_add(&v, &d->k_lap, p->vel, nu, d->is_fluid, s.mask, s.acc);
        else
            mf_laplacian_add(&v, &d->k_lap, p->vel, nu, d->is_fluid, s.mask, s.acc);
        add_to_body(sim, d, &ws->w[k], s.acc, -1.0);
    }
    scratch_free(&s);
    return 0;
}

/* The corrected gradient (CMPS) restricted to the body's wall particles:
 * its pair term is antisymmetric, so the reaction of what the fluid
 * received is the body's force, and momentum is exchanged exactly. */
static int pressure_pairs(mps_data *d, mf_sim *sim, const double *pressure)
{
    mf_walls *ws = sim->walls;
    mf_particles *p = sim->p;
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_grad, &v));
    scratch s;
    MF_CALL(scratch_get(&s, p->n));
    double *fhat = malloc((p->n ? p->n : 1) * sizeof *fhat);
    if (!fhat) {
        scratch_free(&s);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory summing the forces on the rigid bodies");
    }
    /* p^ as the step's gradient has it (mps_gradient_pairs), the halo
     * copies' included: the pair term reads p^ of both particles */
    const int rc = mps_corrected_pmin(d, sim, &v, pressure, fhat);
    if (rc != 0) {
        free(fhat);
        scratch_free(&s);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    const mf_gradient_opts o = {.f = pressure, .coef = 1.0 / sim->fluid[0].rho, .fhat = fhat};
    for (size_t k = 0; k < ws->n; k++) {
        if (!ws->w[k].body)
            continue;
        body_mask(ws, p, k, false, s.mask);
        mf_gradient_ex(&v, &d->k_grad, &o, d->is_fluid, s.mask, s.acc);
        add_to_body(sim, d, &ws->w[k], s.acc, 1.0);
    }
    free(fhat);
    scratch_free(&s);
    return 0;
}

/* The fluid's pressure continued to a point x_s of the body's surface, the
 * wall boundary condition of Adami, Hu & Adams (2012), "A generalized wall
 * boundary condition for smoothed particle hydrodynamics", J. Comput. Phys.
 * 231, 7057-7075, eq. 27, taken to the surface instead of the wall particle:
 *
 *   p_s = sum_i w_ij [p_i + rho (g - a_b).(x_s - x_i)] / sum_i w_ij
 *
 * over the fluid particles i within reGradient of the wall particle j (w_ij
 * eq. 4's weight, a_b the body's acceleration over the step). The sums are
 * split so that one pass serves the 1-3 surface elements of j: sum w, sum w p,
 * sum w x. */
typedef struct surface_ctx {
    const double *pressure, *pos;
    double re;
} surface_ctx;

typedef struct surface_acc {
    double w, wp, wx[3];
} surface_acc;

static inline bool surface_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const surface_ctx *c = ctx;
    surface_acc *a = acc;
    const double w = mf_weight(pr->len, c->re);
    const double *xi = &c->pos[3 * pr->j];
    a->w += w;
    a->wp += w * c->pressure[pr->j];
    for (int k = 0; k < 3; k++)
        a->wx[k] += w * xi[k];
    return true;
}

/* p_s at x_s from the sums of one wall particle; no suction (p_s >= 0, as
 * clipNegativePressure keeps the fluid's). */
static double surface_pressure(const surface_acc *a, double rho, const double ga[3],
                               const double xs[3])
{
    if (!(a->w > 0))
        return 0;
    double h = 0;
    for (int k = 0; k < 3; k++)
        h += ga[k] * (xs[k] - a->wx[k] / a->w);
    const double ps = a->wp / a->w + rho * h;
    return ps > 0 ? ps : 0;
}

/* The paper gradient's form: F = -sum p_s A n over the surface elements of
 * the body's wall particles (mf_body_surface), p_s the fluid's pressure
 * continued to the element (surface_pressure). */
static int pressure_surface(mps_data *d, mf_sim *sim, const double *pressure)
{
    mf_walls *ws = sim->walls;
    mf_particles *p = sim->p;
    const int32_t *id = mf_particles_fi(p, ws->f_wall_id);
    const double l0 = sim->l0, rho = sim->fluid[0].rho;
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_grad, &v));
    const surface_ctx c = {pressure, p->pos, v.radius};
    for (size_t k = 0; k < ws->n; k++) {
        mf_wall *w = &ws->w[k];
        if (!w->body)
            continue;
        MF_CALL(mf_body_surface_prepare(w, p, ws->f_wall_id, (int)k, l0, sim->par));
        double ga[3];
        for (int a = 0; a < 3; a++)
            ga[a] = w->motion.g[a] - w->state.a[a];
        for (size_t j = 0; j < p->n_owned; j++) {
            if (id[j] != (int32_t)k + 1 || p->kind[j] != MF_WALL)
                continue;
            surface_acc a = {0, 0, {0, 0, 0}};
            mf_pairs_row(&v, j, d->is_fluid, surface_pair, &c, &a);
            if (!(a.w > 0))
                continue;
            double area[3][3], shift[3][3];
            const int ns = mf_body_surface(w, &p->pos[3 * j], l0, area, shift);
            for (int e = 0; e < ns; e++) {
                const double x[3] = {p->pos[3 * j] + shift[e][0], p->pos[3 * j + 1] + shift[e][1],
                                     p->pos[3 * j + 2] + shift[e][2]};
                const double ps = surface_pressure(&a, rho, ga, x);
                const double f[3] = {-ps * area[e][0], -ps * area[e][1], -ps * area[e][2]};
                mf_body_add_force(w, x, f);
            }
        }
    }
    return 0;
}

int mps_bodies_pressure(mps_data *d, mf_sim *sim, const double *pressure)
{
    if (mf_bodies_count(sim->walls) == 0)
        return 0;
    MF_CALL(check(d, sim));
    if (d->sc.gradient == MPS_GRADIENT_CORRECTED)
        return pressure_pairs(d, sim, pressure);
    return pressure_surface(d, sim, pressure);
}
