/* mafl_reconfigure.c: where the computation points go (section 3.3), and
 * the point and convection velocities of eqs. 19-20. */
#include <math.h>
#include <string.h>

#include "mafl.h"
#include "mf_error.h"

/* Largest shift of one step, in l0: keeps a point within its neighbourhood. */
#define MAX_SHIFT 0.2

static void clamp_shift(double v[3], double limit)
{
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (len > limit)
        for (int a = 0; a < 3; a++)
            v[a] *= limit / len;
}

/* Unit vectors t[0], t[1] perpendicular to the unit normal nrm (t[1] unused
 * in 2-D). */
static void tangents(int dim, const double nrm[3], double t[2][3])
{
    if (dim == 2) {
        t[0][0] = -nrm[1];
        t[0][1] = nrm[0];
        t[0][2] = 0;
        memset(t[1], 0, sizeof t[1]);
        return;
    }
    double a[3] = {0, 0, 0};
    int smallest = 0;
    for (int k = 1; k < 3; k++)
        if (fabs(nrm[k]) < fabs(nrm[smallest]))
            smallest = k;
    a[smallest] = 1;
    t[0][0] = a[1] * nrm[2] - a[2] * nrm[1];
    t[0][1] = a[2] * nrm[0] - a[0] * nrm[2];
    t[0][2] = a[0] * nrm[1] - a[1] * nrm[0];
    double len = sqrt(t[0][0] * t[0][0] + t[0][1] * t[0][1] + t[0][2] * t[0][2]);
    for (int k = 0; k < 3; k++)
        t[0][k] /= len;
    t[1][0] = nrm[1] * t[0][2] - nrm[2] * t[0][1];
    t[1][1] = nrm[2] * t[0][0] - nrm[0] * t[0][2];
    t[1][2] = nrm[0] * t[0][1] - nrm[1] * t[0][0];
}

/* The point queries below run around point i (mf_grid_near on the grid at
 * r^L) and leave i itself out. */
typedef struct near_ctx {
    size_t i;
    const int32_t *kind0, *flags;
    double r_norm, r_surf, re;
    const double *t; /* surface_shift's tangent */
    double l0;
} near_ctx;

static inline bool on_surface(const near_ctx *c, size_t j)
{
    return c->kind0[j] == MF_FLUID && (c->flags[j] & MPS_FLAG_SURFACE);
}

typedef struct shift_acc {
    double centroid[3], mean[3];
    size_t nall, nsurf;
} shift_acc;

/* The centroid of the neighbours within r_norm, the mean offset of the
 * surface neighbours within r_surf. */
static inline bool shift_point(void *acc, const void *ctx, size_t j, const double r[3],
                               double d2)
{
    const near_ctx *c = ctx;
    shift_acc *a = acc;
    if (j == c->i)
        return true;
    double dist = sqrt(d2);
    if (dist < c->r_norm) {
        for (int q = 0; q < 3; q++)
            a->centroid[q] += r[q];
        a->nall++;
    }
    if (dist < c->r_surf && on_surface(c, j)) {
        for (int q = 0; q < 3; q++)
            a->mean[q] += r[q];
        a->nsurf++;
    }
    return true;
}

typedef struct side_acc {
    bool ahead, behind;
} side_acc;

/* Surface neighbours within r_surf ahead of and behind i along the tangent. */
static inline bool side_point(void *acc, const void *ctx, size_t j, const double r[3], double d2)
{
    const near_ctx *c = ctx;
    side_acc *a = acc;
    if (j == c->i || !on_surface(c, j) || d2 >= c->r_surf * c->r_surf)
        return true;
    double s = r[0] * c->t[0] + r[1] * c->t[1] + r[2] * c->t[2];
    a->ahead = a->ahead || s > 0.25 * c->l0;
    a->behind = a->behind || s < -0.25 * c->l0;
    return true;
}

/* A free-surface point follows the flow and is re-spaced along the
 * surface: it moves a share of the way toward the mean of its surface
 * neighbours (within 1.5 l0), projected on the tangent plane. Only a point
 * with surface neighbours on both sides along each tangent moves: at a
 * contact line or a corner the one-sided mean would drag it off its place. */
static void surface_shift(const mafl_data *d, const mf_sim *sim, size_t i, const int32_t *kind0,
                          const int32_t *flags, double out[3])
{
    const double l0 = sim->l0, *xi = &d->pos_l[3 * i];
    near_ctx c = {i, kind0, flags, d->s.re_interpolation * l0, 1.5 * l0, 0, NULL, l0};
    shift_acc a = {{0, 0, 0}, {0, 0, 0}, 0, 0};
    mf_grid_near(d->grid, xi, shift_point, &c, &a);
    memset(out, 0, 3 * sizeof *out);
    if (a.nall == 0 || a.nsurf < 2)
        return;
    /* Outward normal: away from the neighbours' centroid. */
    double nrm[3], len = 0;
    for (int q = 0; q < 3; q++) {
        nrm[q] = -a.centroid[q] / (double)a.nall;
        len += nrm[q] * nrm[q];
    }
    len = sqrt(len);
    if (len < 1e-3 * l0)
        return;
    for (int q = 0; q < 3; q++)
        nrm[q] /= len;
    double t[2][3];
    tangents(sim->dim, nrm, t);
    /* Surrounded along each tangent? */
    for (int tk = 0; tk < sim->dim - 1; tk++) {
        side_acc s = {false, false};
        c.t = t[tk];
        mf_grid_near(d->grid, xi, side_point, &c, &s);
        if (!s.ahead || !s.behind)
            return;
    }
    double mean[3];
    for (int q = 0; q < 3; q++)
        mean[q] = a.mean[q] / (double)a.nsurf;
    double normal_part = mean[0] * nrm[0] + mean[1] * nrm[1] + mean[2] * nrm[2];
    for (int q = 0; q < 3; q++)
        out[q] = d->s.surface_shift * (mean[q] - normal_part * nrm[q]);
    if (sim->dim == 2)
        out[2] = 0;
    clamp_shift(out, MAX_SHIFT * l0);
}

typedef struct relax_acc {
    double sum[3], centroid[3];
    bool surface; /* a free-surface point among the neighbours */
} relax_acc;

/* The eq. 5 sum of the particle distribution, sum_j w_ij r_ij/|r_ij|^2,
 * and the centroid of the same neighbours. */
static inline bool relax_point(void *acc, const void *ctx, size_t j, const double r[3],
                               double d2)
{
    const near_ctx *c = ctx;
    relax_acc *a = acc;
    if (j == c->i)
        return true;
    double w = mf_weight(sqrt(d2), c->re);
    if (w <= 0)
        return true;
    for (int q = 0; q < 3; q++) {
        a->sum[q] += w * r[q] / d2;
        a->centroid[q] += r[q];
    }
    a->surface = a->surface || (c->kind0 && on_surface(c, j));
    return true;
}

/* Rule relax: toward an even distribution, against the imbalance of the
 * neighbourhood, dl0^2/n0 sum_j w_ij (r_j - r_i)/|r_ij|^2 (the gradient
 * operator of eq. 5 applied to the particle distribution). Within reach of
 * the free surface only the part along the surface is kept, as Lind et al.
 * (2012) do with their shifting: the empty side reads as an imbalance, and
 * the full shift lifted the rows under the surface into the surface layer,
 * which then pressed them down against the flow every step (a steady
 * 0.13 m/s upward velocity under the surface of a resting box, points
 * standing still). The normal: away from the neighbours' centroid. */
static void relax_shift(const mafl_data *d, const mf_sim *sim, const int32_t *kind0,
                        const int32_t *flags, size_t i, double out[3])
{
    const mf_kernel *k = &d->mps->k_grad;
    const near_ctx c = {.i = i, .kind0 = kind0, .flags = flags, .re = k->re};
    relax_acc a = {{0, 0, 0}, {0, 0, 0}, false};
    mf_grid_near(d->grid, &d->pos_l[3 * i], relax_point, &c, &a);
    const double scale = -d->s.shift * k->dim * sim->l0 * sim->l0 / k->n0;
    for (int q = 0; q < 3; q++)
        out[q] = scale * a.sum[q];
    if (sim->dim == 2)
        out[2] = 0;
    double len = sqrt(a.centroid[0] * a.centroid[0] + a.centroid[1] * a.centroid[1] +
                      a.centroid[2] * a.centroid[2]);
    if (a.surface && len > 0) {
        double normal_part = 0;
        for (int q = 0; q < 3; q++)
            normal_part += out[q] * a.centroid[q] / len;
        for (int q = 0; q < 3; q++)
            out[q] -= normal_part * a.centroid[q] / len;
    }
    clamp_shift(out, MAX_SHIFT * sim->l0);
}

typedef struct sided_acc {
    double sum[3];
    size_t count;
    bool emitter; /* an inlet or outlet point among the neighbours */
} sided_acc;

static inline bool sided_point(void *acc, const void *ctx, size_t j, const double r[3],
                               double d2)
{
    const near_ctx *c = ctx;
    sided_acc *a = acc;
    if (j == c->i || d2 >= c->re * c->re)
        return true;
    if (c->kind0[j] == MF_INLET || c->kind0[j] == MF_OUTLET) {
        a->emitter = true;
        return false;
    }
    for (int q = 0; q < 3; q++)
        a->sum[q] += r[q];
    a->count++;
    return true;
}

/* The MPS flag (n* < beta n0, eq. 18) also marks interior points that only
 * lack a neighbour or two: beside the gap a moving point leaves at an inlet,
 * or where points are sparse. Such a point moving with the full flow would
 * catch up with the interior points ahead and merge with them. A point on a
 * free surface has all its neighbours on one side: the centroid of its
 * neighbours within reInterpolation lies more than a fifth of l0 away; and
 * no inlet or outlet point is among them (the first column beside an
 * inlet's gap is one-sided by that test, and moving with the full flow it
 * packed the points after it to about 0.75 l0). */
static bool one_sided(const mafl_data *d, const mf_sim *sim, const int32_t *kind0, size_t i)
{
    const near_ctx c = {.i = i, .kind0 = kind0, .re = d->s.re_interpolation * sim->l0};
    sided_acc a = {{0, 0, 0}, 0, false};
    mf_grid_near(d->grid, &d->pos_l[3 * i], sided_point, &c, &a);
    if (a.emitter)
        return false;
    if (a.count == 0)
        return true;
    double off2 = 0;
    for (int q = 0; q < 3; q++)
        off2 += (a.sum[q] / a.count) * (a.sum[q] / a.count);
    return off2 > 0.04 * sim->l0 * sim->l0;
}

int mafl_reconfigure(mafl_data *d, mf_sim *sim, double dt)
{
    mf_particles *p = sim->p;
    const long n = (long)p->n;
    const double *xn = mf_particles_fd(p, d->f_pos_n);
    const int32_t *kind0 = mf_particles_fi(p, d->f_kind);
    const int32_t *flags = mf_particles_fi(p, d->mps->f_flags);
    double *uc = mf_particles_fd(p, d->f_point_vel), *ua = mf_particles_fd(p, d->f_conv_vel);
    const double *xl = d->pos_l;
    double *xnew = d->pos_new;
#pragma omp parallel for schedule(dynamic, 256)
    for (long i = 0; i < n; i++) {
        double *out = &xnew[3 * i];
        const double *a = &xn[3 * i], *b = &xl[3 * i];
        double shift[3] = {0, 0, 0};
        if (kind0[i] != MF_FLUID) {
            /* Walls, dummies, inlets and outlets return to r^n. */
            memcpy(out, a, 3 * sizeof *out);
        } else if ((flags[i] & MPS_FLAG_SURFACE) && one_sided(d, sim, kind0, (size_t)i)) {
            /* Free surface: Lagrangian, re-spaced along the surface. */
            if (d->s.surface_shift > 0)
                surface_shift(d, sim, (size_t)i, kind0, flags, shift);
            for (int c = 0; c < 3; c++)
                out[c] = b[c] + shift[c];
        } else {
            switch (d->rule) {
            case MAFL_RULE_FIXED:
                memcpy(out, a, 3 * sizeof *out);
                break;
            case MAFL_RULE_FRACTION:
                for (int c = 0; c < 3; c++)
                    out[c] = a[c] + d->s.fraction * (b[c] - a[c]);
                break;
            case MAFL_RULE_RELAX:
                relax_shift(d, sim, kind0, flags, (size_t)i, shift);
                for (int c = 0; c < 3; c++)
                    out[c] = b[c] + shift[c];
                break;
            case MAFL_RULE_LAGRANGIAN:
                memcpy(out, b, 3 * sizeof *out);
                break;
            }
        }
    }
    /* Moving points: pairs that came too close move apart rather than
     * merge (mafl_separation.c). */
    d->last_separated = 0;
    if ((d->rule == MAFL_RULE_FRACTION || d->rule == MAFL_RULE_RELAX) && d->s.separation > 0)
        MF_CALL(mafl_separate(d, sim, d->shift));
#pragma omp parallel for schedule(static)
    for (long i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            uc[3 * i + c] = (xnew[3 * i + c] - xn[3 * i + c]) / dt; /* eq. 19 */
            ua[3 * i + c] = (xl[3 * i + c] - xnew[3 * i + c]) / dt; /* eq. 20 */
        }
    return 0;
}
