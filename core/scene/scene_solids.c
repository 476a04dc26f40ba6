/* scene_solids.c: the solids of constant/geometry as mf_walls.h records, and
 * the obstacles of type box, cylinder and sphere:
 *
 *   obstacles
 *   {
 *       block  { type box;      min (0.6 0 0); max (0.7 0.1 0); }
 *       pillar { type cylinder; centre (0.5 0.2 0); radius 0.05;
 *                axis (0 0 1); length 0.3; }          // 3-D only: axis, length
 *       ball   { type sphere;   centre (0.3 0.3 0.2); radius 0.04;
 *                motion { type rotation; origin (0.3 0.3 0.2); omega 1; } }
 *   }
 *
 * With particle walls, a box obstacle's particles sit on its own lattice
 * min + (i + 1/2) l0, a cylinder's and a sphere's on the case lattice
 * (i + 1/2) l0 (that of meshes); a lattice point inside the shape at depth
 * d is in layer floor(d / l0), MF_WALL for the first wallLayers or where a
 * lattice neighbour lies outside, MF_DUMMY for the next dummyLayers, and
 * deeper points are left out (mf_trimesh.h has the same rule for meshes). */
#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_bodies.h"
#include "mf_error.h"
#include "scene_internal.h"
#include "walls_internal.h"

/* ---- every solid ------------------------------------------------------------- */

int mf_scene_solid_init(const mf_sim *sim, const char *name, const mf_dict *d,
                        const double velocity[3], const mf_dict *motion, int shape,
                        bool obstacle, mf_wall *w)
{
    memset(w, 0, sizeof *w);
    snprintf(w->name, sizeof w->name, "%s", name);
    char where[512];
    snprintf(w->where, sizeof w->where, "%s", mf_loc_str(d->loc, where, sizeof where));
    w->shape = shape;
    w->obstacle = obstacle;
    w->dim = sim->dim;
    for (int a = 0; a < 3; a++)
        w->surface_velocity[a] = a < sim->dim ? velocity[a] : 0;
    MF_CALL(mf_motion_read(motion, sim->dim, &w->motion));
    mf_motion_state(&w->motion, 0, &w->state);
    return 0;
}

int mf_scene_solid_add(mf_sim *sim, mf_wall *w, size_t first)
{
    mf_particles *p = sim->p;
    mf_walls *ws = sim->walls;
    w->first = (long)first;
    w->count = (long)(p->n - first);
    if (w->motion.kind == MF_MOTION_RIGID) {
        if (sim->wall_weight)
            return MF_ERROR(MF_ERR_INPUT, "%s: '%s': rigid bodies need particle walls (the "
                            "fluid's forces on them are summed over their particles)",
                            w->where, w->name);
        MF_CALL(mf_body_create(w, sim->dim));
    }
    const bool moving = mf_wall_moves(w);
    size_t index;
    MF_CALL(mf_walls_add(ws, w, &index));
    const mf_wall *in = &ws->w[index];
    if (moving && p->n > first && ws->f_wall_id < 0)
        MF_CALL(mf_particles_request_field(p, "WallId", 1, MF_FIELD_INT32, true,
                                           &ws->f_wall_id));
    int32_t *id = moving && p->n > first ? mf_particles_fi(p, ws->f_wall_id) : NULL;
    for (size_t i = first; i < p->n; i++) {
        mf_wall_velocity(in, &p->pos[3 * i], true, &p->vel[3 * i]);
        if (id)
            id[i] = (int32_t)index + 1;
    }
    return 0;
}

/* ---- what the lattice made of a shape ------------------------------------------ */

void mf_scene_warn_extent(const mf_sim *sim, const char *where, const char *what,
                          const char *name, const double want[3], size_t first, int kind)
{
    const mf_particles *p = sim->p;
    double mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    size_t count = 0;
    for (size_t i = first; i < p->n; i++) {
        if (kind >= 0 && p->kind[i] != kind)
            continue;
        count++;
        for (int a = 0; a < sim->dim; a++) {
            mn[a] = fmin(mn[a], p->pos[3 * i + a]);
            mx[a] = fmax(mx[a], p->pos[3 * i + a]);
        }
    }
    if (count == 0)
        return;
    static const char axes[] = "xyz";
    for (int a = 0; a < sim->dim; a++) {
        const double got = mx[a] - mn[a] + sim->l0;
        if (fabs(got - want[a]) >= 0.5 * sim->l0 * (1 - 1e-6))
            mf_log_printf(sim->log, MF_LOG_QUIET,
                          "Warning: %s: %s '%s' is %g m along %c, but the lattice of l0 = %g "
                          "makes it %g m (half a spacing or more off): make its size a "
                          "multiple of l0, or choose another particleSpacing\n",
                          where, what, name, want[a], axes[a], sim->l0, got);
    }
}

void mf_scene_warn_radius(const mf_sim *sim, const char *where, const char *what,
                          const char *name, double radius, size_t count)
{
    const double l0 = sim->l0;
    const double got = sim->dim == 2 ? sqrt((double)count * l0 * l0 / M_PI)
                                     : cbrt(3.0 * (double)count * l0 * l0 * l0 / (4 * M_PI));
    if (fabs(got - radius) >= 0.5 * l0 * (1 - 1e-6))
        mf_log_printf(sim->log, MF_LOG_QUIET,
                      "Warning: %s: %s '%s' has radius %g m, but its %zu particles of l0 = %g "
                      "fill a %s of radius %g m (half a spacing or more off): choose a "
                      "finer particleSpacing\n",
                      where, what, name, radius, count, l0, sim->dim == 2 ? "disk" : "ball", got);
}

/* ---- obstacles: box, cylinder, sphere --------------------------------------------- */

static const char *const obstacle_types[] = {"box", "cylinder", "sphere", "mesh", NULL};

typedef struct obstacle_settings {
    const char *type;
    double min[3], max[3], centre[3], axis[3], velocity[3];
    double radius, length;
    long wall_layers, dummy_layers;
    const mf_dict *motion;
} obstacle_settings;

#define SOLID_COMMON(S)                                                                          \
    {"velocity", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, offsetof(S, velocity),          \
     "velocity of the surface along itself, m/s (a belt, a sliding lid; the shape stays)"},     \
    {"motion", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(S, motion),                     \
     "prescribed rigid motion (see geometry: <solid>/motion)"},                                  \
    {"wallLayers", MF_PARAM_INT, "1", 1, 3, NULL, offsetof(S, wall_layers),                     \
     "particle walls: layers of wall particles (in the pressure equation)"},                    \
    {"dummyLayers", MF_PARAM_INT, "2", 0, 4, NULL, offsetof(S, dummy_layers),                   \
     "particle walls: layers of dummy particles behind them (number density only)"}

static const mf_param obstacle_params[] = {
    {"type", MF_PARAM_WORD, NULL, MF_NO_RANGE, obstacle_types, offsetof(obstacle_settings, type),
     "box (min, max), cylinder (centre, radius; 3-D: axis, length), sphere (centre, radius; a "
     "disk in 2-D), mesh (a polygon file: geometry: obstacles/<name>)"},
    {"min", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, offsetof(obstacle_settings, min),
     "box: lower corner, m"},
    {"max", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, offsetof(obstacle_settings, max),
     "box: upper corner, m"},
    {"centre", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL,
     offsetof(obstacle_settings, centre), "cylinder, sphere: centre, m"},
    {"radius", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(obstacle_settings, radius),
     "cylinder, sphere: radius, m"},
    {"axis", MF_PARAM_VECTOR, "(0 0 1)", MF_NO_RANGE, NULL, offsetof(obstacle_settings, axis),
     "cylinder (3-D): direction of its axis"},
    {"length", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(obstacle_settings, length),
     "cylinder (3-D): length along the axis, centred on centre, m (0: endless)"},
    SOLID_COMMON(obstacle_settings),
};
#define NP(t) (sizeof(t) / sizeof((t)[0]))

const mf_param_section mf_solid_sections[] = {
    {"geometry: obstacles/<name>, type box, cylinder or sphere",
     "a solid body placed in the fluid (a fluid particle closer than l0/2 to it is refused)",
     obstacle_params, NP(obstacle_params)},
};
const size_t mf_solid_nsections = NP(mf_solid_sections);

static int need(bool ok, const mf_dict *d, const char *name, const char *what)
{
    if (ok)
        return 0;
    char where[512];
    return MF_ERROR(MF_ERR_INPUT, "%s: obstacle '%s': %s", mf_loc_str(d->loc, where, sizeof where),
                    name, what);
}

/* A lattice point of a shape at depth `depth` (> 0 inside) into its layer. */
static int place(mf_sim *sim, const double x[3], double depth, long wall_layers, long layers,
                 bool touches_outside)
{
    const long layer = (long)floor(depth / sim->l0 + 1e-9);
    if (layer >= layers)
        return 0;
    const double v0[3] = {0, 0, 0};
    const int kind = layer < wall_layers || touches_outside ? MF_WALL : MF_DUMMY;
    return mf_particles_add(sim->p, kind, x, v0, NULL);
}

/* The number of lattice points of a box obstacle along each axis (the
 * rule of mf_box_lattice_max). */
static void box_counts(const mf_sim *sim, const double mn[3], const double mx[3], long n[3])
{
    n[0] = n[1] = n[2] = 1;
    for (int a = 0; a < sim->dim; a++)
        n[a] = (long)floor((mx[a] - mn[a]) / sim->l0 + 1e-9);
}

static int fill_box(mf_sim *sim, const obstacle_settings *s)
{
    const double l0 = sim->l0;
    long n[3];
    box_counts(sim, s->min, s->max, n);
    const long layers = s->wall_layers + s->dummy_layers;
    for (long k = 0; k < n[2]; k++)
        for (long j = 0; j < n[1]; j++)
            for (long i = 0; i < n[0]; i++) {
                const long idx[3] = {i, j, k};
                long layer = LONG_MAX;
                for (int a = 0; a < sim->dim; a++) {
                    long in = idx[a] < n[a] - 1 - idx[a] ? idx[a] : n[a] - 1 - idx[a];
                    if (in < layer)
                        layer = in;
                }
                const double x[3] = {s->min[0] + (i + 0.5) * l0, s->min[1] + (j + 0.5) * l0,
                                     sim->dim == 3 ? s->min[2] + (k + 0.5) * l0 : 0.0};
                MF_CALL(place(sim, x, ((double)layer + 0.5) * l0, s->wall_layers, layers, false));
            }
    return 0;
}

/* Cylinder, sphere: the case lattice within the shape's bounding box. */
static int fill_round(mf_sim *sim, const mf_wall *w, const obstacle_settings *s)
{
    const double l0 = sim->l0;
    const double ext = s->radius + (sim->dim == 3 && w->shape == MF_SOLID_CYLINDER
                                        ? (w->half_length > 0 ? w->half_length : 0)
                                        : 0);
    const long layers = s->wall_layers + s->dummy_layers;
    long lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int a = 0; a < sim->dim; a++) {
        lo[a] = (long)floor((s->centre[a] - ext) / l0) - 1;
        hi[a] = (long)ceil((s->centre[a] + ext) / l0) + 1;
    }
    for (long k = lo[2]; k <= hi[2]; k++)
        for (long j = lo[1]; j <= hi[1]; j++)
            for (long i = lo[0]; i <= hi[0]; i++) {
                const double x[3] = {(i + 0.5) * l0, (j + 0.5) * l0,
                                     sim->dim == 3 ? (k + 0.5) * l0 : 0.0};
                double n[3];
                const double d = mf_wall_body_distance(w, x, n);
                if (!(d < 0))
                    continue;
                bool touches = false;
                for (int dz = sim->dim == 3 ? -1 : 0; dz <= (sim->dim == 3 ? 1 : 0) && !touches;
                     dz++)
                    for (int dy = -1; dy <= 1 && !touches; dy++)
                        for (int dx = -1; dx <= 1 && !touches; dx++) {
                            const double y[3] = {x[0] + dx * l0, x[1] + dy * l0, x[2] + dz * l0};
                            touches = mf_wall_body_distance(w, y, n) >= 0;
                        }
                MF_CALL(place(sim, x, -d, s->wall_layers, layers, touches));
            }
    return 0;
}

int mf_scene_obstacle(mf_sim *sim, const char *name, const mf_dict *d, mf_dict *resolved)
{
    obstacle_settings s;
    MF_CALL(mf_params_apply(obstacle_params, NP(obstacle_params), d, NULL, &s, resolved));
    int shape = strcmp(s.type, "box") == 0        ? MF_SOLID_BOX
                : strcmp(s.type, "cylinder") == 0 ? MF_SOLID_CYLINDER
                                                  : MF_SOLID_SPHERE;
    mf_wall w;
    MF_CALL(mf_scene_solid_init(sim, name, d, s.velocity, s.motion, shape, true, &w));
    int rc = 0;
    if (shape == MF_SOLID_BOX) {
        rc = need(mf_dict_find(d, "min") && mf_dict_find(d, "max"), d, name,
                  "type box needs 'min' and 'max'");
        for (int a = 0; rc == 0 && a < sim->dim; a++)
            rc = need(s.max[a] > s.min[a], d, name, "max must exceed min on every axis");
        memcpy(w.min, s.min, sizeof w.min);
        memcpy(w.max, s.max, sizeof w.max);
        if (sim->dim == 2)
            w.min[2] = w.max[2] = 0;
    } else {
        rc = need(s.radius > 0 && mf_dict_find(d, "centre"), d, name,
                  shape == MF_SOLID_CYLINDER ? "type cylinder needs a centre and a radius > 0"
                                             : "type sphere needs a centre and a radius > 0");
        memcpy(w.centre, s.centre, sizeof w.centre);
        w.radius = s.radius;
        if (sim->dim == 2)
            w.centre[2] = 0;
        const double len = sqrt(s.axis[0] * s.axis[0] + s.axis[1] * s.axis[1] +
                                s.axis[2] * s.axis[2]);
        if (rc == 0 && shape == MF_SOLID_CYLINDER && sim->dim == 3)
            rc = need(len > 0, d, name, "axis must not be zero");
        for (int a = 0; rc == 0 && a < 3; a++)
            w.axis[a] = sim->dim == 3 ? s.axis[a] / len : (a == 2);
        w.half_length = 0.5 * s.length;
    }
    const size_t first = sim->p->n;
    if (rc == 0 && !sim->wall_weight)
        rc = shape == MF_SOLID_BOX ? fill_box(sim, &s) : fill_round(sim, &w, &s);
    if (rc == 0 && !sim->wall_weight && sim->p->n == first)
        rc = need(false, d, name, "smaller than one particle spacing: no particle placed");
    if (rc == 0 && !sim->wall_weight) {
        if (shape == MF_SOLID_BOX) {
            double want[3];
            for (int a = 0; a < 3; a++)
                want[a] = s.max[a] - s.min[a];
            mf_scene_warn_extent(sim, w.where, "obstacle", name, want, first, -1);
            /* The record is the box the particles stand for, not the asked
             * one when the lattice makes it smaller (warned just above): the
             * watch's throughWall test and a rigid body's faces and contacts
             * must see the solid the fluid's pressure sees. At l0 0.00487 the
             * tutorial damBreakObstacle's 0.024 m block is 4 particles,
             * 0.01948 m: fluid 0.93 l0 beside its last wall column was
             * "inside obstacle 'block'" by the asked face (docs/notes/mps.md,
             * "The obstacle at three spacings"). */
            mf_box_lattice_max(sim->l0, sim->dim, w.min, w.max);
        }
    }
    if (rc == 0) {
        const size_t nw = sim->p->n - first;
        mf_log_printf(sim->log, MF_LOG_NORMAL, "Obstacle %s '%s': %zu wall and dummy particles%s\n",
                      s.type, name, nw, sim->wall_weight ? " (wall weight: none)" : "");
        rc = mf_scene_solid_add(sim, &w, first);
    }
    if (rc != 0) {
        mf_motion_free(&w.motion);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    return 0;
}
