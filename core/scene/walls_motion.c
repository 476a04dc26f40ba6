/* walls_motion.c: the prescribed motions of solids (mf_walls.h) and the
 * rigid transforms between their body frame and the world.
 *
 *   motion { type constant;    velocity (0.1 0 0); }
 *   motion { type rotation;    origin (0.5 0.5 0); axis (0 0 1); omega 2; }
 *   motion { type oscillating; amplitude (0.01 0 0); omega 5.2; cycles 3; }
 *   motion { type table;       origin (...); axis (...); interpolation spline;
 *            displacement ((0 (0 0 0)) (0.5 (0.02 0 0)) (1 (0 0 0)));
 *            angle ((0 0) (1 10)); }          // degrees about axis
 * as OpenFOAM's solidBody motions (linearMotion, rotatingMotion,
 * oscillatingDisplacement, tabulated6DoFMotion) and `table` Function1. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_mat3.h"
#include "mf_params.h"
#include "mf_walls.h"

static const char *const motion_types[] = {"none",  "constant", "rotation", "oscillating",
                                           "table", "external", "rigid", NULL};
static const char *const interpolations[] = {"linear", "spline", NULL};

typedef struct motion_settings {
    const char *type, *interpolation;
    double origin[3], axis[3], velocity[3], amplitude[3];
    double omega, angle_amplitude, cycles;
    double density, mass, inertia[3], g[3], restitution, friction; /* rigid */
} motion_settings;

const mf_param mf_motion_params[] = {
    {"type", MF_PARAM_WORD, "none", MF_NO_RANGE, motion_types, offsetof(motion_settings, type),
     "none, constant (velocity), rotation (omega about axis through origin), oscillating "
     "(amplitude sin(omega t), angleAmplitude sin(omega t)), table (displacement and angle "
     "tables: ((t (dx dy dz)) ...), ((t degrees) ...)), external (set by a module), rigid (moved "
     "by the fluid's pressure and viscous forces and gravity: rigid_bodies.c)"},
    {"origin", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, offsetof(motion_settings, origin),
     "centre of rotation at t = 0, m (rigid: the centre of mass; box, cylinder, sphere: their "
     "centre unless given)"},
    {"axis", MF_PARAM_VECTOR, "(0 0 1)", MF_NO_RANGE, NULL, offsetof(motion_settings, axis),
     "axis of rotation (2-D: z, the only one)"},
    {"velocity", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL,
     offsetof(motion_settings, velocity), "constant: the velocity, m/s; rigid: the initial velocity"},
    {"omega", MF_PARAM_SCALAR, "0", -1e6, 1e6, NULL, offsetof(motion_settings, omega),
     "rotation: angular velocity, rad/s; oscillating: angular frequency, rad/s; rigid: initial "
     "angular velocity about axis, rad/s"},
    {"amplitude", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL,
     offsetof(motion_settings, amplitude), "oscillating: displacement amplitude, m"},
    {"angleAmplitude", MF_PARAM_SCALAR, "0", -360, 360, NULL,
     offsetof(motion_settings, angle_amplitude), "oscillating: angle amplitude, degrees"},
    {"cycles", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(motion_settings, cycles),
     "oscillating: stop after this many periods, at rest where it started (0: never)"},
    {"interpolation", MF_PARAM_WORD, "linear", MF_NO_RANGE, interpolations,
     offsetof(motion_settings, interpolation),
     "table: linear, or spline (natural cubic: the velocity is continuous)"},
    {"density", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(motion_settings, density),
     "rigid: density of the body, kg/m^3 (mass and inertia from the shape; 2-D: per metre of "
     "depth); 0: give mass and inertia"},
    {"mass", MF_PARAM_SCALAR, "0", 0, 1e12, NULL, offsetof(motion_settings, mass),
     "rigid: mass, kg (2-D: kg/m), instead of density"},
    {"inertia", MF_PARAM_VECTOR, "(0 0 0)", 0, 1e12, NULL, offsetof(motion_settings, inertia),
     "rigid, with mass: principal moments of inertia about the centre of mass along the body "
     "axes x, y, z, kg m^2 (2-D: only z, kg m)"},
    {"g", MF_PARAM_VECTOR, "(0 -9.81 0)", -1e6, 1e6, NULL, offsetof(motion_settings, g),
     "rigid: acceleration of gravity on the body, m/s^2 (the gravity force's g)"},
    {"restitution", MF_PARAM_SCALAR, "0", 0, 1, NULL, offsetof(motion_settings, restitution),
     "rigid: coefficient of restitution of its contact with walls, obstacles and other bodies "
     "(0: the approach stops, 1: it bounces back at the speed it came)"},
    {"friction", MF_PARAM_SCALAR, "0", 0, 10, NULL, offsetof(motion_settings, friction),
     "rigid: Coulomb's coefficient of friction of its contacts (the tangential impulse at most "
     "friction times the normal one; two bodies: the mean; 0: none)"},
};
const size_t mf_motion_nparams = sizeof mf_motion_params / sizeof mf_motion_params[0];
const mf_param_section mf_motion_sections[] = {
    {"geometry: <wall or obstacle>/motion",
     "the prescribed rigid motion of a wall or obstacle; type table also takes displacement "
     "((t (dx dy dz)) ...) and angle ((t degrees) ...), rows in increasing time",
     mf_motion_params, sizeof mf_motion_params / sizeof mf_motion_params[0]},
};
const size_t mf_motion_nsections = 1;
static const char *const motion_extra[] = {"displacement", "angle", NULL};

/* ---- tables ---------------------------------------------------------------- */

void mf_motion_free(mf_motion *m)
{
    mf_motion_table *ts[2] = {&m->disp, &m->angle};
    for (int k = 0; k < 2; k++) {
        free(ts[k]->t);
        free(ts[k]->y);
        free(ts[k]->y2);
        memset(ts[k], 0, sizeof *ts[k]);
    }
}

/* Natural cubic spline: second derivatives at the rows (Press et al.,
 * Numerical Recipes, section 3.3). */
static int spline_prepare(mf_motion_table *tb)
{
    const size_t n = tb->n;
    const int nc = tb->ncomp;
    tb->y2 = calloc(n * (size_t)nc, sizeof *tb->y2);
    double *u = calloc(n, sizeof *u);
    if (!tb->y2 || !u) {
        free(u);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    }
    for (int c = 0; c < nc; c++) {
        double *y2 = tb->y2;
        for (size_t i = 1; i + 1 < n; i++) {
            const double sig = (tb->t[i] - tb->t[i - 1]) / (tb->t[i + 1] - tb->t[i - 1]);
            const double p = sig * y2[(i - 1) * nc + c] + 2;
            y2[i * nc + c] = (sig - 1) / p;
            const double dy = (tb->y[(i + 1) * nc + c] - tb->y[i * nc + c]) /
                                  (tb->t[i + 1] - tb->t[i]) -
                              (tb->y[i * nc + c] - tb->y[(i - 1) * nc + c]) /
                                  (tb->t[i] - tb->t[i - 1]);
            u[i] = (6 * dy / (tb->t[i + 1] - tb->t[i - 1]) - sig * u[i - 1]) / p;
        }
        y2[(n - 1) * nc + c] = 0;
        for (size_t i = n - 1; i-- > 0;)
            y2[i * nc + c] = y2[i * nc + c] * y2[(i + 1) * nc + c] + u[i];
        y2[0 * nc + c] = 0;
    }
    free(u);
    return 0;
}

/* Value, first and second derivative of each component at time t. */
static void table_eval(const mf_motion_table *tb, double t, double *y, double *dy, double *ddy)
{
    const int nc = tb->ncomp;
    for (int c = 0; c < nc; c++)
        y[c] = dy[c] = ddy[c] = 0;
    if (tb->n == 0)
        return;
    if (t <= tb->t[0] || tb->n == 1) {
        for (int c = 0; c < nc; c++)
            y[c] = tb->y[c];
        return;
    }
    if (t >= tb->t[tb->n - 1]) {
        for (int c = 0; c < nc; c++)
            y[c] = tb->y[(tb->n - 1) * nc + c];
        return;
    }
    size_t lo = 0, hi = tb->n - 1; /* t[lo] <= t < t[hi] */
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (tb->t[mid] <= t)
            lo = mid;
        else
            hi = mid;
    }
    const double h = tb->t[hi] - tb->t[lo];
    const double a = (tb->t[hi] - t) / h, b = (t - tb->t[lo]) / h;
    for (int c = 0; c < nc; c++) {
        const double ylo = tb->y[lo * nc + c], yhi = tb->y[hi * nc + c];
        y[c] = a * ylo + b * yhi;
        dy[c] = (yhi - ylo) / h;
        if (tb->y2) {
            const double mlo = tb->y2[lo * nc + c], mhi = tb->y2[hi * nc + c];
            y[c] += ((a * a * a - a) * mlo + (b * b * b - b) * mhi) * h * h / 6;
            dy[c] += (-(3 * a * a - 1) * mlo + (3 * b * b - 1) * mhi) * h / 6;
            ddy[c] = a * mlo + b * mhi;
        }
    }
}

/* key ((t v) (t v) ...): v a number (ncomp 1) or a vector (ncomp 3). */
static int read_table(const mf_dict *d, const char *key, int ncomp, double scale, bool spline,
                      mf_motion_table *tb)
{
    mf_entry *e = mf_dict_find(d, key);
    if (!e)
        return 0;
    e->used = true;
    char where[512];
    const char *shape = ncomp == 1 ? "((0 0) (1 10))" : "((0 (0 0 0)) (1 (0.1 0 0)))";
    if (e->n != 1 || e->items[0]->kind != MF_VAL_LIST || e->items[0]->n == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: motion '%s' takes a list of (time value) rows, e.g. %s",
                        mf_loc_str(e->loc, where, sizeof where), key, shape);
    const mf_value *list = e->items[0];
    tb->n = list->n;
    tb->ncomp = ncomp;
    tb->t = malloc(tb->n * sizeof *tb->t);
    tb->y = malloc(tb->n * (size_t)ncomp * sizeof *tb->y);
    if (!tb->t || !tb->y)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    for (size_t k = 0; k < list->n; k++) {
        const mf_value *row = list->items[k];
        bool ok = row->kind == MF_VAL_LIST && row->n == 2 && row->items[0]->kind == MF_VAL_NUMBER;
        if (ok && ncomp == 1)
            ok = row->items[1]->kind == MF_VAL_NUMBER;
        if (ok && ncomp == 3) {
            const mf_value *v = row->items[1];
            ok = v->kind == MF_VAL_LIST && v->n == 3;
            for (int c = 0; ok && c < 3; c++)
                ok = v->items[c]->kind == MF_VAL_NUMBER;
        }
        if (!ok)
            return MF_ERROR(MF_ERR_INPUT, "%s: motion '%s': row %zu is not (time %s), e.g. %s",
                            mf_loc_str(row->loc, where, sizeof where), key, k + 1,
                            ncomp == 1 ? "value" : "(x y z)", shape);
        tb->t[k] = row->items[0]->number;
        if (ncomp == 1)
            tb->y[k] = scale * row->items[1]->number;
        else
            for (int c = 0; c < 3; c++)
                tb->y[3 * k + c] = scale * row->items[1]->items[c]->number;
        if (!isfinite(tb->t[k]) || (k > 0 && !(tb->t[k] > tb->t[k - 1])))
            return MF_ERROR(MF_ERR_INPUT, "%s: motion '%s': the times must increase (row %zu: %g "
                            "after %g)", mf_loc_str(row->loc, where, sizeof where), key, k + 1,
                            tb->t[k], k > 0 ? tb->t[k - 1] : 0.0);
    }
    if (spline && tb->n > 2)
        MF_CALL(spline_prepare(tb));
    return 0;
}

/* ---- reading ----------------------------------------------------------------- */

int mf_motion_read(const mf_dict *d, int dim, mf_motion *m)
{
    memset(m, 0, sizeof *m);
    m->axis[2] = 1;
    if (!d)
        return 0;
    motion_settings s;
    MF_CALL(mf_params_apply(mf_motion_params, mf_motion_nparams, d, motion_extra, &s, NULL));
    for (int k = 0; motion_types[k]; k++)
        if (strcmp(s.type, motion_types[k]) == 0)
            m->kind = k;
    char where[512];
    double len = sqrt(s.axis[0] * s.axis[0] + s.axis[1] * s.axis[1] + s.axis[2] * s.axis[2]);
    if (dim == 2 && mf_dict_find(d, "axis") && (fabs(s.axis[0]) > 0 || fabs(s.axis[1]) > 0))
        return MF_ERROR(MF_ERR_INPUT, "%s: motion: in 2-D the axis of rotation is z (0 0 1)",
                        mf_loc_str(mf_dict_find(d, "axis")->loc, where, sizeof where));
    if (!(len > 0))
        return MF_ERROR(MF_ERR_INPUT, "%s: motion: axis must not be zero",
                        mf_loc_str(d->loc, where, sizeof where));
    for (int a = 0; a < 3; a++) {
        m->origin[a] = s.origin[a];
        m->axis[a] = s.axis[a] / len;
        m->velocity[a] = s.velocity[a];
        m->amplitude[a] = s.amplitude[a];
    }
    if (dim == 2) { /* no motion out of the plane */
        m->velocity[2] = m->amplitude[2] = 0;
        m->origin[2] = 0;
    }
    m->omega = s.omega;
    m->angle_amplitude = s.angle_amplitude * M_PI / 180;
    m->cycles = s.cycles;
    m->density = s.density;
    m->restitution = s.restitution;
    m->friction = s.friction;
    m->mass = s.mass;
    m->origin_given = mf_dict_find(d, "origin") != NULL;
    for (int a = 0; a < 3; a++) {
        m->inertia[a] = s.inertia[a];
        m->g[a] = dim == 2 && a == 2 ? 0 : s.g[a];
    }
    const bool spline = strcmp(s.interpolation, "spline") == 0;
    int rc = read_table(d, "displacement", 3, 1.0, spline, &m->disp);
    if (rc == 0)
        rc = read_table(d, "angle", 1, M_PI / 180, spline, &m->angle);
    if (rc == 0 && m->kind == MF_MOTION_TABLE && m->disp.n == 0 && m->angle.n == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: motion type table needs a displacement or an angle "
                      "table, e.g. displacement ((0 (0 0 0)) (1 (0.1 0 0)));",
                      mf_loc_str(d->loc, where, sizeof where));
    if (rc == 0 && m->kind != MF_MOTION_TABLE && (m->disp.n || m->angle.n))
        rc = MF_ERROR(MF_ERR_INPUT, "%s: displacement and angle tables belong to motion type "
                      "table (this one is %s)", mf_loc_str(d->loc, where, sizeof where), s.type);
    if (rc == 0 && m->kind == MF_MOTION_OSCILLATING && !(fabs(m->omega) > 0))
        rc = MF_ERROR(MF_ERR_INPUT, "%s: motion type oscillating needs omega (rad/s) != 0",
                      mf_loc_str(d->loc, where, sizeof where));
    if (rc == 0 && m->kind == MF_MOTION_RIGID && !(m->density > 0) && !(m->mass > 0))
        rc = MF_ERROR(MF_ERR_INPUT, "%s: motion type rigid needs a density (kg/m^3), or a mass "
                      "and an inertia", mf_loc_str(d->loc, where, sizeof where));
    if (rc == 0 && m->kind == MF_MOTION_RIGID && m->density > 0 && m->mass > 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: motion type rigid takes a density or a mass, not both",
                      mf_loc_str(d->loc, where, sizeof where));
    if (rc == 0 && m->kind == MF_MOTION_RIGID && m->mass > 0 &&
        !(dim == 2 ? m->inertia[2] > 0
                   : m->inertia[0] > 0 && m->inertia[1] > 0 && m->inertia[2] > 0))
        rc = MF_ERROR(MF_ERR_INPUT, "%s: motion type rigid with a mass needs its inertia, e.g. "
                      "inertia %s;", mf_loc_str(d->loc, where, sizeof where),
                      dim == 2 ? "(0 0 0.01)" : "(0.01 0.01 0.01)");
    if (dim == 2)
        for (size_t k = 0; rc == 0 && k < m->disp.n; k++)
            m->disp.y[3 * k + 2] = 0;
    if (rc != 0) {
        mf_motion_free(m);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    return 0;
}

/* ---- states -------------------------------------------------------------------- */

void mf_rotation_matrix(const double a[3], double angle, double R[9])
{
    const double c = cos(angle), s = sin(angle), C = 1 - c;
    const double x = a[0], y = a[1], z = a[2];
    const double M[9] = {c + x * x * C,     x * y * C - z * s, x * z * C + y * s,
                         y * x * C + z * s, c + y * y * C,     y * z * C - x * s,
                         z * x * C - y * s, z * y * C + x * s, c + z * z * C};
    memcpy(R, M, sizeof M);
}

static void identity_state(mf_rigid_state *s)
{
    memset(s, 0, sizeof *s);
    s->R[0] = s->R[4] = s->R[8] = 1;
}

/* An angle theta(t) about the axis with its rates into the state. */
static void set_angle(const mf_motion *m, double th, double dth, double ddth, mf_rigid_state *s)
{
    mf_rotation_matrix(m->axis, th, s->R);
    for (int a = 0; a < 3; a++) {
        s->w[a] = dth * m->axis[a];
        s->dw[a] = ddth * m->axis[a];
    }
}

void mf_motion_state(const mf_motion *m, double t, mf_rigid_state *s)
{
    identity_state(s);
    switch (m->kind) {
    case MF_MOTION_CONSTANT:
        for (int a = 0; a < 3; a++) {
            s->d[a] = m->velocity[a] * t;
            s->v[a] = m->velocity[a];
        }
        break;
    case MF_MOTION_ROTATION:
        set_angle(m, m->omega * t, m->omega, 0, s);
        break;
    case MF_MOTION_OSCILLATING: {
        const double w = m->omega;
        double tt = t;
        if (m->cycles > 0 && tt > 2 * M_PI * m->cycles / fabs(w))
            break; /* back where it started, at rest */
        if (tt < 0)
            break;
        const double sn = sin(w * tt), cs = cos(w * tt);
        for (int a = 0; a < 3; a++) {
            s->d[a] = m->amplitude[a] * sn;
            s->v[a] = m->amplitude[a] * w * cs;
            s->a[a] = -m->amplitude[a] * w * w * sn;
        }
        if (m->angle_amplitude != 0)
            set_angle(m, m->angle_amplitude * sn, m->angle_amplitude * w * cs,
                      -m->angle_amplitude * w * w * sn, s);
        break;
    }
    case MF_MOTION_TABLE: {
        if (m->disp.n)
            table_eval(&m->disp, t, s->d, s->v, s->a);
        if (m->angle.n) {
            double th, dth, ddth;
            table_eval(&m->angle, t, &th, &dth, &ddth);
            set_angle(m, th, dth, ddth, s);
        }
        break;
    }
    default:
        break;
    }
}

bool mf_wall_moves(const mf_wall *w)
{
    return w->motion.kind != MF_MOTION_NONE;
}

void mf_walls_set_time(mf_walls *ws, double t)
{
    for (size_t k = 0; ws && k < ws->n; k++) {
        mf_wall *w = &ws->w[k];
        if (w->motion.kind == MF_MOTION_NONE || w->motion.kind == MF_MOTION_EXTERNAL ||
            w->motion.kind == MF_MOTION_RIGID)
            continue;
        mf_motion_state(&w->motion, t, &w->state);
        w->state_time = t;
    }
}

void mf_wall_set_state(mf_wall *w, const mf_rigid_state *s, double t)
{
    w->state = *s;
    w->state_time = t;
}

void mf_wall_to_body(const mf_wall *w, const double x[3], double xb[3])
{
    const double *R = w->state.R, *o = w->motion.origin, *d = w->state.d;
    double r[3];
    for (int a = 0; a < 3; a++)
        r[a] = x[a] - o[a] - d[a];
    for (int a = 0; a < 3; a++) /* R^T r */
        xb[a] = o[a] + R[a] * r[0] + R[3 + a] * r[1] + R[6 + a] * r[2];
}

void mf_wall_to_world(const mf_wall *w, const double xb[3], double x[3])
{
    const double *R = w->state.R, *o = w->motion.origin, *d = w->state.d;
    double r[3];
    for (int a = 0; a < 3; a++)
        r[a] = xb[a] - o[a];
    for (int a = 0; a < 3; a++)
        x[a] = o[a] + d[a] + R[3 * a] * r[0] + R[3 * a + 1] * r[1] + R[3 * a + 2] * r[2];
}

void mf_wall_velocity(const mf_wall *w, const double x[3], bool with_surface, double v[3])
{
    const mf_rigid_state *s = &w->state;
    double r[3], wr[3];
    for (int a = 0; a < 3; a++)
        r[a] = x[a] - w->motion.origin[a] - s->d[a];
    mf_cross3(s->w, r, wr);
    for (int a = 0; a < 3; a++)
        v[a] = s->v[a] + wr[a];
    if (with_surface) {
        const double *R = s->R, *u = w->surface_velocity;
        for (int a = 0; a < 3; a++)
            v[a] += R[3 * a] * u[0] + R[3 * a + 1] * u[1] + R[3 * a + 2] * u[2];
    }
}

void mf_wall_acceleration(const mf_wall *w, const double x[3], double acc[3])
{
    const mf_rigid_state *s = &w->state;
    double r[3], ar[3], wr[3], wwr[3];
    for (int a = 0; a < 3; a++)
        r[a] = x[a] - w->motion.origin[a] - s->d[a];
    mf_cross3(s->dw, r, ar);
    mf_cross3(s->w, r, wr);
    mf_cross3(s->w, wr, wwr);
    for (int a = 0; a < 3; a++)
        acc[a] = s->a[a] + ar[a] + wwr[a];
}
