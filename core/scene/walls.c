/* walls.c: the solids of a scene (mf_walls.h): their list, their shapes'
 * signed distances, the watch's test of a particle gone through one, and
 * the particles of moving solids. */
#include "mf_walls.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_bodies.h"
#include "mf_error.h"
#include "mf_mat3.h"
#include "walls_internal.h"

int mf_walls_create(int dim, double l0, bool particles, mf_walls **out)
{
    mf_walls *ws = calloc(1, sizeof *ws);
    if (!ws)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    ws->dim = dim;
    ws->l0 = l0;
    ws->particles = particles;
    ws->f_wall_id = -1;
    *out = ws;
    return 0;
}

void mf_walls_destroy(mf_walls *ws)
{
    if (!ws)
        return;
    for (size_t k = 0; k < ws->n; k++) {
        mf_motion_free(&ws->w[k].motion);
        mf_wall_mesh_destroy(ws->w[k].mesh);
        mf_body_destroy(ws->w[k].body);
    }
    free(ws->w);
    free(ws);
}

int mf_walls_add(mf_walls *ws, mf_wall *w, size_t *index)
{
    mf_wall *grown = realloc(ws->w, (ws->n + 1) * sizeof *grown);
    if (!grown)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    ws->w = grown;
    ws->w[ws->n] = *w;
    ws->w[ws->n].dim = ws->dim;
    memset(&w->motion, 0, sizeof w->motion); /* taken over with the mesh */
    w->mesh = NULL;
    w->body = NULL;
    if (index)
        *index = ws->n;
    ws->n++;
    return 0;
}

bool mf_walls_any_moving(const mf_walls *ws)
{
    for (size_t k = 0; ws && k < ws->n; k++)
        if (mf_wall_moves(&ws->w[k]))
            return true;
    return false;
}

int mf_walls_prepare(mf_walls *ws, double reach)
{
    for (size_t k = 0; ws && k < ws->n; k++) {
        mf_wall *w = &ws->w[k];
        if (w->mesh && mf_wall_mesh_cell(w->mesh) < reach)
            MF_CALL(mf_wall_mesh_index(w->mesh, reach));
    }
    return 0;
}

size_t mf_walls_memory(const mf_walls *ws)
{
    size_t bytes = ws ? sizeof *ws + ws->n * sizeof *ws->w : 0;
    for (size_t k = 0; ws && k < ws->n; k++)
        bytes += mf_wall_mesh_memory(ws->w[k].mesh);
    return bytes;
}

/* ---- signed distances, body frame ----------------------------------------- */

static double tank_distance(const mf_wall *w, int dim, const double x[3], double n[3])
{
    double best = INFINITY;
    for (int a = 0; a < dim; a++)
        for (int s = 0; s < 2; s++) {
            if (w->open[a][s])
                continue;
            const double d = s == 0 ? x[a] - w->min[a] : w->max[a] - x[a];
            if (d < best) {
                best = d;
                n[0] = n[1] = n[2] = 0;
                n[a] = s == 0 ? 1 : -1;
            }
        }
    return best;
}

/* A box's signed distance, positive outside (Quilez's formula). */
static double box_distance(const double mn[3], const double mx[3], int dim, const double x[3],
                           double n[3])
{
    double q[3] = {0, 0, 0}, out2 = 0, inside = -INFINITY;
    int arg = 0;
    for (int a = 0; a < dim; a++) {
        const double c = 0.5 * (mn[a] + mx[a]), h = 0.5 * (mx[a] - mn[a]);
        const double rel = x[a] - c;
        q[a] = fabs(rel) - h;
        if (q[a] > 0)
            out2 += q[a] * q[a];
        if (q[a] > inside) {
            inside = q[a];
            arg = a;
        }
    }
    n[0] = n[1] = n[2] = 0;
    if (out2 > 0) {
        const double d = sqrt(out2);
        for (int a = 0; a < dim; a++)
            if (q[a] > 0)
                n[a] = (x[a] > 0.5 * (mn[a] + mx[a]) ? 1 : -1) * q[a] / d;
        return d;
    }
    n[arg] = x[arg] > 0.5 * (mn[arg] + mx[arg]) ? 1 : -1;
    return inside;
}

static double cylinder_distance(const mf_wall *w, int dim, const double x[3], double n[3])
{
    double r[3], ax[3] = {0, 0, 1};
    if (dim == 3)
        memcpy(ax, w->axis, sizeof ax);
    for (int a = 0; a < 3; a++)
        r[a] = x[a] - w->centre[a];
    if (dim == 2)
        r[2] = 0;
    const double t = r[0] * ax[0] + r[1] * ax[1] + r[2] * ax[2];
    double rad[3];
    for (int a = 0; a < 3; a++)
        rad[a] = r[a] - t * ax[a];
    const double rho = sqrt(rad[0] * rad[0] + rad[1] * rad[1] + rad[2] * rad[2]);
    double er[3] = {1, 0, 0};
    if (rho > 0)
        for (int a = 0; a < 3; a++)
            er[a] = rad[a] / rho;
    const double qr = rho - w->radius;
    if (dim == 2 || !(w->half_length > 0)) {
        memcpy(n, er, 3 * sizeof *n);
        return qr;
    }
    const double qa = fabs(t) - w->half_length, sa = t >= 0 ? 1 : -1;
    if (qr > 0 && qa > 0) {
        const double d = sqrt(qr * qr + qa * qa);
        for (int a = 0; a < 3; a++)
            n[a] = (qr * er[a] + qa * sa * ax[a]) / d;
        return d;
    }
    if (qr > qa) {
        memcpy(n, er, 3 * sizeof *n);
        return qr;
    }
    for (int a = 0; a < 3; a++)
        n[a] = sa * ax[a];
    return qa;
}

static double sphere_distance(const mf_wall *w, int dim, const double x[3], double n[3])
{
    double r[3] = {0, 0, 0}, len = 0;
    for (int a = 0; a < dim; a++) {
        r[a] = x[a] - w->centre[a];
        len += r[a] * r[a];
    }
    len = sqrt(len);
    n[0] = n[1] = n[2] = 0;
    if (len > 0)
        for (int a = 0; a < dim; a++)
            n[a] = r[a] / len;
    else
        n[0] = 1;
    return len - w->radius;
}

double mf_wall_body_distance(const mf_wall *w, const double xb[3], double n[3])
{
    const int dim = w->dim;
    switch (w->shape) {
    case MF_SOLID_TANK: return tank_distance(w, dim, xb, n);
    case MF_SOLID_BOX: return box_distance(w->min, w->max, dim, xb, n);
    case MF_SOLID_CYLINDER: return cylinder_distance(w, dim, xb, n);
    case MF_SOLID_SPHERE: return sphere_distance(w, dim, xb, n);
    case MF_SOLID_MESH:
        if (w->mesh)
            return mf_wall_mesh_distance(w->mesh, xb, n);
        break;
    default:
        break;
    }
    n[0] = n[1] = n[2] = 0;
    return INFINITY;
}

double mf_wall_distance(const mf_wall *w, const double x[3], double n[3])
{
    double xb[3], nb[3];
    mf_wall_to_body(w, x, xb);
    const double d = mf_wall_body_distance(w, xb, nb);
    if (n)
        mf_mat3_vec(w->state.R, nb, n);
    return d;
}

void mf_box_lattice_max(double l0, int dim, const double min[3], double max[3])
{
    for (int a = 0; a < dim; a++) {
        const double size = floor((max[a] - min[a]) / l0 + 1e-9) * l0;
        if (fabs(size - (max[a] - min[a])) > 1e-6 * l0)
            max[a] = min[a] + size;
    }
}

bool mf_wall_passed(const mf_wall *w, double l0, int dim, const double x[3], int *axis,
                    int *side)
{
    const double h = 0.5 * l0;
    double xb[3], nb[3];
    mf_wall_to_body(w, x, xb);
    *axis = -1;
    *side = -1;
    if (w->shape == MF_SOLID_MESH)
        return false;
    if (w->shape != MF_SOLID_TANK)
        return mf_wall_body_distance(w, xb, nb) < -h;
    for (int a = 0; a < dim; a++)
        for (int s = 0; s < 2; s++) {
            if (w->open[a][s])
                continue;
            bool past = s == 0 ? xb[a] < w->min[a] - h : xb[a] > w->max[a] + h;
            bool within = past;
            for (int o = 0; o < dim && within; o++)
                if (o != a && (xb[o] < w->min[o] - h || xb[o] > w->max[o] + h))
                    within = false;
            if (within) {
                *axis = a;
                *side = s;
                return true;
            }
        }
    return false;
}

bool mf_wall_spilled(const mf_wall *w, double l0, const double x[3], const double step[3],
                     int axis, int side)
{
    if (w->shape != MF_SOLID_TANK || !(w->thickness > 0) || axis < 0 || axis > 2)
        return false;
    double before[3], xb[3], bb[3];
    for (int a = 0; a < 3; a++)
        before[a] = x[a] - step[a];
    mf_wall_to_body(w, x, xb);
    mf_wall_to_body(w, before, bb);
    const double h = 0.5 * l0;
    if (side == 0)
        return xb[axis] < w->min[axis] - w->thickness && bb[axis] < w->min[axis] - h;
    return xb[axis] > w->max[axis] + w->thickness && bb[axis] > w->max[axis] + h;
}

/* ---- particles of moving solids --------------------------------------------- */

void mf_walls_move_particles(const mf_walls *ws, const mf_rigid_state *from_states,
                             mf_particles *p)
{
    if (!ws || ws->f_wall_id < 0)
        return;
    const int32_t *id = mf_particles_fi(p, ws->f_wall_id);
    for (size_t i = 0; i < p->n_owned; i++) {
        if (id[i] <= 0 || (size_t)id[i] > ws->n)
            continue;
        const mf_wall *w = &ws->w[id[i] - 1];
        if (!mf_wall_moves(w))
            continue;
        mf_wall from = *w; /* the body frame through the old state */
        from.state = from_states[id[i] - 1];
        double xb[3], *x = &p->pos[3 * i];
        mf_wall_to_body(&from, x, xb);
        mf_wall_to_world(w, xb, x);
        mf_wall_velocity(w, x, true, &p->vel[3 * i]);
        if (ws->dim == 2)
            x[2] = p->vel[3 * i + 2] = 0;
    }
}

int mf_walls_advance(mf_walls *ws, mf_particles *p, double t_from, double t_to)
{
    if (!ws || !mf_walls_any_moving(ws))
        return 0;
    mf_rigid_state *from = malloc(ws->n * sizeof *from);
    if (!from)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory moving the walls");
    mf_walls_set_time(ws, t_from);
    mf_bodies_set_committed(ws);
    for (size_t k = 0; k < ws->n; k++)
        from[k] = ws->w[k].state;
    mf_walls_set_time(ws, t_to);
    const int rc = mf_bodies_set_trial(ws, p, t_to - t_from);
    if (rc == 0)
        mf_walls_move_particles(ws, from, p);
    free(from);
    MF_CALL(rc);
    return 0;
}

/* Solids without particles (wall weight): their speed where the fluid is. */
static double speed_at_fluid(const mf_walls *ws, const mf_particles *p)
{
    double u2 = 0;
    for (size_t k = 0; k < ws->n; k++) {
        const double *su = ws->w[k].surface_velocity; /* a sliding lid */
        if (!mf_wall_moves(&ws->w[k]) && su[0] == 0 && su[1] == 0 && su[2] == 0)
            continue;
        for (size_t i = 0; i < p->n_owned; i++) {
            if (p->kind[i] != MF_FLUID)
                continue;
            double v[3];
            mf_wall_velocity(&ws->w[k], &p->pos[3 * i], true, v);
            u2 = fmax(u2, v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        }
    }
    return sqrt(u2);
}

double mf_walls_max_speed(const mf_walls *ws, const mf_particles *p)
{
    if (ws && !ws->particles)
        return speed_at_fluid(ws, p);
    if (!ws || ws->f_wall_id < 0)
        return 0;
    const int32_t *id = mf_particles_fi(p, ws->f_wall_id);
    double u2 = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (id[i] <= 0)
            continue;
        const double *v = &p->vel[3 * i];
        u2 = fmax(u2, v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    }
    return sqrt(u2);
}
