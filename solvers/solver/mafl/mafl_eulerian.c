/* mafl_eulerian.c: the Eulerian phase of MPS-MAFL (section 3.3).
 *
 * The value at the new point r^{n+1}_i = r^L_i - u^a dt is the Lagrangian
 * field read |u^a| dt upstream of r^L_i (eq. 21): a 1-D convection along
 * the streamline. Each point gets its own grid along e = u^a/|u^a| through
 * r^L_i, spacing dr: k = -2, -1 upstream, +1 downstream, the point itself at
 * k = 0. A grid value is the weighted mean of the neighbours in a thin disk
 * around the grid point (eq. 23):
 *   <f>_k = sum_j f_j w(|r_j - r_k|) / sum_j w(|r_j - r_k|),  w = re/r - 1,
 * over fluid, inlet and outlet points (walls carry no scalar and no flow)
 * with |(r_j - r_k).e| <= thickness/2. The convection module then advances
 * f_i with q = |u^a| dt / dr (eqs. 24-26).
 *
 * Accuracy: the singular weight makes <f>_k exact where a point sits on
 * the grid point (a lattice with the flow along a lattice direction);
 * between points the weighted mean is a first-order estimate, and its
 * error enters every step: on irregular points it limits the order of the
 * whole scheme to one, whatever the convection scheme.
 *
 * A grid point with no neighbour in its disk (the edge of the fluid) takes
 * its inner neighbour's value: zero gradient. Where |u^a| dt > dr the grid
 * is widened to dr = |u^a| dt (q = 1) and counted. */
#include <math.h>
#include <string.h>

#include "mafl.h"
#include "mf_error.h"

static inline bool is_source(int kind)
{
    return kind == MF_FLUID || kind == MF_INLET || kind == MF_OUTLET;
}

typedef struct carried {
    int nc;                            /* number of carried components */
    const double *src[MAFL_MAX_CARRIED];
    int stride[MAFL_MAX_CARRIED];      /* 3 for velocity components, 1 for scalars */
} carried;

static inline double carried_at(const carried *cf, int c, size_t j)
{
    return cf->src[c][(size_t)cf->stride[c] * j];
}

typedef struct disk_ctx {
    const carried *cf;
    const int32_t *kind0;
    const double *e;  /* the grid's direction */
    double re, half, exact;
} disk_ctx;

typedef struct disk_acc {
    double sum_w, sum[MAFL_MAX_CARRIED];
    long on_point;    /* a point on the grid point (its values are exact), or -1 */
} disk_acc;

/* One neighbour of the grid point x in the disk: weight re/r - 1 (eq. 23). */
static inline bool disk_point(void *acc, const void *ctx, size_t j, const double r[3], double d2)
{
    const disk_ctx *c = ctx;
    disk_acc *a = acc;
    if (!is_source(c->kind0[j]))
        return true;
    double along = r[0] * c->e[0] + r[1] * c->e[1] + r[2] * c->e[2];
    if (fabs(along) > c->half)
        return true;
    double dist = sqrt(d2);
    if (dist >= c->re)
        return true;
    if (dist < c->exact) { /* on the grid point: w is infinite */
        a->on_point = (long)j;
        return false;
    }
    double w = c->re / dist - 1.0;
    a->sum_w += w;
    for (int k = 0; k < c->cf->nc; k++)
        a->sum[k] += w * carried_at(c->cf, k, j);
    return true;
}

/* eq. 23 at x: writes the nc grid values and returns true, or false if the
 * disk holds no point. */
static bool grid_value(const mafl_data *d, const carried *cf, const int32_t *kind0,
                       const double x[3], const double e[3], double re, double half,
                       double *out)
{
    const disk_ctx c = {cf, kind0, e, re, half, 1e-9 * re};
    disk_acc a = {.sum_w = 0, .on_point = -1};
    mf_grid_near(d->grid, x, disk_point, &c, &a);
    if (a.on_point >= 0) {
        for (int k = 0; k < cf->nc; k++)
            out[k] = carried_at(cf, k, (size_t)a.on_point);
        return true;
    }
    if (!(a.sum_w > 0))
        return false;
    for (int k = 0; k < cf->nc; k++)
        out[k] = a.sum[k] / a.sum_w;
    return true;
}

int mafl_eulerian(mafl_data *d, mf_sim *sim, double dt)
{
    mf_particles *p = sim->p;
    const size_t n = p->n;
    const int32_t *kind0 = mf_particles_fi(p, d->f_kind);
    const double *ua = mf_particles_fd(p, d->f_conv_vel);
    carried cf = {0};
    for (int c = 0; c < sim->dim; c++) {
        cf.src[cf.nc] = p->vel + c;
        cf.stride[cf.nc++] = 3;
    }
    for (int k = 0; k < d->nscalars; k++) {
        cf.src[cf.nc] = mf_particles_fd(p, d->f_scalar[k]);
        cf.stride[cf.nc++] = 1;
    }
    const double l0 = sim->l0, re = d->s.re_interpolation * l0, dr0 = d->s.grid_spacing * l0;
    const mf_convection_ops *ops = d->conv_ops;
    const void *scheme = d->conv.data;
    double q_max = 0;
    long limited = 0;
#pragma omp parallel for schedule(dynamic, 256) reduction(max : q_max) reduction(+ : limited)
    for (long ii = 0; ii < (long)n; ii++) {
        const size_t i = (size_t)ii;
        for (int c = 0; c < cf.nc; c++)
            d->value[c * n + i] = carried_at(&cf, c, i); /* f^L */
        d->convected[i] = 0;
        if (kind0[i] != MF_FLUID && kind0[i] != MF_OUTLET)
            continue;
        d->convected[i] = 1;
        const double *u = &ua[3 * i];
        const double speed = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        const double travel = speed * dt;
        if (!(travel > 1e-12 * l0))
            continue; /* the point is where the fluid is: f^{n+1} = f^L */
        double dr = dr0;
        if (travel > dr) {
            dr = travel;
            limited++;
        }
        const double q = travel / dr;
        if (q > q_max)
            q_max = q;
        const double e[3] = {u[0] / speed, u[1] / speed, u[2] / speed};
        const double half = 0.5 * d->s.disk_thickness * dr;
        const double *xi = &d->pos_l[3 * i];
        /* Grid values at k = -2, -1, +1 (eq. 23). */
        static const int offsets[3] = {-2, -1, 1};
        double g[3][MAFL_MAX_CARRIED];
        bool found[3];
        for (int s = 0; s < 3; s++) {
            double x[3];
            for (int a = 0; a < 3; a++)
                x[a] = xi[a] + offsets[s] * dr * e[a];
            found[s] = grid_value(d, &cf, kind0, x, e, re, half, g[s]);
        }
        for (int c = 0; c < cf.nc; c++) {
            double fi = carried_at(&cf, c, i);
            double fm1 = found[1] ? g[1][c] : fi;
            double fm2 = found[0] ? g[0][c] : fm1;
            double fp1 = found[2] ? g[2][c] : fi;
            const double f[4] = {fm2, fm1, fi, fp1};
            d->value[c * n + i] = ops->convect(scheme, f, q);
        }
    }
    d->q_max = q_max;
    d->q_limited += limited;
    return 0;
}
