/* emitter.c: transported scalars, inlets, outlets and nozzles (mf_emitter.h). */
#include "mf_emitter.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_params.h"
#include "mf_scene.h"
#include "scene_lattice.h"

/* ======================================================================
 * Scalar profiles
 * ==================================================================== */

static const char *const profile_types[] = {"uniform", "gaussian", "step", "box", NULL};

typedef struct profile_settings {
    const char *type;
    double value, amplitude, width, base, below, above, inside, outside;
    double centre[3], direction[3], origin[3], normal[3], min[3], max[3];
} profile_settings;

#define PS(f) offsetof(profile_settings, f)
static const mf_param uniform_params[] = {
    {"type", MF_PARAM_WORD, "uniform", MF_NO_RANGE, profile_types, PS(type), "profile"},
    {"value", MF_PARAM_SCALAR, NULL, MF_NO_RANGE, NULL, PS(value), "the value everywhere"},
};
static const mf_param gaussian_params[] = {
    {"type", MF_PARAM_WORD, "gaussian", MF_NO_RANGE, profile_types, PS(type), "profile"},
    {"centre", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, PS(centre), "centre of the bump, m"},
    {"width", MF_PARAM_SCALAR, NULL, 1e-12, 1e12, NULL, PS(width),
     "standard deviation s of exp(-d^2/(2 s^2)), m"},
    {"amplitude", MF_PARAM_SCALAR, "1", MF_NO_RANGE, NULL, PS(amplitude), "peak above the base"},
    {"base", MF_PARAM_SCALAR, "0", MF_NO_RANGE, NULL, PS(base), "value far from the centre"},
    {"direction", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, PS(direction),
     "measure d along this direction only ((0 0 0): distance in every direction)"},
};
static const mf_param step_params[] = {
    {"type", MF_PARAM_WORD, "step", MF_NO_RANGE, profile_types, PS(type), "profile"},
    {"origin", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, PS(origin), "a point of the step, m"},
    {"normal", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, PS(normal),
     "the step's normal: 'above' on the side it points to"},
    {"below", MF_PARAM_SCALAR, "1", MF_NO_RANGE, NULL, PS(below), "value behind the step"},
    {"above", MF_PARAM_SCALAR, "0", MF_NO_RANGE, NULL, PS(above), "value ahead of the step"},
};
static const mf_param box_params[] = {
    {"type", MF_PARAM_WORD, "box", MF_NO_RANGE, profile_types, PS(type), "profile"},
    {"min", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, PS(min), "lower corner, m"},
    {"max", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, PS(max), "upper corner, m"},
    {"inside", MF_PARAM_SCALAR, "1", MF_NO_RANGE, NULL, PS(inside), "value inside the box"},
    {"outside", MF_PARAM_SCALAR, "0", MF_NO_RANGE, NULL, PS(outside), "value outside"},
};
#undef PS

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

int mf_scalar_profile_read(const mf_entry *e, int dim, mf_scalar_profile *out, mf_dict *resolved)
{
    char where[512];
    memset(out, 0, sizeof *out);
    if (e->n == 1 && e->items[0]->kind == MF_VAL_NUMBER) {
        out->type = MF_PROFILE_UNIFORM;
        out->value = e->items[0]->number;
        if (resolved)
            MF_CALL(mf_dict_set_number(resolved, e->key, out->value));
        return 0;
    }
    if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: scalar '%s' takes a number or a profile { type gaussian; ... } "
                        "(types: uniform, gaussian, step, box)",
                        mf_loc_str(e->loc, where, sizeof where), e->key);
    const mf_dict *d = e->items[0]->dict;
    const char *type = NULL;
    MF_CALL(mf_dict_get_word(d, "type", &type));
    int t = -1;
    for (int k = 0; profile_types[k]; k++)
        if (strcmp(type, profile_types[k]) == 0)
            t = k;
    if (t < 0) {
        const char *hint = mf_did_you_mean(type, profile_types, 4);
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: scalar '%s': unknown profile type '%s'%s%s%s; valid: uniform, "
                        "gaussian, step, box",
                        mf_loc_str(mf_dict_find(d, "type")->loc, where, sizeof where), e->key,
                        type, hint ? " (did you mean '" : "", hint ? hint : "",
                        hint ? "'?)" : "");
    }
    static const mf_param *const tables[] = {uniform_params, gaussian_params, step_params,
                                             box_params};
    static const size_t sizes[] = {2, 6, 5, 5};
    profile_settings s;
    memset(&s, 0, sizeof s);
    mf_dict *r = resolved ? mf_dict_set_subdict(resolved, e->key) : NULL;
    MF_CALL(mf_params_apply(tables[t], sizes[t], d, NULL, &s, r));
    out->type = (mf_profile_type)t;
    switch (out->type) {
    case MF_PROFILE_UNIFORM:
        out->value = s.value;
        break;
    case MF_PROFILE_GAUSSIAN: {
        out->value = s.base;
        out->amplitude = s.amplitude;
        out->width = s.width;
        memcpy(out->centre, s.centre, sizeof out->centre);
        double len = norm3(s.direction);
        for (int a = 0; a < 3; a++)
            out->direction[a] = len > 0 ? s.direction[a] / len : 0.0;
        break;
    }
    case MF_PROFILE_STEP: {
        double len = norm3(s.normal);
        if (!(len > 0))
            return MF_ERROR(MF_ERR_INPUT, "%s: scalar '%s': 'normal' must not be zero",
                            mf_loc_str(mf_dict_find(d, "normal")->loc, where, sizeof where),
                            e->key);
        memcpy(out->centre, s.origin, sizeof out->centre);
        for (int a = 0; a < 3; a++)
            out->direction[a] = s.normal[a] / len;
        out->inside = s.below;
        out->outside = s.above;
        break;
    }
    case MF_PROFILE_BOX:
        for (int a = 0; a < dim; a++)
            if (!(s.max[a] > s.min[a]))
                return MF_ERROR(MF_ERR_INPUT,
                                "%s: scalar '%s': box max must exceed min on every axis",
                                mf_loc_str(d->loc, where, sizeof where), e->key);
        memcpy(out->min, s.min, sizeof out->min);
        memcpy(out->max, s.max, sizeof out->max);
        if (dim == 2) { /* the z extent plays no part in 2-D */
            out->min[2] = -INFINITY;
            out->max[2] = INFINITY;
        }
        out->inside = s.inside;
        out->outside = s.outside;
        break;
    }
    return 0;
}

double mf_scalar_profile_eval(const mf_scalar_profile *s, const double x[3])
{
    switch (s->type) {
    case MF_PROFILE_UNIFORM:
        return s->value;
    case MF_PROFILE_GAUSSIAN: {
        double r[3] = {x[0] - s->centre[0], x[1] - s->centre[1], x[2] - s->centre[2]};
        double d2;
        if (s->direction[0] != 0 || s->direction[1] != 0 || s->direction[2] != 0) {
            double along = r[0] * s->direction[0] + r[1] * s->direction[1] + r[2] * s->direction[2];
            d2 = along * along;
        } else {
            d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        }
        return s->value + s->amplitude * exp(-d2 / (2.0 * s->width * s->width));
    }
    case MF_PROFILE_STEP: {
        double side = 0;
        for (int a = 0; a < 3; a++)
            side += (x[a] - s->centre[a]) * s->direction[a];
        return side < 0 ? s->inside : s->outside;
    }
    case MF_PROFILE_BOX:
        for (int a = 0; a < 3; a++)
            if (x[a] < s->min[a] || x[a] > s->max[a])
                return s->outside;
        return s->inside;
    }
    return 0.0;
}

int mf_scalar_declare(mf_sim *sim, const char *name, int *field)
{
    /* Datasets of every snapshot and fields solvers create: a scalar of that
     * name would silently share (or clash with) them. */
    static const char *const reserved[] = {
        "Coordinates", "Velocities", "ParticleIDs", "StorageIndex", "Pressure", "NumberDensity",
        "Flags", "FluidId", "ConvectionVelocity", "PointVelocity", NULL};
    for (int k = 0; reserved[k]; k++)
        if (strcmp(name, reserved[k]) == 0 || strncmp(name, "Mafl", 4) == 0)
            return MF_ERROR(MF_ERR_INPUT,
                            "scalar '%s': the name is taken by a particle field of mpsflow; "
                            "choose another (e.g. dye, temperature)",
                            name);
    size_t len = strlen(name);
    if (len == 0 || len >= sizeof sim->scalar_name[0])
        return MF_ERROR(MF_ERR_INPUT, "scalar '%s': names have 1 to %zu characters", name,
                        sizeof sim->scalar_name[0] - 1);
    int known = -1;
    for (int k = 0; k < sim->nscalars; k++)
        if (strcmp(sim->scalar_name[k], name) == 0)
            known = k;
    if (known < 0 && sim->nscalars == MF_MAX_SCALARS)
        return MF_ERROR(MF_ERR_INPUT, "scalar '%s': at most %d transported scalars", name,
                        MF_MAX_SCALARS);
    MF_CALL(mf_particles_request_field(sim->p, name, 1, MF_FIELD_DOUBLE, true, field));
    if (known < 0)
        memcpy(sim->scalar_name[sim->nscalars++], name, len + 1);
    return 0;
}

/* Walk `scalars { name value-or-profile; ... }`, declaring each field. */
static int read_scalars(mf_sim *sim, const mf_dict *scalars, mf_emitter_scalars *out,
                        mf_dict *resolved)
{
    char where[512];
    out->n = 0;
    for (size_t k = 0; scalars && k < scalars->n; k++) {
        mf_entry *e = scalars->entries[k];
        e->used = true;
        if (out->n == MF_EMITTER_MAX_SCALARS)
            return MF_ERROR(MF_ERR_INPUT, "%s: at most %d scalars",
                            mf_loc_str(e->loc, where, sizeof where), MF_EMITTER_MAX_SCALARS);
        int rc = mf_scalar_declare(sim, e->key, &out->field[out->n]);
        if (rc != 0)
            return MF_ERROR(rc, "%s: %s", mf_loc_str(e->loc, where, sizeof where),
                            mf_error_message());
        MF_CALL(mf_scalar_profile_read(e, sim->dim, &out->value[out->n], resolved));
        out->n++;
    }
    return 0;
}

static void set_scalars(const mf_emitter_scalars *s, mf_particles *p, size_t i)
{
    for (int k = 0; k < s->n; k++)
        mf_particles_fd(p, s->field[k])[i] = mf_scalar_profile_eval(&s->value[k], &p->pos[3 * i]);
}

int mf_scene_block_scalars(mf_sim *sim, const mf_dict *scalars, size_t first, size_t last,
                           mf_dict *resolved)
{
    mf_emitter_scalars s;
    MF_CALL(read_scalars(sim, scalars, &s, resolved));
    for (size_t i = first; i < last; i++)
        set_scalars(&s, sim->p, i);
    return 0;
}

/* ======================================================================
 * Parsing inlets, outlets, nozzles
 * ==================================================================== */

static const char *const inlet_profiles[] = {"uniform", "parabolic", NULL};

typedef struct inlet_settings {
    double min[3], max[3], velocity[3];
    const char *profile, *fluid;
    const mf_dict *scalars;
} inlet_settings;

static const mf_param inlet_params[] = {
    {"min", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(inlet_settings, min),
     "lower corner of the inlet buffer, m"},
    {"max", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(inlet_settings, max),
     "upper corner of the inlet buffer, m"},
    {"velocity", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(inlet_settings, velocity),
     "mean inflow velocity, m/s (along a coordinate axis: the inflow direction)"},
    {"profile", MF_PARAM_WORD, "uniform", MF_NO_RANGE, inlet_profiles,
     offsetof(inlet_settings, profile),
     "velocity across the inlet: uniform, or parabolic with the same mean"},
    {"fluid", MF_PARAM_WORD, "", MF_NO_RANGE, NULL, offsetof(inlet_settings, fluid),
     "fluid that enters (empty: the first of constant/fluids)"},
    {"scalars", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(inlet_settings, scalars),
     "values of transported scalars that enter: { dye 1; }"},
};

typedef struct outlet_settings {
    double min[3], max[3], direction[3], velocity[3];
} outlet_settings;

static const mf_param outlet_params[] = {
    {"min", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(outlet_settings, min),
     "lower corner of the outlet buffer, m"},
    {"max", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(outlet_settings, max),
     "upper corner of the outlet buffer, m"},
    {"direction", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(outlet_settings, direction),
     "outflow direction (along a coordinate axis)"},
    {"velocity", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL,
     offsetof(outlet_settings, velocity), "initial velocity of the outlet's points, m/s"},
};

static const char *const nozzle_types[] = {"nozzle", NULL};

typedef struct nozzle_settings {
    const char *type, *fluid;
    double centre[3], velocity[3];
    double diameter, rate, start, end;
    const mf_dict *scalars;
} nozzle_settings;

static const mf_param nozzle_params[] = {
    {"type", MF_PARAM_WORD, "nozzle", MF_NO_RANGE, nozzle_types, offsetof(nozzle_settings, type),
     "kind of emitter"},
    {"centre", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(nozzle_settings, centre),
     "middle of the opening, m"},
    {"velocity", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(nozzle_settings, velocity),
     "velocity of the fluid added, m/s (its direction is the nozzle's axis)"},
    {"diameter", MF_PARAM_SCALAR, NULL, 1e-12, 1e12, NULL, offsetof(nozzle_settings, diameter),
     "diameter of the opening (its width in 2-D), m"},
    {"rate", MF_PARAM_SCALAR, "0", 0, 1e12, NULL, offsetof(nozzle_settings, rate),
     "volume per second (m^2/s in 2-D); 0: |velocity| times the opening"},
    {"start", MF_PARAM_SCALAR, "0", 0, 1e30, NULL, offsetof(nozzle_settings, start),
     "first time it emits, s"},
    {"end", MF_PARAM_SCALAR, "1e30", 0, 1e30, NULL, offsetof(nozzle_settings, end),
     "it emits before this time, s"},
    {"fluid", MF_PARAM_WORD, "", MF_NO_RANGE, NULL, offsetof(nozzle_settings, fluid),
     "fluid it adds (empty: the first of constant/fluids)"},
    {"scalars", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(nozzle_settings, scalars),
     "values of transported scalars it adds: { dye 1; }"},
};

/* The axis of v and its sign, if v is along one coordinate axis. */
static int axis_of(const double v[3], int dim, int *axis, int *sign)
{
    int found = -1;
    for (int a = 0; a < dim; a++) {
        if (v[a] == 0)
            continue;
        if (found >= 0)
            return -1;
        found = a;
    }
    if (found < 0)
        return -1;
    *axis = found;
    *sign = v[found] > 0 ? 1 : -1;
    return 0;
}

static int fluid_index(mf_sim *sim, const mf_dict *d, const char *name, int *fluid,
                       mf_dict *resolved)
{
    *fluid = 0;
    if (name && name[0]) {
        int rc = mf_scene_fluid_index(sim, name, fluid);
        if (rc != 0) {
            char where[512];
            return MF_ERROR(rc, "%s: %s", mf_loc_str(mf_dict_find(d, "fluid")->loc, where,
                                                     sizeof where),
                            mf_error_message());
        }
    }
    if (resolved)
        MF_CALL(mf_dict_set_word(resolved, "fluid", sim->fluid[*fluid].name));
    return 0;
}

/* Fill the box [mn, mx] with particles of `kind` on the lattice; velocity
 * from the inlet profile (in != NULL) or v0; returns how many. */
static int fill_box(mf_sim *sim, mf_emitters *em, int kind, const double *mn, const double *mx,
                    const mf_inlet *in, const double v0[3], size_t *count)
{
    const double l0 = sim->l0;
    long hi[3] = {1, 1, 1};
    for (int a = 0; a < sim->dim; a++)
        hi[a] = mf_lattice_count(mn[a], mx[a], l0);
    size_t before = sim->p->n;
    for (long k = 0; k < hi[2]; k++)
        for (long j = 0; j < hi[1]; j++)
            for (long i = 0; i < hi[0]; i++) {
                double x[3] = {mn[0] + (i + 0.5) * l0, mn[1] + (j + 0.5) * l0,
                               sim->dim == 3 ? mn[2] + (k + 0.5) * l0 : 0.0};
                double u[3] = {v0[0], v0[1], v0[2]};
                if (in)
                    mf_inlet_velocity(in, sim->dim, x, u);
                size_t idx = sim->p->n;
                MF_CALL(mf_particles_add(sim->p, kind, x, u, NULL));
                if (in) {
                    set_scalars(&in->scalars, sim->p, idx);
                    if (em->fluid_field >= 0)
                        mf_particles_fi(sim->p, em->fluid_field)[idx] = in->fluid;
                }
            }
    *count = sim->p->n - before;
    return 0;
}

static int add_inlet(mf_sim *sim, mf_emitters *em, const char *name, const mf_dict *d,
                     mf_dict *resolved)
{
    char where[512];
    inlet_settings s;
    mf_dict *r = resolved ? mf_dict_set_subdict(resolved, name) : NULL;
    MF_CALL(mf_params_apply(inlet_params, sizeof inlet_params / sizeof inlet_params[0], d, NULL,
                            &s, r));
    MF_CALL(mf_lattice_check_box("inlet", name, d, s.min, s.max, sim->dim));
    mf_inlet *in = &em->inlet[em->ninlets];
    memset(in, 0, sizeof *in);
    snprintf(in->name, sizeof in->name, "%s", name);
    memcpy(in->min, s.min, sizeof in->min);
    memcpy(in->max, s.max, sizeof in->max);
    memcpy(in->velocity, s.velocity, sizeof in->velocity);
    if (sim->dim == 2)
        in->velocity[2] = 0;
    if (axis_of(in->velocity, sim->dim, &in->axis, &in->sign) != 0)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: inlet '%s': velocity (%g %g %g) must be non-zero and along a "
                        "coordinate axis (the inflow direction)",
                        mf_loc_str(mf_dict_find(d, "velocity")->loc, where, sizeof where), name,
                        s.velocity[0], s.velocity[1], s.velocity[2]);
    in->profile = strcmp(s.profile, "parabolic") == 0 ? MF_INLET_PARABOLIC : MF_INLET_UNIFORM;
    MF_CALL(fluid_index(sim, d, s.fluid, &in->fluid, r));
    MF_CALL(read_scalars(sim, s.scalars, &in->scalars,
                         r ? mf_dict_set_subdict(r, "scalars") : NULL));
    size_t count = 0;
    const double zero[3] = {0, 0, 0};
    MF_CALL(fill_box(sim, em, MF_INLET, in->min, in->max, in, zero, &count));
    if (count == 0)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: inlet '%s' is thinner than one particle spacing (%g): no point "
                        "placed",
                        mf_loc_str(d->loc, where, sizeof where), name, sim->l0);
    em->ninlets++;
    return 0;
}

static int add_outlet(mf_sim *sim, mf_emitters *em, const char *name, const mf_dict *d,
                      mf_dict *resolved)
{
    char where[512];
    outlet_settings s;
    mf_dict *r = resolved ? mf_dict_set_subdict(resolved, name) : NULL;
    MF_CALL(mf_params_apply(outlet_params, sizeof outlet_params / sizeof outlet_params[0], d,
                            NULL, &s, r));
    MF_CALL(mf_lattice_check_box("outlet", name, d, s.min, s.max, sim->dim));
    mf_outlet *out = &em->outlet[em->noutlets];
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "%s", name);
    memcpy(out->min, s.min, sizeof out->min);
    memcpy(out->max, s.max, sizeof out->max);
    memcpy(out->velocity, s.velocity, sizeof out->velocity);
    if (sim->dim == 2) {
        s.direction[2] = 0;
        out->velocity[2] = 0;
    }
    if (axis_of(s.direction, sim->dim, &out->axis, &out->sign) != 0)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: outlet '%s': direction (%g %g %g) must be non-zero and along a "
                        "coordinate axis",
                        mf_loc_str(mf_dict_find(d, "direction")->loc, where, sizeof where),
                        name, s.direction[0], s.direction[1], s.direction[2]);
    size_t count = 0;
    MF_CALL(fill_box(sim, em, MF_OUTLET, out->min, out->max, NULL, out->velocity, &count));
    if (count == 0)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: outlet '%s' is thinner than one particle spacing (%g): no point "
                        "placed",
                        mf_loc_str(d->loc, where, sizeof where), name, sim->l0);
    em->noutlets++;
    return 0;
}

/* Two unit vectors perpendicular to the unit vector d (and to each other). */
static void perpendiculars(const double d[3], double a[3], double b[3])
{
    double t[3] = {0, 0, 0};
    int smallest = 0;
    for (int k = 1; k < 3; k++)
        if (fabs(d[k]) < fabs(d[smallest]))
            smallest = k;
    t[smallest] = 1;
    /* a = t x d normalised, b = d x a */
    a[0] = t[1] * d[2] - t[2] * d[1];
    a[1] = t[2] * d[0] - t[0] * d[2];
    a[2] = t[0] * d[1] - t[1] * d[0];
    double len = norm3(a);
    for (int k = 0; k < 3; k++)
        a[k] /= len;
    b[0] = d[1] * a[2] - d[2] * a[1];
    b[1] = d[2] * a[0] - d[0] * a[2];
    b[2] = d[0] * a[1] - d[1] * a[0];
}

static int add_nozzle(mf_sim *sim, mf_emitters *em, const char *name, const mf_dict *d,
                      mf_dict *resolved)
{
    char where[512];
    nozzle_settings s;
    mf_dict *r = resolved ? mf_dict_set_subdict(resolved, name) : NULL;
    MF_CALL(mf_params_apply(nozzle_params, sizeof nozzle_params / sizeof nozzle_params[0], d,
                            NULL, &s, r));
    mf_nozzle *nz = &em->nozzle[em->nnozzles];
    memset(nz, 0, sizeof *nz);
    snprintf(nz->name, sizeof nz->name, "%s", name);
    memcpy(nz->centre, s.centre, sizeof nz->centre);
    memcpy(nz->velocity, s.velocity, sizeof nz->velocity);
    if (sim->dim == 2) {
        nz->centre[2] = 0;
        nz->velocity[2] = 0;
    }
    nz->speed = norm3(nz->velocity);
    if (!(nz->speed > 0))
        return MF_ERROR(MF_ERR_INPUT, "%s: nozzle '%s': velocity must not be zero",
                        mf_loc_str(mf_dict_find(d, "velocity")->loc, where, sizeof where), name);
    for (int a = 0; a < 3; a++)
        nz->dir[a] = nz->velocity[a] / nz->speed;
    if (!(s.end > s.start))
        return MF_ERROR(MF_ERR_INPUT, "%s: nozzle '%s': end (%g) must be after start (%g)",
                        mf_loc_str(d->loc, where, sizeof where), name, s.end, s.start);
    nz->diameter = s.diameter;
    nz->start = s.start;
    nz->end = s.end;
    MF_CALL(fluid_index(sim, d, s.fluid, &nz->fluid, r));
    MF_CALL(read_scalars(sim, s.scalars, &nz->scalars,
                         r ? mf_dict_set_subdict(r, "scalars") : NULL));

    /* Lattice points across the opening: a line in 2-D, a disc in 3-D. */
    const double l0 = sim->l0;
    long m = lround(s.diameter / l0);
    if (m < 1)
        m = 1;
    size_t cap = sim->dim == 2 ? (size_t)m : (size_t)(m * m);
    nz->offset = malloc(3 * cap * sizeof *nz->offset);
    if (!nz->offset)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for nozzle '%s'", name);
    em->nnozzles++; /* counted from here: on an error below, the cleanup frees its offsets */
    double a[3], b[3];
    if (sim->dim == 2) {
        a[0] = -nz->dir[1];
        a[1] = nz->dir[0];
        a[2] = 0;
        b[0] = b[1] = b[2] = 0;
    } else {
        perpendiculars(nz->dir, a, b);
    }
    const double half = 0.5 * (double)(m - 1);
    for (long i = 0; i < m; i++)
        for (long j = 0; j < (sim->dim == 3 ? m : 1); j++) {
            double u = (i - half) * l0, v = sim->dim == 3 ? (j - half) * l0 : 0.0;
            if (sim->dim == 3 && u * u + v * v > 0.25 * s.diameter * s.diameter + 1e-9 * l0 * l0 &&
                m > 1)
                continue;
            double *o = &nz->offset[3 * nz->nper_layer++];
            for (int k = 0; k < 3; k++)
                o[k] = u * a[k] + v * b[k];
        }
    /* Layers of nper_layer particles of volume l0^dim each. */
    const double layer_volume = (double)nz->nper_layer * pow(l0, sim->dim);
    const double natural_rate = nz->speed * (double)nz->nper_layer * pow(l0, sim->dim - 1);
    nz->rate = s.rate > 0 ? s.rate : natural_rate;
    nz->period = layer_volume / nz->rate;
    if (nz->speed * nz->period < 0.5 * l0)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: nozzle '%s': rate %g puts its layers %.3g l0 apart at speed %g: "
                        "raise the velocity or the diameter (at most %g at this speed)",
                        mf_loc_str(d->loc, where, sizeof where), name, nz->rate,
                        nz->speed * nz->period / l0, nz->speed, 2 * natural_rate);
    if (r)
        MF_CALL(mf_dict_set_number(r, "rate", nz->rate));
    return 0;
}

typedef int (*add_fn)(mf_sim *, mf_emitters *, const char *, const mf_dict *, mf_dict *);

static int for_each(mf_sim *sim, mf_emitters *em, const mf_dict *group, const char *what,
                    add_fn fn, mf_dict *resolved)
{
    char where[512];
    for (size_t k = 0; group && k < group->n; k++) {
        mf_entry *e = group->entries[k];
        if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT)
            return MF_ERROR(MF_ERR_INPUT, "%s: %s '%s' must be a sub-dictionary { ... }",
                            mf_loc_str(e->loc, where, sizeof where), what, e->key);
        e->used = true;
        MF_CALL(fn(sim, em, e->key, e->items[0]->dict, resolved));
    }
    return 0;
}

int mf_emitters_create(mf_sim *sim, const mf_dict *inlets, const mf_dict *outlets,
                       const mf_dict *nozzles, mf_dict *resolved_inlets,
                       mf_dict *resolved_outlets, mf_dict *resolved_nozzles, mf_emitters **out)
{
    *out = NULL;
    size_t ni = inlets ? inlets->n : 0, no = outlets ? outlets->n : 0,
           nn = nozzles ? nozzles->n : 0;
    if (ni + no + nn == 0)
        return 0;
    mf_emitters *em = calloc(1, sizeof *em);
    if (!em)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    *out = em; /* freeable from here on, even if parsing fails */
    em->inlet = calloc(ni ? ni : 1, sizeof *em->inlet);
    em->outlet = calloc(no ? no : 1, sizeof *em->outlet);
    em->nozzle = calloc(nn ? nn : 1, sizeof *em->nozzle);
    if (!em->inlet || !em->outlet || !em->nozzle)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    em->fluid_field = mf_particles_field_index(sim->p, "FluidId");
    MF_CALL(for_each(sim, em, inlets, "inlet", add_inlet, resolved_inlets));
    MF_CALL(for_each(sim, em, outlets, "outlet", add_outlet, resolved_outlets));
    MF_CALL(for_each(sim, em, nozzles, "emitter", add_nozzle, resolved_nozzles));
    return 0;
}

void mf_emitters_destroy(mf_emitters *em)
{
    if (!em)
        return;
    for (size_t k = 0; k < em->nnozzles; k++)
        free(em->nozzle[k].offset);
    free(em->inlet);
    free(em->outlet);
    free(em->nozzle);
    free(em->flag);
    free(em);
}

/* ======================================================================
 * One step
 * ==================================================================== */

void mf_inlet_velocity(const mf_inlet *in, int dim, const double x[3], double u[3])
{
    double f = 1.0;
    if (in->profile == MF_INLET_PARABOLIC) {
        /* 6 eta (1 - eta) across each transverse axis: mean 1, zero at the
         * edges of the box. */
        for (int a = 0; a < dim; a++) {
            if (a == in->axis)
                continue;
            double eta = (x[a] - in->min[a]) / (in->max[a] - in->min[a]);
            eta = eta < 0 ? 0 : (eta > 1 ? 1 : eta);
            f *= 6.0 * eta * (1.0 - eta);
        }
    }
    for (int a = 0; a < 3; a++)
        u[a] = f * in->velocity[a];
}

static bool in_box(const double *mn, const double *mx, int dim, const double x[3], double margin)
{
    for (int a = 0; a < dim; a++)
        if (x[a] < mn[a] - margin || x[a] > mx[a] + margin)
            return false;
    return true;
}

int mf_emitters_inlet_at(const mf_emitters *em, int dim, const double x[3], double margin)
{
    for (size_t k = 0; em && k < em->ninlets; k++)
        if (in_box(em->inlet[k].min, em->inlet[k].max, dim, x, margin))
            return (int)k;
    return -1;
}

int mf_emitters_outlet_at(const mf_emitters *em, int dim, const double x[3], double margin)
{
    for (size_t k = 0; em && k < em->noutlets; k++)
        if (in_box(em->outlet[k].min, em->outlet[k].max, dim, x, margin))
            return (int)k;
    return -1;
}

/* Signed distance of x past the downstream face of an inlet (> 0: inside
 * the domain), and past the upstream face of an outlet (> 0: in the outlet). */
static double past_inlet_face(const mf_inlet *in, const double x[3])
{
    double face = in->sign > 0 ? in->max[in->axis] : in->min[in->axis];
    return in->sign * (x[in->axis] - face);
}

static double past_outlet_face(const mf_outlet *out, const double x[3])
{
    double face = out->sign > 0 ? out->min[out->axis] : out->max[out->axis];
    return out->sign * (x[out->axis] - face);
}

static double outlet_length(const mf_outlet *out)
{
    return out->max[out->axis] - out->min[out->axis];
}

/* The inlet an inlet particle belongs to: the box across the flow, and
 * along it from one spacing upstream to well past the face (a moving
 * particle is at most a step beyond it). */
static int owning_inlet(const mf_emitters *em, int dim, const double x[3], double l0)
{
    for (size_t k = 0; k < em->ninlets; k++) {
        const mf_inlet *in = &em->inlet[k];
        bool ok = true;
        for (int a = 0; a < dim && ok; a++) {
            double lo = in->min[a] - 0.5 * l0, hi = in->max[a] + 0.5 * l0;
            if (a == in->axis) {
                lo -= l0 + (in->max[a] - in->min[a]);
                hi += l0 + (in->max[a] - in->min[a]);
            }
            ok = x[a] >= lo && x[a] <= hi;
        }
        if (ok)
            return (int)k;
    }
    return -1;
}

void mf_emitters_set_inlet_values(const mf_emitters *em, mf_sim *sim)
{
    mf_particles *p = sim->p;
    for (size_t i = 0; em && em->ninlets && i < p->n_owned; i++) {
        if (p->kind[i] != MF_INLET)
            continue;
        int k = owning_inlet(em, sim->dim, &p->pos[3 * i], sim->l0);
        if (k < 0)
            continue;
        mf_inlet_velocity(&em->inlet[k], sim->dim, &p->pos[3 * i], &p->vel[3 * i]);
        set_scalars(&em->inlet[k].scalars, p, i);
    }
}

static int grow_flags(mf_emitters *em, size_t n)
{
    if (n <= em->cap_flag)
        return 0;
    size_t cap = n + n / 4 + 64;
    if (mf_resize(&em->flag, cap, 1))
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particle flags", n);
    em->cap_flag = cap;
    return 0;
}

/* Moving buffers: inlet particles advance, cross into the domain as fluid
 * and are replaced one buffer length upstream. */
static int move_inlets(mf_emitters *em, mf_sim *sim, double dt, size_t n0, size_t *added)
{
    mf_particles *p = sim->p;
    for (size_t i = 0; i < n0; i++) {
        if (p->kind[i] != MF_INLET)
            continue;
        int k = owning_inlet(em, sim->dim, &p->pos[3 * i], sim->l0);
        if (k < 0)
            continue;
        const mf_inlet *in = &em->inlet[k];
        double *x = &p->pos[3 * i], *u = &p->vel[3 * i];
        mf_inlet_velocity(in, sim->dim, x, u);
        for (int a = 0; a < sim->dim; a++)
            x[a] += dt * u[a];
        set_scalars(&in->scalars, p, i);
        double past = past_inlet_face(in, x);
        if (past <= 0)
            continue;
        p->kind[i] = MF_FLUID;
        if (em->fluid_field >= 0)
            mf_particles_fi(p, em->fluid_field)[i] = in->fluid;
        double y[3] = {x[0], x[1], x[2]}, v[3];
        y[in->axis] -= in->sign * (in->max[in->axis] - in->min[in->axis]);
        mf_inlet_velocity(in, sim->dim, y, v);
        size_t idx = p->n;
        MF_CALL(mf_particles_add(p, MF_INLET, y, v, NULL));
        set_scalars(&in->scalars, p, idx);
        /* p->pos may have moved: x and u are not used past this point. */
        (*added)++;
    }
    return 0;
}

/* The outlet whose cross-section holds x (with l0/2 to spare) and that x
 * is past the upstream face of (by any amount, beyond the far face too:
 * whatever went through an outlet has left). -1 if none. */
static int outlet_passed(const mf_emitters *em, int dim, const double x[3], double l0)
{
    for (size_t k = 0; k < em->noutlets; k++) {
        const mf_outlet *out = &em->outlet[k];
        bool across = true;
        for (int a = 0; a < dim && across; a++)
            if (a != out->axis)
                across = x[a] >= out->min[a] - 0.5 * l0 && x[a] <= out->max[a] + 0.5 * l0;
        if (across && past_outlet_face(out, x) > 0)
            return (int)k;
    }
    return -1;
}

/* Moving buffers: fluid that crosses an outlet face becomes an outlet
 * particle; outlet particles move on with their velocity and leave at the
 * far face. */
static void move_outlets(mf_emitters *em, mf_sim *sim, double dt, size_t n0)
{
    mf_particles *p = sim->p;
    for (size_t i = 0; i < n0; i++) {
        if (p->kind[i] != MF_FLUID && p->kind[i] != MF_OUTLET)
            continue;
        double *x = &p->pos[3 * i];
        int k = outlet_passed(em, sim->dim, x, sim->l0);
        if (k < 0)
            continue;
        p->kind[i] = MF_OUTLET;
        for (int a = 0; a < sim->dim; a++)
            x[a] += dt * p->vel[3 * i + a];
        if (past_outlet_face(&em->outlet[k], x) > outlet_length(&em->outlet[k]))
            em->flag[i] = 1;
    }
}

/* Fixed buffers: fluid points inside (or beyond) an outlet box have left
 * the domain. */
static void drain_outlets(mf_emitters *em, mf_sim *sim, size_t n0)
{
    mf_particles *p = sim->p;
    for (size_t i = 0; i < n0; i++)
        if (p->kind[i] == MF_FLUID && outlet_passed(em, sim->dim, &p->pos[3 * i], sim->l0) >= 0)
            em->flag[i] = 1;
}

/* Layers emitted before time t: layer k leaves at start + k period. */
static double layers_before(const mf_nozzle *nz, double t)
{
    if (t <= nz->start)
        return 0;
    double total = ceil((nz->end - nz->start) / nz->period);
    double k = ceil((t - nz->start) / nz->period);
    return k < total ? k : total;
}

static int run_nozzle(mf_emitters *em, const mf_nozzle *nz, mf_sim *sim, double dt,
                      size_t *added)
{
    const double t0 = sim->time, t1 = sim->time + dt;
    double k0 = layers_before(nz, t0), k1 = layers_before(nz, t1);
    if (k1 - k0 > 1e5)
        return MF_ERROR(MF_ERR_INPUT, "nozzle '%s' would add %.0f layers in one step of %g s",
                        nz->name, k1 - k0, dt);
    mf_particles *p = sim->p;
    for (double k = k0; k < k1; k += 1) {
        /* Behind the opening by the distance it travels before this step
         * ends: the solver's step carries it out. */
        double tk = nz->start + k * nz->period;
        double back = nz->speed * (tk - t0);
        for (size_t m = 0; m < nz->nper_layer; m++) {
            double x[3];
            for (int a = 0; a < 3; a++)
                x[a] = nz->centre[a] + nz->offset[3 * m + a] - back * nz->dir[a];
            size_t idx = p->n;
            MF_CALL(mf_particles_add(p, MF_FLUID, x, nz->velocity, NULL));
            set_scalars(&nz->scalars, p, idx);
            if (em->fluid_field >= 0)
                mf_particles_fi(p, em->fluid_field)[idx] = nz->fluid;
            (*added)++;
        }
    }
    return 0;
}

int mf_emitters_apply(mf_emitters *em, mf_sim *sim, double dt, size_t *added, size_t *removed)
{
    *added = 0;
    *removed = 0;
    if (!em)
        return 0;
    mf_particles *p = sim->p;
    const size_t n0 = p->n;
    MF_CALL(grow_flags(em, n0));
    memset(em->flag, 0, n0);
    if (em->fixed_buffers) {
        mf_emitters_set_inlet_values(em, sim);
        drain_outlets(em, sim, n0);
    } else {
        MF_CALL(move_inlets(em, sim, dt, n0, added));
        move_outlets(em, sim, dt, n0);
    }
    for (size_t k = 0; k < em->nnozzles; k++)
        MF_CALL(run_nozzle(em, &em->nozzle[k], sim, dt, added));
    /* New particles are appended after n0 and never flagged. */
    MF_CALL(grow_flags(em, p->n));
    memset(em->flag + n0, 0, p->n - n0);
    MF_CALL(mf_particles_remove(p, em->flag, removed));
    return 0;
}

double mf_emitters_fluid_kinetic_energy(const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    const int ff = mf_particles_field_index(p, "FluidId");
    const double vol = pow(sim->l0, sim->dim);
    double ke = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        int f = ff >= 0 ? mf_particles_fi(p, ff)[i] : 0;
        const double *v = &p->vel[3 * i];
        ke += 0.5 * sim->fluid[f].rho * vol * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    }
    return ke;
}

#define NP(t) (sizeof(t) / sizeof((t)[0]))
const mf_param_section mf_emitter_sections[] = {
    {"geometry: inlets/<name>", "a buffer of points entering at a given velocity", inlet_params,
     NP(inlet_params)},
    {"geometry: outlets/<name>", "a buffer where fluid leaves and is removed", outlet_params,
     NP(outlet_params)},
    {"geometry: emitters/<name>, type nozzle", "fluid added across an opening for a time window",
     nozzle_params, NP(nozzle_params)},
    {"geometry: scalars/<name>, type uniform", "a transported scalar's initial value (also `NAME v;`)",
     uniform_params, NP(uniform_params)},
    {"geometry: scalars/<name>, type gaussian", "b + a exp(-d^2 / (2 s^2))", gaussian_params,
     NP(gaussian_params)},
    {"geometry: scalars/<name>, type step", "one value behind a plane, another ahead",
     step_params, NP(step_params)},
    {"geometry: scalars/<name>, type box", "one value inside a box, another outside", box_params,
     NP(box_params)},
};
const size_t mf_emitter_nsections = NP(mf_emitter_sections);
