/* control_shape.c: the regions and targets of the control forces (see
 * control_shape.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "control_shape.h"
#include "mf_error.h"
#include "mf_trimesh.h"

const char *const control_shape_types[] = {"box", "sphere", "mesh", "point", NULL};

/* Signed distance to the box [lo, hi] (negative inside), on the first dim axes. */
static double box_phi(const double lo[3], const double hi[3], const double x[3], int dim)
{
    double out = 0, in = -INFINITY;
    for (int a = 0; a < dim; a++) {
        const double c = 0.5 * (lo[a] + hi[a]), h = 0.5 * (hi[a] - lo[a]);
        const double q = fabs(x[a] - c) - h;
        out += q > 0 ? q * q : 0;
        in = fmax(in, q);
    }
    return out > 0 ? sqrt(out) : in;
}

static double sphere_phi(const double c[3], double r, const double x[3], int dim)
{
    double d2 = 0;
    for (int a = 0; a < dim; a++)
        d2 += (x[a] - c[a]) * (x[a] - c[a]);
    return sqrt(d2) - r;
}

/* Lattice index of coordinate v on spacing h: the point (i + 1/2) h nearest. */
static long lattice_index(double v, double h)
{
    return (long)floor(v / h);
}

/* A mesh sampled on the case's lattice: the flags of the lattice points
 * inside the closed surface (|winding| > 1/2: either orientation). */
static int sample_mesh(control_shape *sh, const mf_trimesh *m)
{
    double mn[3], mx[3];
    mf_trimesh_bounds(m, mn, mx);
    size_t total = 1;
    for (int a = 0; a < 3; a++) {
        if (a >= sh->dim) {
            sh->base[a] = 0;
            sh->n[a] = 1;
            sh->lo[a] = sh->hi[a] = 0;
            continue;
        }
        sh->base[a] = lattice_index(mn[a], sh->l0) - 1;
        sh->n[a] = lattice_index(mx[a], sh->l0) + 2 - sh->base[a];
        sh->lo[a] = sh->base[a] * sh->l0;
        sh->hi[a] = (sh->base[a] + sh->n[a]) * sh->l0;
        if (sh->n[a] <= 0 || sh->n[a] > 1L << 20)
            return MF_ERROR(MF_ERR_INPUT, "mesh %s spans %g m along axis %d: %ld lattice points "
                            "at l0 = %g m (check its scale)", m->name, mx[a] - mn[a], a,
                            sh->n[a], sh->l0);
        total *= (size_t)sh->n[a];
    }
    if (total > (size_t)1 << 27)
        return MF_ERROR(MF_ERR_INPUT, "mesh %s: %zu lattice points in its bounding box at "
                        "l0 = %g m, too many to sample (check its scale)", m->name, total, sh->l0);
    sh->inside = calloc(total, 1);
    if (!sh->inside)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory sampling mesh %s", m->name);
    size_t k = 0;
    for (long iz = 0; iz < sh->n[2]; iz++)
        for (long iy = 0; iy < sh->n[1]; iy++)
            for (long ix = 0; ix < sh->n[0]; ix++, k++) {
                const long idx[3] = {sh->base[0] + ix, sh->base[1] + iy, sh->base[2] + iz};
                double x[3] = {0, 0, 0};
                for (int a = 0; a < sh->dim; a++)
                    x[a] = (idx[a] + 0.5) * sh->l0;
                sh->inside[k] = fabs(mf_trimesh_winding(m, x)) > 0.5;
            }
    return 0;
}

static int load_mesh(control_shape *sh, const char *who, const mf_sim *sim)
{
    const control_shape_settings *s = &sh->s;
    if (strcmp(s->file, "none") == 0)
        return MF_ERROR(MF_ERR_INPUT, "force %s: shape mesh needs a polygon file (file \"x.obj\";)",
                        who);
    if (s->offset != 0)
        return MF_ERROR(MF_ERR_INPUT, "force %s: offset %g with shape mesh: a mesh region is "
                        "its closed surface (offset 0); use a box or sphere to grow or shrink",
                        who, s->offset);
    if (!sim->mesh_reader)
        return MF_ERROR(MF_ERR_INPUT, "force %s: shape mesh: no polygon reader in this run", who);
    mf_trimesh m;
    mf_trimesh_init(&m);
    int rc = sim->mesh_reader->read(sim->mesh_reader->ctx, s->file, sim->mesh_relative_to, &m);
    mf_trimesh_report r;
    if (rc == 0) {
        mf_trimesh_scale(&m, s->scale);
        rc = mf_trimesh_check(&m, &r);
    }
    if (rc == 0 && !r.closed)
        rc = MF_ERROR(MF_ERR_INPUT, "force %s: mesh %s is not closed (%zu open edges, %zu "
                      "non-manifold): a region needs an inside", who, m.name, r.nboundary,
                      r.nnonmanifold);
    if (rc == 0)
        rc = sample_mesh(sh, &m);
    mf_trimesh_free(&m);
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    return 0;
}

int control_shape_create(const control_shape_settings *s, const char *who, const mf_sim *sim,
                         control_shape *out)
{
    memset(out, 0, sizeof *out);
    out->s = *s;
    out->dim = sim->dim;
    out->l0 = sim->l0;
    if (strcmp(s->shape, "box") == 0) {
        out->type = CONTROL_BOX;
        for (int a = 0; a < sim->dim; a++) {
            if (!(s->max[a] > s->min[a]))
                return MF_ERROR(MF_ERR_INPUT, "force %s: shape box needs max > min on every "
                                "axis (axis %d: %g, %g)", who, a, s->min[a], s->max[a]);
            out->lo[a] = s->min[a] - s->offset;
            out->hi[a] = s->max[a] + s->offset;
        }
    } else if (strcmp(s->shape, "sphere") == 0) {
        out->type = CONTROL_SPHERE;
        for (int a = 0; a < sim->dim; a++) {
            out->lo[a] = s->centre[a] - s->radius - s->offset;
            out->hi[a] = s->centre[a] + s->radius + s->offset;
        }
    } else if (strcmp(s->shape, "point") == 0) {
        out->type = CONTROL_POINT;
        for (int a = 0; a < sim->dim; a++)
            out->lo[a] = out->hi[a] = s->centre[a];
        return 0;
    } else {
        out->type = CONTROL_MESH;
        MF_CALL(load_mesh(out, who, sim));
    }
    for (int a = 0; a < sim->dim; a++)
        if (!(out->hi[a] > out->lo[a]))
            return MF_ERROR(MF_ERR_INPUT, "force %s: offset %g leaves the region empty", who,
                            s->offset);
    return 0;
}

void control_shape_free(control_shape *sh)
{
    free(sh->inside);
    sh->inside = NULL;
}

double control_shape_phi(const control_shape *sh, const double x[3], const double shift[3])
{
    double y[3] = {x[0], x[1], x[2]};
    if (shift)
        for (int a = 0; a < 3; a++)
            y[a] -= shift[a];
    switch (sh->type) {
    case CONTROL_BOX: return box_phi(sh->s.min, sh->s.max, y, sh->dim) - sh->s.offset;
    case CONTROL_SPHERE: return sphere_phi(sh->s.centre, sh->s.radius, y, sh->dim) - sh->s.offset;
    case CONTROL_POINT: return sphere_phi(sh->s.centre, 0, y, sh->dim);
    case CONTROL_MESH: break;
    }
    size_t k = 0, stride = 1;
    for (int a = 0; a < sh->dim; a++) {
        const long i = lattice_index(y[a], sh->l0) - sh->base[a];
        if (i < 0 || i >= sh->n[a])
            return 0.5 * sh->l0;
        k += (size_t)i * stride;
        stride *= (size_t)sh->n[a];
    }
    return sh->inside[k] ? -0.5 * sh->l0 : 0.5 * sh->l0;
}

size_t control_shape_lattice(const control_shape *sh, double h, double *xyz, size_t cap)
{
    if (sh->type == CONTROL_POINT) {
        if (xyz && cap > 0)
            for (int a = 0; a < 3; a++)
                xyz[a] = a < sh->dim ? sh->s.centre[a] : 0;
        return 1;
    }
    long lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int a = 0; a < sh->dim; a++) {
        lo[a] = lattice_index(sh->lo[a], h) - 1;
        hi[a] = lattice_index(sh->hi[a], h) + 1;
    }
    size_t n = 0;
    for (long iz = lo[2]; iz <= hi[2]; iz++)
        for (long iy = lo[1]; iy <= hi[1]; iy++)
            for (long ix = lo[0]; ix <= hi[0]; ix++) {
                const long idx[3] = {ix, iy, iz};
                double x[3] = {0, 0, 0};
                for (int a = 0; a < sh->dim; a++)
                    x[a] = (idx[a] + 0.5) * h;
                if (!control_shape_contains(sh, x, NULL))
                    continue;
                if (xyz && n < cap)
                    memcpy(&xyz[3 * n], x, sizeof x);
                n++;
            }
    return n;
}
