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

/* A free-surface point follows the flow and is re-spaced along the
 * surface: it moves a share of the way toward the mean of its surface
 * neighbours (within 1.5 l0), projected on the tangent plane. Only a point
 * with surface neighbours on both sides along each tangent moves: at a
 * contact line or a corner the one-sided mean would drag it off its place. */
static void surface_shift(const mafl_data *d, const mf_sim *sim, size_t i, const int32_t *kind0,
                          const int32_t *flags, double out[3])
{
    const double l0 = sim->l0, *xi = &d->pos_l[3 * i];
    const double r_surf = 1.5 * l0, r_norm = d->s.re_interpolation * l0;
    double centroid[3] = {0, 0, 0}, mean[3] = {0, 0, 0};
    size_t nall = 0, nsurf = 0;
    long cells[27];
    int nc = mafl_cells_near(&d->grid, xi, cells);
    for (int c = 0; c < nc; c++)
        for (size_t k = d->grid.cell_start[cells[c]]; k < d->grid.cell_start[cells[c] + 1]; k++) {
            size_t j = d->grid.order[k];
            if (j == i)
                continue;
            const double *xj = &d->pos_l[3 * j];
            double r[3] = {xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]};
            double dist = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
            if (dist < r_norm) {
                for (int a = 0; a < 3; a++)
                    centroid[a] += r[a];
                nall++;
            }
            if (dist < r_surf && kind0[j] == MF_FLUID && (flags[j] & MPS_FLAG_SURFACE)) {
                for (int a = 0; a < 3; a++)
                    mean[a] += r[a];
                nsurf++;
            }
        }
    memset(out, 0, 3 * sizeof *out);
    if (nall == 0 || nsurf < 2)
        return;
    /* Outward normal: away from the neighbours' centroid. */
    double nrm[3], len = 0;
    for (int a = 0; a < 3; a++) {
        nrm[a] = -centroid[a] / (double)nall;
        len += nrm[a] * nrm[a];
    }
    len = sqrt(len);
    if (len < 1e-3 * l0)
        return;
    for (int a = 0; a < 3; a++)
        nrm[a] /= len;
    double t[2][3];
    tangents(sim->dim, nrm, t);
    /* Surrounded along each tangent? */
    for (int tk = 0; tk < sim->dim - 1; tk++) {
        bool ahead = false, behind = false;
        for (int c = 0; c < nc; c++)
            for (size_t k = d->grid.cell_start[cells[c]]; k < d->grid.cell_start[cells[c] + 1];
                 k++) {
                size_t j = d->grid.order[k];
                if (j == i || kind0[j] != MF_FLUID || !(flags[j] & MPS_FLAG_SURFACE))
                    continue;
                const double *xj = &d->pos_l[3 * j];
                double r[3] = {xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]};
                if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] >= r_surf * r_surf)
                    continue;
                double s = r[0] * t[tk][0] + r[1] * t[tk][1] + r[2] * t[tk][2];
                ahead = ahead || s > 0.25 * l0;
                behind = behind || s < -0.25 * l0;
            }
        if (!ahead || !behind)
            return;
    }
    for (int a = 0; a < 3; a++)
        mean[a] /= (double)nsurf;
    double normal_part = mean[0] * nrm[0] + mean[1] * nrm[1] + mean[2] * nrm[2];
    for (int a = 0; a < 3; a++)
        out[a] = d->s.surface_shift * (mean[a] - normal_part * nrm[a]);
    if (sim->dim == 2)
        out[2] = 0;
    clamp_shift(out, MAX_SHIFT * l0);
}

/* Rule relax: toward an even distribution, against the imbalance of the
 * neighbourhood, dl0^2/n0 sum_j w_ij (r_j - r_i)/|r_ij|^2 (the gradient
 * operator of eq. 5 applied to the particle distribution). */
static void relax_shift(const mafl_data *d, const mf_sim *sim, size_t i, double out[3])
{
    const mf_kernel *k = &d->mps->k_grad;
    const double *xi = &d->pos_l[3 * i];
    double sum[3] = {0, 0, 0};
    long cells[27];
    int nc = mafl_cells_near(&d->grid, xi, cells);
    for (int c = 0; c < nc; c++)
        for (size_t m = d->grid.cell_start[cells[c]]; m < d->grid.cell_start[cells[c] + 1]; m++) {
            size_t j = d->grid.order[m];
            if (j == i)
                continue;
            const double *xj = &d->pos_l[3 * j];
            double r[3] = {xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]};
            double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            double w = mf_weight(sqrt(r2), k->re);
            if (w <= 0)
                continue;
            for (int a = 0; a < 3; a++)
                sum[a] += w * r[a] / r2;
        }
    const double scale = -d->s.shift * k->dim * sim->l0 * sim->l0 / k->n0;
    for (int a = 0; a < 3; a++)
        out[a] = scale * sum[a];
    if (sim->dim == 2)
        out[2] = 0;
    clamp_shift(out, MAX_SHIFT * sim->l0);
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
    const double *xi = &d->pos_l[3 * i], re = d->s.re_interpolation * sim->l0;
    double sum[3] = {0, 0, 0};
    size_t count = 0;
    long cells[27];
    int nc = mafl_cells_near(&d->grid, xi, cells);
    for (int c = 0; c < nc; c++)
        for (size_t m = d->grid.cell_start[cells[c]]; m < d->grid.cell_start[cells[c] + 1]; m++) {
            size_t j = d->grid.order[m];
            const double *xj = &d->pos_l[3 * j];
            double r[3] = {xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]};
            double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            if (j == i || r2 >= re * re)
                continue;
            if (kind0[j] == MF_INLET || kind0[j] == MF_OUTLET)
                return false;
            for (int a = 0; a < 3; a++)
                sum[a] += r[a];
            count++;
        }
    if (count == 0)
        return true;
    double off2 = 0;
    for (int a = 0; a < 3; a++)
        off2 += (sum[a] / count) * (sum[a] / count);
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
                relax_shift(d, sim, (size_t)i, shift);
                for (int c = 0; c < 3; c++)
                    out[c] = b[c] + shift[c];
                break;
            case MAFL_RULE_LAGRANGIAN:
                memcpy(out, b, 3 * sizeof *out);
                break;
            }
        }
        for (int c = 0; c < 3; c++) {
            uc[3 * i + c] = (out[c] - a[c]) / dt; /* eq. 19 */
            ua[3 * i + c] = (b[c] - out[c]) / dt; /* eq. 20 */
        }
    }
    return 0;
}
