/* rigid_bodies.c: the dynamics of the rigid bodies moved by the fluid
 * (mf_bodies.h; Akinci et al. 2012, section 4: the fluid's pair forces on
 * the body's particles summed into a force and a torque, integrated by
 * symplectic Euler). */
#include "mf_bodies.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_mat3.h"
#include "mf_fs.h"
#include "mf_parallel.h"
#include "bodies_internal.h"
#include "walls_internal.h"


/* Inverse of a symmetric positive definite 3x3 matrix (the adjugate). */
static bool invert3(const double A[9], double B[9])
{
    const double c00 = A[4] * A[8] - A[5] * A[7], c01 = A[5] * A[6] - A[3] * A[8],
                 c02 = A[3] * A[7] - A[4] * A[6];
    const double det = A[0] * c00 + A[1] * c01 + A[2] * c02;
    if (!(det > 0))
        return false;
    B[0] = c00 / det;
    B[1] = (A[2] * A[7] - A[1] * A[8]) / det;
    B[2] = (A[1] * A[5] - A[2] * A[4]) / det;
    B[3] = c01 / det;
    B[4] = (A[0] * A[8] - A[2] * A[6]) / det;
    B[5] = (A[2] * A[3] - A[0] * A[5]) / det;
    B[6] = c02 / det;
    B[7] = (A[1] * A[6] - A[0] * A[7]) / det;
    B[8] = (A[0] * A[4] - A[1] * A[3]) / det;
    return true;
}

/* A closed mesh's volume, centroid and inertia per unit mass
 * (mf_trimesh_mass: Eberly 2002, Mirtich 1996); an open or inside-out
 * surface is refused. */
static int mesh_inertia(const mf_wall *w, double *volume, double centre[3], double I[9])
{
    const mf_trimesh *m = mf_wall_mesh_surface(w->mesh);
    mf_trimesh_report r;
    MF_CALL(mf_wall_mesh_report(w->mesh, &r));
    mf_trimesh_mass(m, volume, centre, I);
    if (!r.closed)
        return MF_ERROR(MF_ERR_INPUT, "%s: obstacle '%s', file '%s': not a closed surface (%zu "
                        "open edges, the first at (%g %g %g); %zu edges of three or more "
                        "triangles; signed volume %g m^3): the mass of a rigid body from its "
                        "density needs a closed mesh (or give mass, inertia and origin)",
                        w->where, w->name, m->name, r.nboundary, r.at_boundary[0],
                        r.at_boundary[1], r.at_boundary[2], r.nnonmanifold, *volume);
    if (!(*volume > 0))
        return MF_ERROR(MF_ERR_INPUT, "%s: obstacle '%s', file '%s': the surface is inside out "
                        "(signed volume %g m^3: its triangles' normals (b - a) x (c - a) point "
                        "inward): turn its triangles", w->where, w->name, m->name, *volume);
    return 0;
}

/* Volume (2-D: area), the centre and the inertia per unit mass of a shape. */
static int shape_inertia(const mf_wall *w, int dim, double *volume, double centre[3],
                         double I[9])
{
    memset(I, 0, 9 * sizeof *I);
    if (w->shape == MF_SOLID_BOX) {
        double e[3] = {1, 1, 1};
        *volume = 1;
        for (int a = 0; a < 3; a++) {
            centre[a] = a < dim ? 0.5 * (w->min[a] + w->max[a]) : 0;
            if (a < dim) {
                e[a] = w->max[a] - w->min[a];
                *volume *= e[a];
            }
        }
        if (dim == 2)
            e[2] = 0;
        I[0] = (e[1] * e[1] + e[2] * e[2]) / 12;
        I[4] = (e[0] * e[0] + e[2] * e[2]) / 12;
        I[8] = (e[0] * e[0] + e[1] * e[1]) / 12;
        return 0;
    }
    const double r = w->radius;
    memcpy(centre, w->centre, 3 * sizeof *centre);
    if (dim == 2 && (w->shape == MF_SOLID_CYLINDER || w->shape == MF_SOLID_SPHERE)) {
        *volume = M_PI * r * r; /* a disk */
        I[0] = I[4] = 0.25 * r * r;
        I[8] = 0.5 * r * r;
        return 0;
    }
    if (w->shape == MF_SOLID_SPHERE) {
        *volume = 4.0 / 3.0 * M_PI * r * r * r;
        I[0] = I[4] = I[8] = 0.4 * r * r;
        return 0;
    }
    if (w->shape == MF_SOLID_CYLINDER) {
        const double L = 2 * w->half_length;
        if (!(L > 0))
            return MF_ERROR(MF_ERR_INPUT, "%s: obstacle '%s': a rigid cylinder in 3-D needs a "
                            "length (an endless one has no mass)", w->where, w->name);
        *volume = M_PI * r * r * L;
        /* (3 r^2 + L^2)/12 across the axis a, r^2/2 along it */
        const double across = (3 * r * r + L * L) / 12, along = 0.5 * r * r;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                I[3 * i + j] = across * ((i == j) - w->axis[i] * w->axis[j]) +
                               along * w->axis[i] * w->axis[j];
        return 0;
    }
    if (w->shape == MF_SOLID_MESH && dim == 3 && w->mesh)
        return mesh_inertia(w, volume, centre, I);
    /* 2-D: a mesh obstacle is a profile extruded across z = 0 (walls_mesh.c),
     * whose section the triangles do not give */
    return MF_ERROR(MF_ERR_INPUT, "%s: obstacle '%s': a rigid mesh body in 2-D needs its mass, "
                    "inertia and origin (the centre of mass) in motion { type rigid; mass ...; "
                    "inertia (...); origin (...); } (its section is not computed from the "
                    "extruded profile; density works for box, cylinder, sphere and 3-D meshes)",
                    w->where, w->name);
}

int mf_body_create(mf_wall *w, int dim)
{
    mf_motion *m = &w->motion;
    if (!w->obstacle)
        return MF_ERROR(MF_ERR_INPUT, "%s: wall '%s': motion type rigid is for obstacles (a "
                        "body in the fluid), not for the walls that hold it", w->where, w->name);
    mf_body *b = calloc(1, sizeof *b);
    if (!b)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    double volume = 0, centre[3] = {0, 0, 0}, I[9];
    int rc = 0;
    if (m->density > 0 || !m->origin_given) {
        rc = shape_inertia(w, dim, &volume, centre, I);
        if (rc != 0) {
            free(b);
            return mf_error_trace(rc, __FILE__, __LINE__, __func__);
        }
    }
    if (m->density > 0) {
        b->mass = m->density * volume;
        for (int k = 0; k < 9; k++)
            b->Ib[k] = b->mass * I[k];
    } else {
        b->mass = m->mass;
        b->Ib[0] = m->inertia[0];
        b->Ib[4] = m->inertia[1];
        b->Ib[8] = m->inertia[2];
    }
    if (dim == 2) { /* only Izz acts: the others only keep the matrix invertible */
        b->Ib[1] = b->Ib[2] = b->Ib[3] = b->Ib[5] = b->Ib[6] = b->Ib[7] = 0;
        b->Ib[0] = b->Ib[4] = b->Ib[8];
    }
    if (!invert3(b->Ib, b->Ib_inv)) {
        free(b);
        return MF_ERROR(MF_ERR_INPUT, "%s: obstacle '%s': its inertia is not positive definite",
                        w->where, w->name);
    }
    if (!m->origin_given)
        memcpy(m->origin, centre, sizeof centre);
    memcpy(b->x, m->origin, sizeof b->x);
    memcpy(b->v, m->velocity, sizeof b->v);
    b->R[0] = b->R[4] = b->R[8] = 1;
    for (int a = 0; a < 3; a++)
        b->w[a] = m->omega * m->axis[a];
    mf_mat3_vec(b->Ib, b->w, b->L); /* R = I at t = 0 */
    memcpy(b->xt, b->x, sizeof b->x);
    memcpy(b->vt, b->v, sizeof b->v);
    memcpy(b->Rt, b->R, sizeof b->R);
    memcpy(b->Lt, b->L, sizeof b->L);
    memcpy(b->wt, b->w, sizeof b->w);
    w->body = b;
    memset(&w->state, 0, sizeof w->state);
    memcpy(w->state.R, b->R, sizeof b->R);
    memcpy(w->state.v, b->v, sizeof b->v);
    memcpy(w->state.w, b->w, sizeof b->w);
    return 0;
}

void mf_body_destroy(mf_body *b)
{
    if (!b)
        return;
    if (b->csv)
        fclose(b->csv);
    free(b);
}

size_t mf_bodies_count(const mf_walls *ws)
{
    size_t n = 0;
    for (size_t k = 0; ws && k < ws->n; k++)
        n += ws->w[k].body != NULL;
    return n;
}

/* The wall's rigid state from a body state (x the centre, R, v, w; a and dw
 * the change over the step). */
static void to_state(mf_wall *w, const double x[3], const double R[9], const double v[3],
                     const double om[3], const double a[3], const double dw[3])
{
    mf_rigid_state *s = &w->state;
    for (int c = 0; c < 3; c++) {
        s->d[c] = x[c] - w->motion.origin[c];
        s->v[c] = v[c];
        s->a[c] = a[c];
        s->w[c] = om[c];
        s->dw[c] = dw[c];
    }
    memcpy(s->R, R, sizeof s->R);
}

void mf_bodies_set_committed(mf_walls *ws)
{
    static const double zero[3] = {0, 0, 0};
    for (size_t k = 0; ws && k < ws->n; k++) {
        mf_wall *w = &ws->w[k];
        mf_body *b = w->body;
        if (b)
            to_state(w, b->x, b->R, b->v, b->w, zero, zero);
    }
}

void mf_body_finish_trial(mf_wall *w, int dim, double dt)
{
    mf_body *b = w->body;
    double a[3], dw[3], Linv[3], wb[3];
    if (dim == 2)
        b->Lt[0] = b->Lt[1] = 0;
    /* w = R I_b^-1 R^T L with the orientation at t^n */
    mf_mat3_t_vec(b->R, b->Lt, Linv);
    mf_mat3_vec(b->Ib_inv, Linv, wb);
    mf_mat3_vec(b->R, wb, b->wt);
    for (int c = 0; c < 3; c++)
        b->xt[c] = b->x[c] + dt * b->vt[c];
    const double speed = sqrt(b->wt[0] * b->wt[0] + b->wt[1] * b->wt[1] + b->wt[2] * b->wt[2]);
    if (speed > 0) {
        const double axis[3] = {b->wt[0] / speed, b->wt[1] / speed, b->wt[2] / speed};
        double dR[9];
        mf_rotation_matrix(axis, speed * dt, dR);
        mf_mat3_mul(dR, b->R, b->Rt);
    } else {
        memcpy(b->Rt, b->R, sizeof b->R);
    }
    for (int c = 0; c < 3; c++) {
        a[c] = dt > 0 ? (b->vt[c] - b->v[c]) / dt : 0;
        dw[c] = dt > 0 ? (b->wt[c] - b->w[c]) / dt : 0;
    }
    to_state(w, b->xt, b->Rt, b->vt, b->wt, a, dw);
}

int mf_bodies_set_trial(mf_walls *ws, const mf_particles *p, double dt)
{
    for (size_t k = 0; ws && k < ws->n; k++) {
        mf_wall *w = &ws->w[k];
        mf_body *b = w->body;
        if (!b)
            continue;
        const int dim = ws->dim;
        for (int c = 0; c < 3; c++) {
            b->vt[c] = c < dim ? b->v[c] + b->J[c] / b->mass + dt * w->motion.g[c] : 0;
            b->Lt[c] = b->L[c] + b->H[c];
        }
        mf_body_finish_trial(w, dim, dt);
    }
    if (ws && p)
        MF_CALL(mf_bodies_contact(ws, p, dt));
    return 0;
}

void mf_bodies_clear_forces(mf_walls *ws)
{
    for (size_t k = 0; ws && k < ws->n; k++)
        if (ws->w[k].body) {
            memset(ws->w[k].force, 0, sizeof ws->w[k].force);
            memset(ws->w[k].torque, 0, sizeof ws->w[k].torque);
        }
}

void mf_body_add_force(mf_wall *w, const double x[3], const double f[3])
{
    const double *c = w->body->xt; /* the centre where the step has it */
    const double r[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]};
    double t[3];
    mf_cross3(r, f, t);
    for (int a = 0; a < 3; a++) {
        w->force[a] += f[a];
        w->torque[a] += t[a];
    }
}

/* Orientation as a unit quaternion (w x y z) from R (Shepperd's method). */
static void quaternion(const double R[9], double q[4])
{
    const double tr = R[0] + R[4] + R[8];
    if (tr > 0) {
        const double s = 2 * sqrt(tr + 1);
        q[0] = 0.25 * s;
        q[1] = (R[7] - R[5]) / s;
        q[2] = (R[2] - R[6]) / s;
        q[3] = (R[3] - R[1]) / s;
    } else if (R[0] > R[4] && R[0] > R[8]) {
        const double s = 2 * sqrt(1 + R[0] - R[4] - R[8]);
        q[0] = (R[7] - R[5]) / s;
        q[1] = 0.25 * s;
        q[2] = (R[1] + R[3]) / s;
        q[3] = (R[2] + R[6]) / s;
    } else if (R[4] > R[8]) {
        const double s = 2 * sqrt(1 + R[4] - R[0] - R[8]);
        q[0] = (R[2] - R[6]) / s;
        q[1] = (R[1] + R[3]) / s;
        q[2] = 0.25 * s;
        q[3] = (R[5] + R[7]) / s;
    } else {
        const double s = 2 * sqrt(1 + R[8] - R[0] - R[4]);
        q[0] = (R[3] - R[1]) / s;
        q[1] = (R[2] + R[6]) / s;
        q[2] = (R[5] + R[7]) / s;
        q[3] = 0.25 * s;
    }
}

static void write_row(const mf_wall *w, double t)
{
    const mf_body *b = w->body;
    if (!b->csv)
        return;
    double q[4];
    quaternion(b->R, q);
    fprintf(b->csv,
            "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,"
            "%.9g,%.9g,%.9g,%.9g\n",
            t, b->x[0], b->x[1], b->x[2], q[0], q[1], q[2], q[3], b->v[0], b->v[1], b->v[2],
            b->w[0], b->w[1], b->w[2], w->force[0], w->force[1], w->force[2], w->torque[0],
            w->torque[1], w->torque[2]);
    fflush(b->csv);
}

/* On several ranks each rank summed the fluid's force and torque over its
 * owned particles: the sums over all ranks, the same on every rank, so that
 * every rank integrates the same body state. */
static int reduce_forces(mf_walls *ws)
{
    const size_t nb = mf_bodies_count(ws);
    if (!ws || !ws->par || nb == 0)
        return 0;
    double *sum = malloc(6 * nb * sizeof *sum);
    if (!sum)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory summing the rigid bodies' forces");
    size_t m = 0;
    for (size_t k = 0; k < ws->n; k++)
        if (ws->w[k].body) {
            for (int c = 0; c < 3; c++) {
                sum[m + c] = ws->w[k].force[c];
                sum[m + 3 + c] = ws->w[k].torque[c];
            }
            m += 6;
        }
    mf_parallel_sum(ws->par, sum, (int)(6 * nb));
    /* MPI does not promise every rank the same rounding of a sum (the order
     * of its additions may differ by rank): rank 0's, so that no rank's body
     * drifts from the others' */
    mf_parallel_bcast(ws->par, sum, 6 * nb * sizeof *sum, 0);
    m = 0;
    for (size_t k = 0; k < ws->n; k++)
        if (ws->w[k].body) {
            for (int c = 0; c < 3; c++) {
                ws->w[k].force[c] = sum[m + c];
                ws->w[k].torque[c] = sum[m + 3 + c];
            }
            m += 6;
        }
    free(sum);
    return 0;
}

int mf_bodies_accept(mf_walls *ws, double t, double dt)
{
    MF_CALL(reduce_forces(ws));
    for (size_t k = 0; ws && k < ws->n; k++) {
        mf_wall *w = &ws->w[k];
        mf_body *b = w->body;
        if (!b)
            continue;
        memcpy(b->x, b->xt, sizeof b->x);
        memcpy(b->v, b->vt, sizeof b->v);
        memcpy(b->R, b->Rt, sizeof b->R);
        memcpy(b->L, b->Lt, sizeof b->L);
        memcpy(b->w, b->wt, sizeof b->w);
        for (int c = 0; c < 3; c++) {
            b->J[c] = dt * w->force[c];
            b->H[c] = dt * w->torque[c];
        }
        if (ws->dim == 2)
            b->J[2] = b->H[0] = b->H[1] = 0;
        w->state_time = t;
        if (!(isfinite(b->x[0]) && isfinite(b->x[1]) && isfinite(b->v[0]) && isfinite(b->v[1])))
            return MF_ERROR(MF_ERR_NUMERIC, "rigid body '%s' at time %g: its state is not "
                            "finite", w->name, t);
        write_row(w, t);
    }
    return 0;
}

/* A restart at time t: the rows of path up to t (the previous run's, which
 * may have gone on past its last snapshot) are kept and the file is opened
 * to append; false when there is no such file. */
static int reopen_at(mf_body *b, const char *path, double t, bool *kept)
{
    *kept = false;
    FILE *in = fopen(path, "r");
    if (!in)
        return 0;
    mf_replace kept_rows;
    int rc = mf_replace_open(&kept_rows, path, "w");
    if (rc != 0) {
        fclose(in);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    FILE *out = kept_rows.f;
    char line[4096];
    while (fgets(line, sizeof line, in)) {
        char *end;
        const double row_t = strtod(line, &end);
        /* comments and the column names stay; rows up to t (%.9g of it) */
        if (end == line || row_t <= t + 1e-9 * fmax(fabs(t), 1e-300))
            fputs(line, out);
    }
    fclose(in);
    MF_CALL(mf_replace_commit(&kept_rows, 0));
    b->csv = fopen(path, "a");
    if (!b->csv)
        return MF_ERROR(MF_ERR_IO, "cannot write %s: %s", path, strerror(errno));
    *kept = true;
    return 0;
}

int mf_bodies_open_output(mf_walls *ws, const char *post_dir, double t, bool restart)
{
    if (mf_bodies_count(ws) == 0)
        return 0;
    MF_CALL(mf_mkdir_p(post_dir));
    char path[4400];
    for (size_t k = 0; k < ws->n; k++) {
        mf_wall *w = &ws->w[k];
        mf_body *b = w->body;
        if (!b)
            continue;
        snprintf(path, sizeof path, "%s/%s", post_dir, w->name);
        MF_CALL(mf_mkdir_p(path));
        snprintf(path, sizeof path, "%s/%s/bodyState.csv", post_dir, w->name);
        if (b->csv)
            fclose(b->csv);
        b->csv = NULL;
        bool kept = false;
        if (restart)
            MF_CALL(reopen_at(b, path, t, &kept));
        if (kept)
            continue;
        b->csv = fopen(path, "w");
        if (!b->csv)
            return MF_ERROR(MF_ERR_IO, "cannot write %s: %s", path, strerror(errno));
        fprintf(b->csv, "# rigid body '%s': mass %.9g (2-D: per metre), centre of mass, "
                "orientation (quaternion w x y z), velocity, angular velocity, the fluid's force "
                "and torque about the centre over the step\n", w->name, b->mass);
        fprintf(b->csv, "time,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,Fx,Fy,Fz,Tx,Ty,Tz\n");
        write_row(w, t);
    }
    return 0;
}

void mf_body_get(const mf_wall *w, mf_body_momentum *out)
{
    const mf_body *b = w->body;
    memset(out, 0, sizeof *out);
    if (!b)
        return;
    out->mass = b->mass;
    memcpy(out->rotation, b->R, sizeof out->rotation);
    for (int c = 0; c < 3; c++) {
        out->centre[c] = b->x[c];
        out->velocity[c] = b->v[c];
        out->omega[c] = b->w[c];
        out->momentum[c] = b->mass * b->v[c];
        out->angular[c] = b->L[c];
        out->impulse[c] = b->J[c];
        out->angular_impulse[c] = b->H[c];
    }
}

int mf_body_set(mf_wall *w, const mf_body_momentum *s, const char *where)
{
    mf_body *b = w->body;
    if (!b)
        return MF_ERROR(MF_ERR_INTERNAL, "%s: '%s' is not a rigid body", where, w->name);
    if (!(fabs(s->mass - b->mass) <= 1e-12 * b->mass))
        return MF_ERROR(MF_ERR_INPUT, "cannot restart: %s holds rigid body '%s' of mass %.9g, "
                        "the case's (constant/geometry) is %.9g: start a new run", where,
                        w->name, s->mass, b->mass);
    memcpy(b->R, s->rotation, sizeof b->R);
    for (int c = 0; c < 3; c++) {
        b->x[c] = s->centre[c];
        b->v[c] = s->velocity[c];
        b->w[c] = s->omega[c];
        b->L[c] = s->angular[c];
        b->J[c] = s->impulse[c];
        b->H[c] = s->angular_impulse[c];
    }
    memcpy(b->xt, b->x, sizeof b->x);
    memcpy(b->vt, b->v, sizeof b->v);
    memcpy(b->Rt, b->R, sizeof b->R);
    memcpy(b->Lt, b->L, sizeof b->L);
    memcpy(b->wt, b->w, sizeof b->w);
    static const double zero[3] = {0, 0, 0};
    to_state(w, b->x, b->R, b->v, b->w, zero, zero);
    return 0;
}

/* The flat-or-straight faces of a box or a 3-D cylinder, body frame: the
 * depth of body point xb below each and its outward unit normal. A box:
 * xmin xmax ymin ymax (zmin zmax); a cylinder (axis a, centre c, radius r,
 * half-length h, xb - c = t a + rho e_r): the round side (depth r - rho,
 * normal e_r) and the caps at -h and +h (depths t + h and h - t, normals
 * -a and +a). Returns how many (0: a round shape, one element per wall
 * particle: mf_body_surface's other branch). */
static int face_count(const mf_wall *w, int dim)
{
    return w->shape == MF_SOLID_BOX ? 2 * dim
           : w->shape == MF_SOLID_CYLINDER && dim == 3 ? 3
                                                       : 0;
}

static int surface_faces(const mf_wall *w, int dim, const double xb[3], double depth[6],
                         double normal[6][3])
{
    memset(normal, 0, 6 * sizeof normal[0]);
    if (w->shape == MF_SOLID_BOX) {
        for (int a = 0; a < dim; a++) {
            depth[2 * a] = xb[a] - w->min[a];
            depth[2 * a + 1] = w->max[a] - xb[a];
            normal[2 * a][a] = -1;
            normal[2 * a + 1][a] = 1;
        }
        return face_count(w, dim);
    }
    if (face_count(w, dim) == 0)
        return 0;
    const double *ax = w->axis;
    double r[3], rad[3];
    for (int a = 0; a < 3; a++)
        r[a] = xb[a] - w->centre[a];
    const double t = r[0] * ax[0] + r[1] * ax[1] + r[2] * ax[2];
    for (int a = 0; a < 3; a++)
        rad[a] = r[a] - t * ax[a];
    const double rho = sqrt(rad[0] * rad[0] + rad[1] * rad[1] + rad[2] * rad[2]);
    depth[0] = w->radius - rho;
    depth[1] = t + w->half_length;
    depth[2] = w->half_length - t;
    for (int a = 0; a < 3; a++) {
        normal[0][a] = rho > 0 ? rad[a] / rho : 0; /* on the axis: no side there */
        normal[1][a] = -ax[a];
        normal[2][a] = ax[a];
    }
    if (!(rho > 0))
        depth[0] = INFINITY;
    return face_count(w, dim);
}

/* A wall particle stands for a face within l0 of it: a box's outer layer
 * lies at l0/2 on its own lattice; a cylinder sits on the case lattice, and
 * a cap there can fall on a lattice plane, its first plane inside then at
 * depth l0 exactly (a wall particle by the lattice-neighbour rule of
 * scene_solids.c): l0 with a margin for the round-off of that depth. */
static bool stands_for(double depth, double l0)
{
    return depth < l0 * (1 + 1e-6);
}

/* The area of face f of surface_faces: a box's face, the product of the
 * other edges; a cylinder's side 2 pi r L, a cap pi r^2. */
static double face_area(const mf_wall *w, int dim, int f)
{
    if (w->shape == MF_SOLID_CYLINDER)
        return f == 0 ? 2 * M_PI * w->radius * 2 * w->half_length
                      : M_PI * w->radius * w->radius;
    double area = 1;
    for (int a = 0; a < dim; a++)
        if (a != f / 2)
            area *= w->max[a] - w->min[a];
    return area;
}

int mf_body_surface_prepare(mf_wall *w, const mf_particles *p, int f_wall_id, int index,
                            double l0, const struct mf_parallel *par)
{
    mf_body *b = w->body;
    if (b->surface_ready)
        return 0;
    const int dim = w->dim;
    const int32_t *id = mf_particles_fi(p, f_wall_id);
    double count[6] = {0, 0, 0, 0, 0, 0}, nround = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (id[i] != index + 1 || p->kind[i] != MF_WALL)
            continue;
        double xb[3], depth[6], normal[6][3];
        mf_wall_to_body(w, &p->pos[3 * i], xb);
        nround++;
        const int nf = surface_faces(w, dim, xb, depth, normal);
        for (int f = 0; f < nf; f++)
            count[f] += stands_for(depth[f], l0);
        if (w->shape == MF_SOLID_MESH) /* its outer particles (no faces: count[0]) */
            count[0] += stands_for(-mf_wall_body_distance(w, xb, normal[0]), l0);
    }
    /* the counts over every rank's owned particles (whole numbers: exact) */
    double counts[7] = {count[0], count[1], count[2], count[3], count[4], count[5], nround};
    mf_parallel_sum(par, counts, 7);
    memcpy(count, counts, sizeof count);
    nround = counts[6];
    const int nf = face_count(w, dim);
    if (nf > 0) {
        for (int f = 0; f < nf; f++) {
            if (count[f] == 0)
                return MF_ERROR(MF_ERR_INPUT, "%s: rigid body '%s': no wall particle on a face: "
                                "make it at least two particle spacings wide", w->where, w->name);
            b->face_area[f] = face_area(w, dim, f) / count[f];
        }
    } else if (w->shape == MF_SOLID_SPHERE || (w->shape == MF_SOLID_CYLINDER && dim == 2)) {
        const double r = w->radius;
        const double area = dim == 2 ? 2 * M_PI * r : 4 * M_PI * r * r;
        if (nround == 0)
            return MF_ERROR(MF_ERR_INPUT, "%s: rigid body '%s' has no wall particle", w->where,
                            w->name);
        b->round_area = area / nround;
    } else if (w->shape == MF_SOLID_MESH && w->mesh && dim == 3) {
        /* the mesh's whole area over its outer particles, each with the
         * normal at its nearest point (mf_body_surface) */
        mf_trimesh_report r;
        MF_CALL(mf_wall_mesh_report(w->mesh, &r));
        if (count[0] == 0)
            return MF_ERROR(MF_ERR_INPUT, "%s: rigid body '%s' has no wall particle within l0 "
                            "of its surface", w->where, w->name);
        b->round_area = r.area / count[0];
    } else {
        return MF_ERROR(MF_ERR_INPUT, "%s: rigid body '%s': the fluid's pressure on it is "
                        "summed for boxes, cylinders, spheres and 3-D meshes only (a 2-D mesh "
                        "body: use gradient corrected, whose pair reaction needs no surface)",
                        w->where, w->name);
    }
    b->surface_ready = true;
    return 0;
}

int mf_body_surface(const mf_wall *w, const double x[3], double l0, double out_area[3][3],
                    double out_shift[3][3])
{
    const mf_body *b = w->body;
    const int dim = w->dim;
    double xb[3];
    mf_wall_to_body(w, x, xb);
    int n = 0;
    double nb[3] = {0, 0, 0}, db = 0;
    double depth[6], normal[6][3];
    const int nf = surface_faces(w, dim, xb, depth, normal);
    if (nf > 0) {
        for (int f = 0; f < nf && n < 3; f++) {
            if (!stands_for(depth[f], l0))
                continue;
            memcpy(nb, normal[f], sizeof nb);
            db = depth[f];
            mf_mat3_vec(w->state.R, nb, out_area[n]);
            for (int a = 0; a < 3; a++) {
                out_shift[n][a] = db * out_area[n][a];
                out_area[n][a] *= b->face_area[f];
            }
            n++;
        }
        return n;
    }
    if (w->shape == MF_SOLID_MESH) { /* depth -d along the normal into the fluid */
        const double d = mf_wall_body_distance(w, xb, nb);
        if (!stands_for(-d, l0))
            return 0;
        mf_mat3_vec(w->state.R, nb, out_area[0]);
        for (int a = 0; a < 3; a++) {
            out_shift[0][a] = -d * out_area[0][a];
            out_area[0][a] *= b->round_area;
        }
        return 1;
    }
    double r2 = 0;
    for (int a = 0; a < dim; a++)
        r2 += (xb[a] - w->centre[a]) * (xb[a] - w->centre[a]);
    const double r = sqrt(r2);
    if (!(r > 0))
        return 0;
    for (int a = 0; a < dim; a++)
        nb[a] = (xb[a] - w->centre[a]) / r;
    mf_mat3_vec(w->state.R, nb, out_area[0]);
    for (int a = 0; a < 3; a++) {
        out_shift[0][a] = (w->radius - r) * out_area[0][a];
        out_area[0][a] *= b->round_area;
    }
    return 1;
}
