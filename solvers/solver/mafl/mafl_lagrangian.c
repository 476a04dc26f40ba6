/* mafl_lagrangian.c: the Lagrangian phase of MPS-MAFL, the MPS module's
 * own step.
 *
 * densityReference n0 (the default): mps_lagrangian_step as it is; the
 * source of the pressure equation (eq. 14) is (n* - n0)/n0.
 *
 * densityReference startOfStep: the same phases of the MPS module in the
 * same order, with a source that measures only the compression of this
 * step's motion:
 *   n_eff = n0 + sum_{j moving} [w(|r*_ij|) - w(|r^n_ij|)]
 *              + (pairs with a wall or dummy particle: w linearised at r^n),
 * "moving" being fluid, inlet and outlet points. Why:
 *  - a fixed point's Lagrangian displacement slides it along the wall
 *    lattice by the same u dt every step; the wall part of n* changes with
 *    the phase of the lattice (about 5e-4 n0 at Courant number 0.2), a
 *    steady false source. With n0 it is positive beside the walls and
 *    negative one row further in, and only the clipping of negative
 *    pressures keeps a uniform channel flow uniform; linearised, the wall
 *    part changes only by motion toward or away from the wall, so a uniform
 *    flow gives no source at all;
 *  - MPS particles are material, MAFL points are not: an uneven placement
 *    of fixed points (where Lagrangian surface points meet fixed interior
 *    points) is no compression of the fluid, but with n0 it drives a
 *    spurious velocity every step.
 * densityReference divergence: the same, with the pairs of moving points
 * linearised too, n_eff = n0 + sum_j (dw/dr)(r^n_ij/|r^n_ij|).(d_i - d_j),
 * d = r* - r^n: the MPS divergence of this step's displacement, so the
 * source is -(rho/dt) <div u*> (a velocity-divergence source). Why: the
 * exact w(|r*_ij|) - w(|r^n_ij|) of startOfStep also has the second-order
 * term of a shear, pairs pulled apart by (du/dy dt)^2, which reads as an
 * expansion; in a channel it drove a steady flow into the walls and the
 * flow rate fell by 9% over 1 m at l0 = H/10 (4.8% with dt halved: it is
 * O(dt^2) a step), not falling with l0 at a fixed Courant number. With
 * divergence the flow rate is the same at every section within 2e-4
 * (tests/test_mafl.c, part continuity).
 *
 * Both: nothing pulls a free surface back to its volume. On a resting box
 * under gravity (rule fixed) startOfStep loses 40% of the fluid points to
 * merging in 2 s while n0 keeps them all (its spurious velocity levels off
 * near 0.17 m/s, pure MPS about 0.07 m/s). So these are for flows without
 * a free surface (channels: the tutorials scalarAdvection and channelInflow
 * use divergence), n0 for the rest. README (MPS-MAFL) has the numbers.
 *
 * The MPS module's hook does it: mps_data.n_offset (rhs ~ (n*_i - n0 -
 * offset_i)/n0) with offset_i = n*_i - n_eff_i, filled by
 * mps_data.before_assembly once the lists and n* at r* exist. The phase is
 * then one call of mps_lagrangian_step in every case. */
#include <math.h>
#include <string.h>

#include "mafl.h"
#include "mf_error.h"

/* d/dr w(r) / r for w = re/r - 1 (0 outside (0, re)). */
static inline double dw_over_r(double r, double re)
{
    return (r > 0.0 && r < re) ? -re / (r * r * r) : 0.0;
}

static inline double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

typedef struct eff_ctx {
    const mps_data *m;
    const mf_particles *p;
    const mf_pairs *v;
    const double *xn;  /* r^n */
    double re, n0;
    bool linear, project;
    double *eff;
} eff_ctx;

/* wall_frame's sums over i's neighbours of the other sort. */
typedef struct frame_acc {
    bool mi;
    double c[3], sw, mean[3];
} frame_acc;

static inline bool frame_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const eff_ctx *e = ctx;
    frame_acc *f = acc;
    const size_t i = pr->i, j = pr->j;
    if (e->m->is_fluid[j] == f->mi)
        return true;
    const double *xi0 = &e->xn[3 * i], *xj0 = &e->xn[3 * j], *xj = &e->p->pos[3 * j];
    double r0[3] = {xi0[0] - xj0[0], xi0[1] - xj0[1], xi0[2] - xj0[2]};
    double d0 = sqrt(r0[0] * r0[0] + r0[1] * r0[1] + r0[2] * r0[2]);
    if (d0 >= e->re)
        return true;
    double w = (1.0 - d0 / e->re) * (1.0 - d0 / e->re);
    f->sw += w;
    for (int a = 0; a < 3; a++) {
        f->c[a] += w * r0[a];
        f->mean[a] += w * (xj[a] - xj0[a]);
    }
    return true;
}

/* Seen from i at r^n, its neighbours of the other sort (fixed ones for a
 * moving i, moving ones for a fixed i): the wall normal, the direction from
 * their centroid to i (smooth weight (1 - r/re)^2, so that it hardly
 * depends on where i sits along the wall lattice), and for a fixed i the
 * mean displacement of its moving neighbours. False if there are none. */
static bool wall_frame(const eff_ctx *e, size_t i, double nrm[3], double mean[3])
{
    frame_acc f = {e->m->is_fluid[i], {0, 0, 0}, 0, {0, 0, 0}};
    mf_pairs_row(e->v, i, NULL, frame_pair, e, &f);
    memcpy(mean, f.mean, sizeof f.mean);
    double len = sqrt(f.c[0] * f.c[0] + f.c[1] * f.c[1] + f.c[2] * f.c[2]);
    if (!(len > 0) || !(f.sw > 0))
        return false;
    for (int a = 0; a < 3; a++) {
        nrm[a] = f.c[a] / len;
        mean[a] /= f.sw;
    }
    return true;
}

/* effective_density's sum over i's neighbours. */
typedef struct eff_acc {
    double sum, nrm[3], mean[3], mean_n;
    bool mi, wall;
} eff_acc;

static inline bool eff_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const eff_ctx *e = ctx;
    eff_acc *s = acc;
    const size_t i = pr->i, j = pr->j;
    const double *xi = &e->p->pos[3 * i], *xi0 = &e->xn[3 * i];
    const bool mi = s->mi, mj = e->m->is_fluid[j];
    if (!mi && !mj)
        return true;
    const double *xj = &e->p->pos[3 * j], *xj0 = &e->xn[3 * j];
    double r0[3] = {xi0[0] - xj0[0], xi0[1] - xj0[1], xi0[2] - xj0[2]};
    double d0 = sqrt(dot3(r0, r0));
    double g = dw_over_r(d0, e->re);
    /* The relative displacement (a fixed particle's is zero: x = x0). */
    double rel[3];
    for (int a = 0; a < 3; a++)
        rel[a] = (xi[a] - xi0[a]) - (xj[a] - xj0[a]);
    if (mi && mj && !e->linear) {
        double r[3] = {xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]};
        s->sum += mf_weight(sqrt(dot3(r, r)), e->re) - mf_weight(d0, e->re);
    } else if (mi && mj) {
        s->sum += g * dot3(r0, rel);
    } else if (s->wall && mi) {
        s->sum += g * dot3(r0, s->nrm) * dot3(rel, s->nrm);
    } else if (s->wall) { /* rel = -(displacement of j) */
        double deform[3];
        for (int a = 0; a < 3; a++)
            deform[a] = rel[a] + s->mean[a];
        s->sum += g * (dot3(r0, deform) - dot3(r0, s->nrm) * s->mean_n);
    } else {
        s->sum += g * dot3(r0, rel);
    }
    return true;
}

static void eff_row(const void *ctx, size_t i)
{
    const eff_ctx *e = ctx;
    eff_acc s = {.sum = e->n0, .mi = e->m->is_fluid[i]};
    s.wall = e->project && wall_frame(e, i, s.nrm, s.mean);
    s.mean_n = dot3(s.mean, s.nrm);
    mf_pairs_row(e->v, i, NULL, eff_pair, e, &s);
    e->eff[i] = s.sum;
}

/* n_eff at r* (lists at r*, r^n from the field xn): pairs of moving points
 * exactly (linear false) or linearised like the rest (linear true); pairs
 * of a moving and a fixed particle linearised at r^n, where a rigid
 * motion along the wall counts only by its part normal to the wall
 * (wall_frame): sliding along the wall lattice changes the wall part of n
 * with the lattice's phase, which is no compression (with points that move,
 * whole rows slide in step and that false source built up kPa over a 1 m
 * channel). For a moving i that is its own displacement; for a wall
 * particle i the mean displacement of its moving neighbours, their
 * deformation (displacement minus the mean) counting in full. Only with
 * project (rules that move interior points): fixed points sit where the
 * wall lattice is symmetric, and in a corner the one normal is wrong (a
 * resting box with a free surface lost 64% of its points in 2 s with it). */
static int effective_density(const mps_data *m, const mf_sim *sim, const double *xn,
                             bool linear, bool project, double *eff)
{
    mf_pairs v;
    MF_CALL(mps_pairs(m, sim, m->h_nd, &v));
    const eff_ctx e = {m, sim->p, &v, xn, m->k_nd.re, m->k_nd.n0, linear, project, eff};
    mf_pairs_each(&v, NULL, eff_row, &e);
    return 0;
}

/* mps_data.before_assembly: offset_i = n*_i - n_eff_i for the unknowns. */
static int source_offset(mps_data *m, mf_sim *sim, void *ctx)
{
    mafl_data *d = ctx;
    const mf_particles *p = sim->p;
    const double *n = mf_particles_fd(p, m->f_number_density);
    const double *xn = mf_particles_fd(p, d->f_pos_n); /* r^n, reordered with the rest */
    /* Only moving interior points slide along the walls in step. */
    const bool project = d->rule != MAFL_RULE_FIXED;
    MF_CALL(effective_density(m, sim, xn, d->linear_source, project, d->n_offset));
    for (size_t i = 0; i < p->n_owned; i++)
        d->n_offset[i] = m->in_ppe[i] ? n[i] - d->n_offset[i] : 0.0;
    return 0;
}

int mafl_lagrangian(mafl_data *d, mf_sim *sim, double dt)
{
    mps_data *m = d->mps;
    /* d->n_offset may have been reallocated since the last step. */
    m->n_offset = d->incremental ? d->n_offset : NULL;
    m->before_assembly = d->incremental ? source_offset : NULL;
    m->before_assembly_ctx = d;
    MF_CALL(mps_lagrangian_step(m, sim, dt));
    return 0;
}
