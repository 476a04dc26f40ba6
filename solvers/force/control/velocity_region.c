/* velocity_region.c: a velocity field prescribed in a region, the fluid's
 * velocity relaxed toward it:
 *
 *   a_i = rate w(x_i) (U(x_i) - u_i),   U(x) = velocity + Omega x (x - axisPoint)
 *
 * w is the blending weight: `weight` (0 to 1) inside the region, falling
 * linearly to 0 over the `blendWidth` next to its boundary on the inside (w
 * = weight min(1, -phi / blendWidth), phi the region's signed distance), so
 * that a region edge does not shear the fluid in one particle spacing. A
 * particle held in the region long enough moves at w U + (1 - w) times
 * what the rest of the flow gives it; with w = 1, at U within the rate's
 * time 1/rate. Fluid outside the region feels nothing; the force costs one
 * shape test per fluid particle (a look-up for a mesh region). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "control.h"
#include "force/forces.h"
#include "mf_error.h"

typedef struct vregion_settings {
    control_shape_settings region;
    double velocity[3], omega[3], axis_point[3];
    double rate, weight, blend;
} vregion_settings;

static const mf_param vregion_params[] = {
    CONTROL_SHAPE_PARAMS(vregion_settings, region, "region shape"),
    {"velocity", MF_PARAM_VECTOR, "(0 0 0)", -1e6, 1e6, NULL, offsetof(vregion_settings, velocity),
     "prescribed velocity U, m/s (plus the rotation of angularVelocity)"},
    {"angularVelocity", MF_PARAM_VECTOR, "(0 0 0)", -1e6, 1e6, NULL,
     offsetof(vregion_settings, omega),
     "prescribed rotation Omega, rad/s (its z in 2-D): U + Omega x (x - axisPoint)"},
    {"axisPoint", MF_PARAM_VECTOR, "(0 0 0)", -1e6, 1e6, NULL,
     offsetof(vregion_settings, axis_point), "a point of the rotation axis, m"},
    {"rate", MF_PARAM_SCALAR, "50", 0, 1e6, NULL, offsetof(vregion_settings, rate),
     "relaxation rate toward the prescribed velocity, 1/s"},
    {"weight", MF_PARAM_SCALAR, "1", 0, 1, NULL, offsetof(vregion_settings, weight),
     "blending weight w inside the region"},
    {"blendWidth", MF_PARAM_SCALAR, "0", 0, 1e6, NULL, offsetof(vregion_settings, blend),
     "width inside the region's boundary over which w rises from 0, m (box, sphere)"},
};
#define VREGION_NPARAMS (sizeof vregion_params / sizeof vregion_params[0])

typedef struct vregion_data {
    vregion_settings s;
    control_shape region;
} vregion_data;

static void vregion_destroy(void *data)
{
    vregion_data *d = data;
    if (!d)
        return;
    control_shape_free(&d->region);
    free(d);
}

static int vregion_create(const void *settings, mf_sim *sim, void **data)
{
    vregion_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->s = *(const vregion_settings *)settings;
    int rc = control_shape_create(&d->s.region, "velocityRegion", sim, &d->region);
    if (rc == 0 && d->region.type == CONTROL_POINT)
        rc = MF_ERROR(MF_ERR_INPUT, "force velocityRegion: a point has no inside: use a box, "
                      "sphere or mesh region");
    if (rc == 0 && d->s.blend > 0 && d->region.type == CONTROL_MESH)
        rc = MF_ERROR(MF_ERR_INPUT, "force velocityRegion: blendWidth %g with a mesh region: a "
                      "mesh is sampled inside/outside only; use blendWidth 0 or a box or sphere",
                      d->s.blend);
    if (rc != 0) {
        vregion_destroy(d);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "velocityRegion: U = (%g %g %g) m/s in the %s region, rate %g 1/s, w = %g\n",
                  d->s.velocity[0], d->s.velocity[1], d->s.velocity[2], d->s.region.shape,
                  d->s.rate, d->s.weight);
    *data = d;
    return 0;
}

/* The blending weight at signed distance phi (< 0 inside). */
static double blend_weight(const vregion_settings *s, double phi)
{
    if (!(phi < 0))
        return 0;
    return s->blend > 0 ? s->weight * fmin(1, -phi / s->blend) : s->weight;
}

static int vregion_accumulate(void *data, const mf_sim *sim, double *acc)
{
    const vregion_data *d = data;
    const vregion_settings *s = &d->s;
    const mf_particles *p = sim->p;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *x = &p->pos[3 * i];
        const double w = blend_weight(s, control_shape_phi(&d->region, x, NULL));
        if (w == 0)
            continue;
        const double r[3] = {x[0] - s->axis_point[0], x[1] - s->axis_point[1],
                             x[2] - s->axis_point[2]};
        const double U[3] = {s->velocity[0] + s->omega[1] * r[2] - s->omega[2] * r[1],
                             s->velocity[1] + s->omega[2] * r[0] - s->omega[0] * r[2],
                             s->velocity[2] + s->omega[0] * r[1] - s->omega[1] * r[0]};
        for (int q = 0; q < p->dim; q++)
            acc[3 * i + q] += s->rate * w * (U[q] - p->vel[3 * i + q]);
    }
    return 0;
}

/* Explicit relaxation: rate dt <= 1, so that a step never overshoots U. */
static int vregion_stable_dt(void *data, const mf_sim *sim, double *dt)
{
    (void)sim;
    const vregion_data *d = data;
    *dt = d->s.rate * d->s.weight > 0 ? 1 / (d->s.rate * d->s.weight) : INFINITY;
    return 0;
}

const mf_force_ops mf_force_velocityRegion = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "velocityRegion",
             "the fluid's velocity relaxed toward a prescribed field in a region",
             vregion_params, VREGION_NPARAMS, sizeof(vregion_settings)},
    .create = vregion_create,
    .accumulate = vregion_accumulate,
    .destroy = vregion_destroy,
    .stable_dt = vregion_stable_dt,
};
