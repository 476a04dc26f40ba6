/* mps_wall.c: `wall wallWeight;` (MPSCoeffs): walls without particles, their
 * part of every operator of the step from the wall weight tables
 * (core/particles/mf_wall_weight.h; Harada, Koshizuka & Shimazaki 2008,
 * Trans. JSCES 20080006; polygon walls as Mitsume et al. 2015) through the
 * per-particle terms of core/particles/mf_wall_terms.h:
 *   number density (eq. 4; also the mixed source's density term at r^n),
 *   the mixed source's divergence (eq. 6) with the wall's velocity,
 *   the PPE row: the walls take the particle's pressure (p_v = p_i: nothing
 *     of them in the row; no wall rows, nothing Dirichlet on the wall),
 *   the pressure gradient (eq. 5) of the pressure continued into the wall
 *     (mps_wall_keep_approach),
 *   the viscous term (eq. 7) with no slip on the face at the wall's velocity,
 *     or under `laplacian leastSquares;` the walls' virtual points in each
 *     particle's LSMPS fit (mps_wall_lsmps_laplacian: tanks and boxes only),
 *   the collision model against the face.
 * The scene is then built without wall and dummy particles (the driver
 * reads the key before it builds the scene: sim->wall_weight). Each phase
 * calls one function here over the owned fluid particles; the pairs among
 * particles are the pair engine's as before.
 *
 * What the terms assume (refused otherwise, naming the key): the paper's
 * gradient (eq. 5), the paper's Laplacian (eq. 7) or leastSquares (plane
 * faces only: its PPE takes the higher-order Laplacian, in which the walls,
 * at p_v = p_i, add nothing, as in eq. 7's), the density or mixed source, no
 * shifting, explicit viscosity, one fluid, one rank. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_bodies.h"
#include "mf_error.h"
#include "mf_lsmps.h"
#include "mf_operators.h"
#include "mf_wall_terms.h"
#include "mf_walls.h"
#include "mps.h"

const char *const mps_wall_choices[] = {"particles", "wallWeight", NULL};

struct mps_wall {
    mf_wall_tables *tables;
    size_t cap;
    mf_wall_point *pt; /* n: the sums at the particle's last position */
    uint8_t *has;      /* n: a solid within reach there */
    double *f;         /* 3n: the force acceleration of the step (continued pressure) */
    long collisions;   /* face collisions, all steps */
};

/* Where an MPS key was set in the solver dictionary (any solver's Coeffs:
 * the table is shared), or "system/solverDict" if nowhere. */
const char *mps_key_where(const mf_dict *sd, const char *key, char *buf, size_t len)
{
    snprintf(buf, len, "system/solverDict");
    for (size_t k = 0; sd && k < sd->n; k++) {
        const mf_entry *e = sd->entries[k];
        if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT)
            continue;
        const mf_entry *w = mf_dict_find(e->items[0]->dict, key);
        if (w)
            return mf_loc_str(w->loc, buf, len);
    }
    return buf;
}

int mps_wall_refuse(const mps_settings *s, const mf_dict *solver_dict, const char *why)
{
    if (!s->wall || strcmp(s->wall, "wallWeight") != 0)
        return 0;
    char where[512];
    return MF_ERROR(MF_ERR_INPUT,
                    "%s: wall wallWeight: %s; use wall particles; (the default) there",
                    mps_key_where(solver_dict, "wall", where, sizeof where), why);
}

static int reserve(struct mps_wall *w, size_t n)
{
    if (n <= w->cap)
        return 0;
    size_t cap = n + n / 4 + 64;
    if (mf_resize(&w->pt, cap, sizeof *w->pt) || mf_resize(&w->has, cap, 1) ||
        mf_resize(&w->f, 3 * cap, sizeof *w->f))
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the wall weight sums");
    w->cap = cap;
    return 0;
}

/* laplacian leastSquares takes the walls' virtual points on the lattice
 * behind plane faces (mf_wall_points_each): refused, naming the key, with a
 * curved or polygon solid, whose lattice the tables only approximate by a
 * tangent plane. */
static int ls_plane_faces_only(const mps_data *d, const mf_sim *sim, const mf_dict *solver_dict)
{
    if (d->sc.laplacian != MPS_LAPLACIAN_LEAST_SQUARES || !sim->walls)
        return 0;
    for (size_t k = 0; k < sim->walls->n; k++) {
        const mf_wall *s = &sim->walls->w[k];
        if (s->shape == MF_SOLID_TANK || s->shape == MF_SOLID_BOX)
            continue;
        char where[512];
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: key 'laplacian': leastSquares with wall wallWeight takes the "
                        "walls' virtual points behind plane faces (tank and box solids), and "
                        "solid '%s' (%s) is %s; use laplacian paper; there",
                        mps_key_where(solver_dict, "laplacian", where, sizeof where), s->name,
                        s->where,
                        s->shape == MF_SOLID_CYLINDER ? "a cylinder"
                        : s->shape == MF_SOLID_SPHERE ? "a sphere"
                                                      : "a mesh");
    }
    return 0;
}

int mps_wall_create(mps_data *d, mf_sim *sim, const mf_dict *solver_dict)
{
    if (!d->s.wall || strcmp(d->s.wall, "wallWeight") != 0)
        return 0;
    const char *why = NULL;
    if (d->sc.source != MPS_SOURCE_DENSITY && d->sc.source != MPS_SOURCE_MIXED)
        why = "the wall terms are written for source density or mixed (set source mixed;)";
    else if (d->sc.gradient != MPS_GRADIENT_PAPER)
        why = "the wall terms are written for gradient paper (eq. 5)";
    else if (d->sc.laplacian == MPS_LAPLACIAN_HIGHER_ORDER)
        why = "the wall terms are written for laplacian paper (eq. 7) or leastSquares";
    else if (d->sc.shifting != MPS_SHIFT_NONE)
        why = "particle shifting has no wall term yet (set shifting none;)";
    else if (d->visc)
        why = "the implicit viscosity has no wall term yet (set viscosity explicit;)";
    else if (d->s.wall_pressure_extrapolated)
        why = "wallPressureExtrapolated continues the pressure to wall particles (set it to no)";
    else if (d->k_grad.grad_weight != MF_GRAD_WEIGHT_PAPER)
        why = "the wall tables integrate the paper's weight (set gradientWeight paper;)";
    else if (sim->par)
        why = "not on several ranks yet (run it serially)";
    else if (mf_bodies_count(sim->walls) > 0)
        why = "rigid bodies take their forces from their wall particles (mps_bodies.c)";
    else if (!sim->wall_weight)
        why = "the scene was built with wall particles (the driver builds it without them when "
              "MPSCoeffs sets wall wallWeight;)";
    if (why)
        MF_CALL(mps_wall_refuse(&d->s, solver_dict, why));
    MF_CALL(ls_plane_faces_only(d, sim, solver_dict));
    struct mps_wall *w = calloc(1, sizeof *w);
    if (!w)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->wall = w;
    MF_CALL(mf_wall_tables_create(sim->dim, sim->l0, d->k_nd.re, d->k_grad.re, d->k_lap.re,
                                  &w->tables));
    MF_CALL(mf_walls_prepare(sim->walls, mf_wall_tables_reach(w->tables)));
    MF_CALL(reserve(w, sim->p->n));
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "MPS walls: wall weight functions (Harada et al. 2008), %zu solids, tables "
                  "%.1f kB\n",
                  sim->walls ? sim->walls->n : (size_t)0,
                  mf_wall_tables_memory(w->tables) / 1024.0);
    return 0;
}

void mps_wall_destroy(struct mps_wall *w)
{
    if (!w)
        return;
    mf_wall_tables_destroy(w->tables);
    free(w->pt);
    free(w->has);
    free(w->f);
    free(w);
}

int mps_wall_points(mps_data *d, const mf_sim *sim)
{
    struct mps_wall *w = d->wall;
    const mf_particles *p = sim->p;
    MF_CALL(reserve(w, p->n));
    for (size_t i = 0; i < p->n_owned; i++)
        w->has[i] = d->is_fluid[i] &&
                    mf_walls_sums(sim->walls, w->tables, &p->pos[3 * i], &w->pt[i]);
    return 0;
}

void mps_wall_keep_forces(mps_data *d, const mf_sim *sim)
{
    memcpy(d->wall->f, d->acc, 3 * sim->p->n_owned * sizeof *d->acc);
}

/* The wall's velocity at a point, the no-slip weights' average over the
 * solids within reach (one solid: its velocity). */
static void wall_velocity(const mf_wall_point *pt, double u[3])
{
    for (int a = 0; a < 3; a++)
        u[a] = pt->s.visc > 0 ? pt->visc_u[a] / pt->s.visc : 0;
}

/* The acceleration the wall's pressure continues with (mf_wall_gradient_add):
 * the force acceleration f (the hydrostatic continuation), and across the
 * face, where the particle approaches the wall faster than f alone would
 * take it, (u*_i - u_w).n / dt, the rate at which the pressure equation
 * stops the approach (the source's wall term, mps_wall_divergence). At rest
 * both are f; a particle sliding along a wall feels no drag from it; one
 * leaving the wall is not pulled back (as the robust scheme's wall
 * particles, whose sources are clipped at zero). Measured on the resting
 * tank (W/H 2, l0 0.01, to 1.5 s, largest speed / sqrt(gH) after 0.5 s):
 * f alone 0.48, (u* - u_w).n/dt both ways 0.62, this 0.33 (particle walls
 * 0.22); hydrostatic2D's error 0.0023 (particle walls 0.0023). */
void mps_wall_keep_approach(mps_data *d, const mf_sim *sim, double dt)
{
    struct mps_wall *w = d->wall;
    for (size_t i = 0; i < sim->p->n_owned; i++) {
        if (!w->has[i])
            continue;
        const mf_wall_point *pt = &w->pt[i];
        double uw[3], *a = &w->f[3 * i];
        wall_velocity(pt, uw);
        const double *n = pt->normal, *u = &sim->p->vel[3 * i];
        double an = 0, rn = 0;
        for (int k = 0; k < 3; k++) {
            an += a[k] * n[k];
            rn += (u[k] - uw[k]) * n[k];
        }
        const double push = fmin(rn / dt - an, 0.0); /* a wall pushes, never pulls */
        for (int k = 0; k < 3; k++)
            a[k] += push * n[k];
    }
}

void mps_wall_number_density(const mps_data *d, const mf_sim *sim, double *n)
{
    const struct mps_wall *w = d->wall;
    for (size_t i = 0; i < sim->p->n_owned; i++)
        if (w->has[i])
            n[i] += mf_wall_number_density(&w->pt[i].s);
}

void mps_wall_viscous(mps_data *d, const mf_sim *sim, double nu)
{
    const struct mps_wall *w = d->wall;
    for (size_t i = 0; i < sim->p->n_owned; i++)
        if (w->has[i])
            mf_wall_viscous_add(&w->pt[i].s, &d->k_lap, nu, &sim->p->vel[3 * i],
                                w->pt[i].visc_u, &d->acc[3 * i]);
}

/* The walls' virtual points in particle i's LSMPS fit (mf_lsmps_extra_fn):
 * every lattice point of every solid within reach (mf_wall_points_each,
 * the lattice the wall weight tables sum over), carrying the no-slip
 * velocity continued through the face (mf_wall_noslip_factor),
 *   u_v = u_w - (s_v / d)(u_i - u_w) = 2 u_w - u_m,
 * s_v the point's depth behind the face, d the particle's distance to it
 * (at least l0/4, as mf_wall_sums.visc), u_m the velocity at the point's
 * mirror image in the face interpolated linearly between the face (u_w) and
 * the particle (Morris, Fox & Zhu 1997; exact for a field linear in the
 * distance to the face). Measured against u_v = u_w on the channels'
 * `validate` error (bench/wall_weight_channels.sh): poiseuille2D at H/10
 * 0.0132 against 0.165, couette2D 0.00452 against 0.0799; u_v = u_w does
 * not converge (0.0907 at H/20): a fit that sees u_w a whole lattice deep
 * has its zero behind the face. */
typedef struct ls_wall_ctx {
    const mps_data *d;
    const mf_sim *sim;
} ls_wall_ctx;

typedef struct ls_point_ctx {
    mf_lsmps_point_fn add;
    void *acc;
    double du[3];  /* u_w - u_i */
    double d_min;  /* l0/4 */
} ls_point_ctx;

static void ls_point(void *ctx, const double r[3], double depth, double dist, double sign)
{
    const ls_point_ctx *pc = ctx;
    const double phi = mf_wall_noslip_factor(depth, dist, pc->d_min);
    const double df[3] = {phi * pc->du[0], phi * pc->du[1], phi * pc->du[2]};
    pc->add(pc->acc, r, df, sign);
}

static void ls_points(const void *ctx, size_t i, mf_lsmps_point_fn add, void *acc)
{
    const ls_wall_ctx *c = ctx;
    const mps_data *d = c->d;
    const mf_sim *sim = c->sim;
    const struct mps_wall *w = d->wall;
    if (!w->has[i])
        return;
    const double *x = &sim->p->pos[3 * i], *ui = &sim->p->vel[3 * i];
    const double reach = mf_wall_tables_reach(w->tables);
    for (size_t k = 0; k < sim->walls->n; k++) {
        const mf_wall *s = &sim->walls->w[k];
        double n[3], u[3], us[3];
        if (!(mf_wall_distance(s, x, n) < reach))
            continue;
        /* the solid's velocity, its surface velocity along the face only
         * (as mf_walls_sums) */
        mf_wall_velocity(s, x, false, u);
        mf_wall_velocity(s, x, true, us);
        double sn = 0;
        for (int a = 0; a < 3; a++)
            sn += (us[a] - u[a]) * n[a];
        ls_point_ctx pc = {.add = add, .acc = acc, .d_min = 0.25 * sim->l0};
        for (int a = 0; a < 3; a++)
            pc.du[a] = (a < sim->dim ? us[a] - sn * n[a] : 0.0) - ui[a];
        mf_wall_points_each(s, w->tables, sim->dim, sim->l0, d->k_lap.re, x, ls_point, &pc);
    }
}

size_t mps_wall_lsmps_laplacian(mps_data *d, const mf_sim *sim, const mf_pairs *v, double nu,
                                uint8_t *failed)
{
    const ls_wall_ctx c = {d, sim};
    return mf_lsmps_laplacian_add_extra(v, &d->k_lap, sim->p->vel, nu, d->is_fluid,
                                        d->not_dummy, ls_points, &c, d->acc, failed);
}

void mps_wall_viscous_where(mps_data *d, const mf_sim *sim, double nu, const uint8_t *mask)
{
    const struct mps_wall *w = d->wall;
    for (size_t i = 0; i < sim->p->n_owned; i++)
        if (w->has[i] && mask[i])
            mf_wall_viscous_add(&w->pt[i].s, &d->k_lap, nu, &sim->p->vel[3 * i],
                                w->pt[i].visc_u, &d->acc[3 * i]);
}

void mps_wall_divergence(const mps_data *d, const mf_sim *sim, const uint8_t *imask,
                         double *div)
{
    const struct mps_wall *w = d->wall;
    for (size_t i = 0; i < sim->p->n_owned; i++) {
        if (!w->has[i] || !imask[i])
            continue;
        double uw[3];
        wall_velocity(&w->pt[i], uw);
        div[i] += mf_wall_divergence(&w->pt[i].s, &d->k_grad, &sim->p->vel[3 * i], uw);
    }
}

void mps_wall_gradient(const mps_data *d, const mf_sim *sim, const double *pressure,
                       const double *phat, double rho)
{
    const struct mps_wall *w = d->wall;
    for (size_t i = 0; i < sim->p->n_owned; i++)
        if (w->has[i])
            mf_wall_gradient_add(&w->pt[i].s, &d->k_grad, pressure[i], phat[i], rho,
                                 &w->f[3 * i], &d->grad[3 * i]);
}

int mps_wall_collide(mps_data *d, mf_sim *sim, double dt)
{
    const mf_walls *ws = sim->walls;
    if (!ws)
        return 0;
    mf_particles *p = sim->p;
    const double distance = 0.5 * d->s.collision_distance * sim->l0; /* half a pair's */
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->is_fluid[i])
            continue;
        double *x = &p->pos[3 * i], *u = &p->vel[3 * i];
        for (size_t k = 0; k < ws->n; k++) {
            double nrm[3], uw[3], du[3];
            const double dist = mf_wall_distance(&ws->w[k], x, nrm);
            if (!(dist < distance))
                continue;
            mf_wall_velocity(&ws->w[k], x, true, uw);
            if (!mf_wall_collision(dist, nrm, uw, distance, d->s.restitution, u, du))
                continue;
            for (int a = 0; a < sim->dim; a++) {
                u[a] += du[a];
                x[a] += dt * du[a];
            }
            d->wall->collisions++;
        }
    }
    return 0;
}

void mps_wall_report(const struct mps_wall *w, mf_log *log)
{
    if (w)
        mf_log_printf(log, MF_LOG_QUIET, "MPS walls: wall weight, %ld face collisions\n",
                      w->collisions);
}
