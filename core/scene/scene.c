/* scene.c: fluid blocks and wall boxes on the particle lattice. */
#include "mf_scene.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_emitter.h"
#include "mf_error.h"
#include "mf_params.h"
#include "mf_trimesh.h"
#include "scene_internal.h"
#include "scene_lattice.h"

/* ---- fluids -------------------------------------------------------------- */
typedef struct fluid_settings {
    double rho, nu, sigma;
} fluid_settings;

static const mf_param fluid_params[] = {
    {"rho", MF_PARAM_SCALAR, NULL, 1e-3, 1e6, NULL, offsetof(fluid_settings, rho),
     "density, kg/m^3. One fluid's density only scales the pressure; between fluids the ratio "
     "conditions the pressure equation: from hydrogen (0.09) past mercury (13,600), with a "
     "margin"},
    {"nu", MF_PARAM_SCALAR, NULL, 0, 1e4, NULL, offsetof(fluid_settings, nu),
     "kinematic viscosity, m^2/s (water 1e-6, honey 1e-2); the explicit term limits dt to "
     "maxDi l0^2 / nu, the implicit one (viscosity implicit) does not"},
    {"sigma", MF_PARAM_SCALAR, "0", 0, 100, NULL, offsetof(fluid_settings, sigma),
     "surface tension coefficient, N/m (water 0.072, mercury 0.49); the capillary step "
     "sqrt(rho l0^3 / sigma) shrinks as sigma grows"},
};

int mf_scene_read_fluids(const mf_dict *fluids, mf_sim *sim)
{
    char where[512];
    sim->nfluids = 0;
    for (size_t k = 0; k < fluids->n; k++) {
        const mf_entry *e = fluids->entries[k];
        if (strcmp(e->key, "FoamFile") == 0)
            continue;
        if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT)
            return MF_ERROR(MF_ERR_INPUT,
                            "%s: '%s' must be a fluid sub-dictionary { rho ...; nu ...; }",
                            mf_loc_str(e->loc, where, sizeof where), e->key);
        if (sim->nfluids == MF_MAX_FLUIDS)
            return MF_ERROR(MF_ERR_INPUT, "%s: at most %d fluids",
                            mf_loc_str(e->loc, where, sizeof where), MF_MAX_FLUIDS);
        if (strlen(e->key) >= sizeof sim->fluid[0].name)
            return MF_ERROR(MF_ERR_INPUT, "%s: fluid name '%s' is too long",
                            mf_loc_str(e->loc, where, sizeof where), e->key);
        fluid_settings s;
        MF_CALL(mf_params_apply(fluid_params, 3, e->items[0]->dict, NULL, &s, NULL));
        mf_fluid *f = &sim->fluid[sim->nfluids++];
        snprintf(f->name, sizeof f->name, "%s", e->key);
        f->rho = s.rho;
        f->nu = s.nu;
        f->sigma = s.sigma;
    }
    if (sim->nfluids == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: no fluid defined (add e.g. water { rho 1000; nu 1e-6; })",
                        mf_loc_str(fluids->loc, where, sizeof where));
    return 0;
}

int mf_scene_fluid_index(const mf_sim *sim, const char *name, int *index)
{
    const char *names[MF_MAX_FLUIDS];
    char list[1024] = "";
    for (int k = 0; k < sim->nfluids; k++) {
        if (strcmp(sim->fluid[k].name, name) == 0) {
            *index = k;
            return 0;
        }
        names[k] = sim->fluid[k].name;
        strncat(list, k ? ", " : "", sizeof list - strlen(list) - 1);
        strncat(list, names[k], sizeof list - strlen(list) - 1);
    }
    const char *hint = mf_did_you_mean(name, names, (size_t)sim->nfluids);
    return MF_ERROR(MF_ERR_INPUT, "unknown fluid '%s'%s%s%s; constant/fluids defines: %s", name,
                    hint ? " (did you mean '" : "", hint ? hint : "", hint ? "'?)" : "", list);
}

/* ---- geometry ------------------------------------------------------------ */
typedef struct geometry_settings {
    long dimension;
    double spacing;
    const mf_dict *fluid_blocks, *walls;
    const mf_dict *inlets, *outlets, *emitters; /* mf_emitter.h */
    const mf_dict *obstacles;                   /* mf_trimesh.h */
} geometry_settings;

static const mf_param geometry_params[] = {
    {"dimension", MF_PARAM_INT, NULL, 2, 3, NULL, offsetof(geometry_settings, dimension),
     "2 or 3"},
    {"particleSpacing", MF_PARAM_SCALAR, NULL, 1e-9, 1e6, NULL,
     offsetof(geometry_settings, spacing),
     "l0, the initial particle spacing, m (-l0 overrides it, in the same range). The numerics "
     "are scale-free; what bounds l0 is the count it makes, checked against maxMemory before "
     "any particle is made"},
    {"fluidBlocks", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL,
     offsetof(geometry_settings, fluid_blocks), "named blocks of fluid particles"},
    {"walls", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(geometry_settings, walls),
     "named walls (layers of fixed particles)"},
    {"inlets", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(geometry_settings, inlets),
     "named inlets: buffers of points with a given velocity (mf_emitter.h)"},
    {"outlets", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(geometry_settings, outlets),
     "named outlets: buffers where fluid leaves and is removed"},
    {"emitters", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(geometry_settings, emitters),
     "named emitters (type nozzle): add fluid at a velocity and rate for a time window"},
    {"obstacles", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(geometry_settings, obstacles),
     "named solid bodies in the fluid: type box, cylinder, sphere or mesh (a polygon file)"},
};
static const char *const geometry_extra[] = {"FoamFile", NULL};
#define NP(t) (sizeof(t) / sizeof((t)[0]))

static const char *const block_types[] = {"box", "mesh", NULL}; /* mesh: mf_trimesh.h */

/* Fluid blocks: a box (min, max) or a sphere, a disk in 2-D (centre,
 * radius; for droplets). */
static const char *const fluid_block_types[] = {"box", "sphere", "mesh", NULL};

typedef struct block_settings {
    const char *type;
    double min[3], max[3], velocity[3];
    const char *fluid;
    const mf_dict *scalars;
    double centre[3], radius;
    bool overwrite;
    double wave_amplitude, wave_length;
} block_settings;
#define BLOCK_NPARAMS 11

static const mf_param block_params[BLOCK_NPARAMS] = {
    {"type", MF_PARAM_WORD, "box", MF_NO_RANGE, fluid_block_types,
     offsetof(block_settings, type), "shape of the block: box (min, max) or sphere (centre, "
     "radius; a disk in 2-D)"},
    {"min", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, offsetof(block_settings, min),
     "lower corner, m (box; required)"},
    {"max", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, offsetof(block_settings, max),
     "upper corner, m (box; required)"},
    {"velocity", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL,
     offsetof(block_settings, velocity), "initial velocity, m/s"},
    {"fluid", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(block_settings, fluid),
     "name of a fluid in constant/fluids"},
    {"scalars", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(block_settings, scalars),
     "initial transported scalars: { dye { type gaussian; ... } tracer 0; } (mf_emitter.h)"},
    {"centre", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, offsetof(block_settings, centre),
     "centre, m (sphere)"},
    {"radius", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(block_settings, radius),
     "radius, m (sphere; required)"},
    {"overwrite", MF_PARAM_BOOL, "no", MF_NO_RANGE, NULL, offsetof(block_settings, overwrite),
     "remove the fluid particles of earlier blocks inside this one first (a droplet in "
     "another fluid; as setFields regions overwrite)"},
    {"topAmplitude", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL,
     offsetof(block_settings, wave_amplitude),
     "box: the top face is y = max_y + topAmplitude sin(2 pi (x - min_x) / topWavelength), m "
     "(a perturbed interface: Rayleigh-Taylor)"},
    {"topWavelength", MF_PARAM_SCALAR, "1", 1e-12, 1e12, NULL,
     offsetof(block_settings, wave_length), "wavelength of the top face's wave, m"},
};

typedef struct wall_settings {
    const char *type;
    double min[3], max[3];
    long wall_layers, dummy_layers;
    double velocity[3];
    const mf_dict *motion;
} wall_settings;

static const mf_param wall_params[] = {
    {"type", MF_PARAM_WORD, "box", MF_NO_RANGE, block_types, offsetof(wall_settings, type),
     "shape enclosed by the wall"},
    {"min", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(wall_settings, min),
     "lower corner of the enclosed region, m"},
    {"max", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(wall_settings, max),
     "upper corner of the enclosed region, m"},
    {"wallLayers", MF_PARAM_INT, "1", 1, 3, NULL, offsetof(wall_settings, wall_layers),
     "layers of wall particles (in the pressure equation)"},
    {"dummyLayers", MF_PARAM_INT, "2", 0, 4, NULL, offsetof(wall_settings, dummy_layers),
     "outer layers of dummy particles (number density only)"},
    {"velocity", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, offsetof(wall_settings, velocity),
     "velocity of the wall's surface along itself, m/s (a sliding lid: the box stays)"},
    {"motion", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(wall_settings, motion),
     "prescribed rigid motion of the box (see geometry: <wall or obstacle>/motion)"},
};
static const char *const wall_extra[] = {"open", NULL};

/* A box needs min and max, a sphere its radius. */
static int check_block_shape(const char *name, const mf_dict *d, bool sphere,
                             const block_settings *s, int dim)
{
    char where[512];
    if (sphere) {
        if (!(s->radius > 0))
            return MF_ERROR(MF_ERR_INPUT,
                            "%s: fluid block '%s': type sphere needs a radius > 0 (and a centre)",
                            mf_loc_str(d->loc, where, sizeof where), name);
        return 0;
    }
    if (!mf_dict_find(d, "min") || !mf_dict_find(d, "max"))
        return MF_ERROR(MF_ERR_INPUT, "%s: fluid block '%s': type box needs 'min' and 'max'",
                        mf_loc_str(d->loc, where, sizeof where), name);
    return mf_lattice_check_box("fluid block", name, d, s->min, s->max, dim);
}

/* The height of a box block's top face at x (a wave when topAmplitude != 0). */
static double box_top(const block_settings *s, const double x[3])
{
    return s->max[1] + s->wave_amplitude * sin(2 * M_PI * (x[0] - s->min[0]) / s->wave_length);
}

static bool inside_sphere(const double x[3], const double c[3], double r, int dim)
{
    double d2 = 0;
    for (int a = 0; a < dim; a++)
        d2 += (x[a] - c[a]) * (x[a] - c[a]);
    return d2 < r * r;
}

/* overwrite: the fluid particles already placed inside the block's shape go
 * (the test that places the block's own particles, so that blocks on the
 * same lattice fit without gap or overlap). */
static int remove_fluid_inside(mf_sim *sim, const block_settings *s, bool sphere)
{
    mf_particles *p = sim->p;
    uint8_t *gone = calloc(p->n ? p->n : 1, 1);
    if (!gone)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    for (size_t i = 0; i < p->n; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *x = &p->pos[3 * i];
        bool in = true;
        if (sphere) {
            in = inside_sphere(x, s->centre, s->radius, sim->dim);
        } else {
            for (int a = 0; a < sim->dim; a++)
                in = in && x[a] > s->min[a] && (a == 1 ? x[a] < box_top(s, x) : x[a] < s->max[a]);
        }
        gone[i] = in;
    }
    size_t removed = 0;
    int rc = mf_particles_remove(p, gone, &removed);
    free(gone);
    return rc;
}

static int add_fluid_block(mf_sim *sim, const char *name, const mf_dict *d, int fluid_field,
                           mf_dict *resolved)
{
    block_settings s;
    mf_dict *out = resolved ? mf_dict_set_subdict(resolved, name) : NULL;
    MF_CALL(mf_params_apply(block_params, BLOCK_NPARAMS, d, NULL, &s, out));
    const bool sphere = strcmp(s.type, "sphere") == 0;
    MF_CALL(check_block_shape(name, d, sphere, &s, sim->dim));
    int fid = 0;
    if (mf_scene_fluid_index(sim, s.fluid, &fid) != 0) {
        char where[512];
        return MF_ERROR(MF_ERR_INPUT, "%s: fluid block '%s': %s",
                        mf_loc_str(mf_dict_find(d, "fluid")->loc, where, sizeof where), name,
                        mf_error_message());
    }
    const double l0 = sim->l0;
    long lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    if (sphere) { /* the lattice centre + (i + 1/2) l0, symmetric about the centre */
        long m = (long)ceil(s.radius / l0);
        for (int a = 0; a < sim->dim; a++) {
            s.min[a] = s.centre[a] - (double)m * l0;
            hi[a] = 2 * m;
        }
    }
    for (int a = 0; a < sim->dim && !sphere; a++)
        hi[a] = mf_lattice_count(s.min[a], s.max[a] + (a == 1 ? fabs(s.wave_amplitude) : 0), l0);
    if (s.overwrite)
        MF_CALL(remove_fluid_inside(sim, &s, sphere));
    size_t before = sim->p->n;
    for (long k = lo[2]; k < hi[2]; k++)
        for (long j = lo[1]; j < hi[1]; j++)
            for (long i = lo[0]; i < hi[0]; i++) {
                double x[3] = {s.min[0] + (i + 0.5) * l0, s.min[1] + (j + 0.5) * l0,
                               sim->dim == 3 ? s.min[2] + (k + 0.5) * l0 : 0.0};
                if (sphere && !inside_sphere(x, s.centre, s.radius, sim->dim))
                    continue;
                if (!sphere && s.wave_amplitude != 0 && !(x[1] < box_top(&s, x)))
                    continue;
                MF_CALL(mf_particles_add(sim->p, MF_FLUID, x, s.velocity, NULL));
            }
    if (fluid_field >= 0) {
        int32_t *fid_arr = mf_particles_fi(sim->p, fluid_field);
        for (size_t i = before; i < sim->p->n; i++)
            fid_arr[i] = fid;
    }
    if (s.scalars)
        MF_CALL(mf_scene_block_scalars(sim, s.scalars, before, sim->p->n,
                                       out ? mf_dict_set_subdict(out, "scalars") : NULL));
    char where[512];
    if (sim->p->n == before)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: fluid block '%s' is smaller than one particle spacing (%g): no "
                        "particle placed",
                        mf_loc_str(d->loc, where, sizeof where), name, l0);
    mf_loc_str(d->loc, where, sizeof where);
    if (sphere) {
        mf_scene_warn_radius(sim, where, "fluid block", name, s.radius, sim->p->n - before);
    } else if (s.wave_amplitude == 0) {
        double want[3];
        for (int a = 0; a < 3; a++)
            want[a] = s.max[a] - s.min[a];
        mf_scene_warn_extent(sim, where, "fluid block", name, want, before, MF_FLUID);
    }
    return 0;
}

static int parse_open_faces(const mf_dict *d, const char *name, bool open[3][2])
{
    static const char *const faces[] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
    memset(open, 0, 6 * sizeof(bool));
    mf_entry *e = mf_dict_find(d, "open");
    if (!e)
        return 0;
    e->used = true;
    char where[512];
    if (e->n != 1 || e->items[0]->kind != MF_VAL_LIST)
        return MF_ERROR(MF_ERR_INPUT, "%s: wall '%s': 'open' takes a list of faces, e.g. (ymax)",
                        mf_loc_str(e->loc, where, sizeof where), name);
    const mf_value *list = e->items[0];
    for (size_t k = 0; k < list->n; k++) {
        const mf_value *v = list->items[k];
        int f = -1;
        for (int q = 0; q < 6 && v->kind == MF_VAL_WORD; q++)
            if (strcmp(v->text, faces[q]) == 0)
                f = q;
        if (f < 0) {
            const char *hint = v->kind == MF_VAL_WORD ? mf_did_you_mean(v->text, faces, 6) : NULL;
            return MF_ERROR(MF_ERR_INPUT,
                            "%s: wall '%s': unknown face in 'open'%s%s%s; faces are xmin, xmax, "
                            "ymin, ymax, zmin, zmax",
                            mf_loc_str(v->loc, where, sizeof where), name,
                            hint ? " (did you mean '" : "", hint ? hint : "", hint ? "'?)" : "");
        }
        open[f / 2][f % 2] = true;
    }
    return 0;
}

/* A wall box: a tank for the solids (mf_walls.h) and, with particle walls,
 * its layers: a lattice point k steps outside the region is in layer k, the
 * first wallLayers are MF_WALL, the rest MF_DUMMY. */
static int add_wall_particles(mf_sim *sim, const wall_settings *ws, bool open[3][2]);
static int add_wall_box(mf_sim *sim, const char *name, const mf_dict *d, mf_dict *resolved)
{
    wall_settings s;
    mf_dict *out = resolved ? mf_dict_set_subdict(resolved, name) : NULL;
    MF_CALL(mf_params_apply(wall_params, NP(wall_params), d, wall_extra, &s, out));
    MF_CALL(mf_lattice_check_box("wall", name, d, s.min, s.max, sim->dim));
    bool open[3][2];
    MF_CALL(parse_open_faces(d, name, open));
    mf_wall w;
    MF_CALL(mf_scene_solid_init(sim, name, d, s.velocity, s.motion, MF_SOLID_TANK, false, &w));
    memcpy(w.min, s.min, sizeof w.min);
    memcpy(w.max, s.max, sizeof w.max);
    memcpy(w.open, open, sizeof w.open);
    if (sim->dim == 2) /* no z faces in 2-D */
        w.open[2][0] = w.open[2][1] = true;
    if (!sim->wall_weight)
        w.thickness = (double)(s.wall_layers + s.dummy_layers) * sim->l0;
    const size_t first = sim->p->n;
    int rc = sim->wall_weight ? 0 : add_wall_particles(sim, &s, open);
    if (rc == 0)
        rc = mf_scene_solid_add(sim, &w, first);
    if (rc != 0) {
        mf_motion_free(&w.motion);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    return 0;
}

/* The wall box's particles: a lattice point k steps outside the region is
 * in layer k. */
static int add_wall_particles(mf_sim *sim, const wall_settings *ws, bool open[3][2])
{
    const wall_settings s = *ws;
    const double l0 = sim->l0;
    const long layers = s.wall_layers + s.dummy_layers;
    long lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, n[3] = {1, 1, 1};
    for (int a = 0; a < sim->dim; a++) {
        long h = mf_lattice_count(s.min[a], s.max[a], l0);
        n[a] = h;
        lo[a] = open[a][0] ? 0 : -layers;
        hi[a] = open[a][1] ? h : h + layers;
    }
    for (long k = lo[2]; k < hi[2]; k++)
        for (long j = lo[1]; j < hi[1]; j++)
            for (long i = lo[0]; i < hi[0]; i++) {
                long idx[3] = {i, j, k};
                long layer = 0; /* how many lattice steps outside the region */
                for (int a = 0; a < sim->dim; a++) {
                    long out_a = idx[a] < 0 ? -idx[a] : (idx[a] >= n[a] ? idx[a] - n[a] + 1 : 0);
                    if (out_a > layer)
                        layer = out_a;
                }
                if (layer == 0)
                    continue; /* inside: that is where the fluid goes */
                double x[3] = {s.min[0] + (i + 0.5) * l0, s.min[1] + (j + 0.5) * l0,
                               sim->dim == 3 ? s.min[2] + (k + 0.5) * l0 : 0.0};
                const double v0[3] = {0, 0, 0};
                int kind = layer <= s.wall_layers ? MF_WALL : MF_DUMMY;
                MF_CALL(mf_particles_add(sim->p, kind, x, v0, NULL));
            }
    return 0;
}

/* Walk a dictionary of named sub-dictionaries (blocks, walls). */
static int for_each_named(const mf_dict *group, const char *what,
                          int (*fn)(mf_sim *, const char *, const mf_dict *, void *), mf_sim *sim,
                          void *ctx)
{
    char where[512];
    for (size_t k = 0; group && k < group->n; k++) {
        mf_entry *e = group->entries[k];
        if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT)
            return MF_ERROR(MF_ERR_INPUT, "%s: %s '%s' must be a sub-dictionary { ... }",
                            mf_loc_str(e->loc, where, sizeof where), what, e->key);
        e->used = true;
        MF_CALL(fn(sim, e->key, e->items[0]->dict, ctx));
    }
    return 0;
}

typedef struct build_ctx {
    int fluid_field;
    mf_dict *resolved;
    mf_scene_meshes *meshes; /* type mesh entries, read up front (mf_trimesh.h) */
} build_ctx;

static int visit_block(mf_sim *sim, const char *name, const mf_dict *d, void *ctx)
{
    build_ctx *c = ctx;
    if (mf_scene_entry_is_mesh(d))
        return mf_scene_mesh_fluid(c->meshes, sim, name, d, c->fluid_field,
                                   c->resolved ? mf_dict_set_subdict(c->resolved, name) : NULL);
    return add_fluid_block(sim, name, d, c->fluid_field, c->resolved);
}

static int visit_wall(mf_sim *sim, const char *name, const mf_dict *d, void *ctx)
{
    build_ctx *c = ctx;
    if (mf_scene_entry_is_mesh(d))
        return mf_scene_mesh_wall(c->meshes, sim, name, d, false,
                                  c->resolved ? mf_dict_set_subdict(c->resolved, name) : NULL);
    return add_wall_box(sim, name, d, c->resolved);
}

static int visit_obstacle(mf_sim *sim, const char *name, const mf_dict *d, void *ctx)
{
    build_ctx *c = ctx;
    if (!mf_scene_entry_is_mesh(d))
        return mf_scene_obstacle(sim, name, d,
                                 c->resolved ? mf_dict_set_subdict(c->resolved, name) : NULL);
    return mf_scene_mesh_wall(c->meshes, sim, name, d, true,
                              c->resolved ? mf_dict_set_subdict(c->resolved, name) : NULL);
}

static int build_scene(const mf_dict *geometry, double l0_override, mf_sim *sim,
                       mf_dict *resolved, const mf_trimesh_reader *reader, build_ctx *ctx,
                       mf_scene_budget *budget);

int mf_scene_build(const mf_dict *geometry, double l0_override, mf_sim *sim, mf_dict *resolved)
{
    return mf_scene_build_with_reader(geometry, l0_override, sim, resolved, NULL);
}

int mf_scene_build_with_reader(const mf_dict *geometry, double l0_override, mf_sim *sim,
                               mf_dict *resolved, const mf_trimesh_reader *reader)
{
    return mf_scene_build_budgeted(geometry, l0_override, sim, resolved, reader, NULL);
}

int mf_scene_build_budgeted(const mf_dict *geometry, double l0_override, mf_sim *sim,
                            mf_dict *resolved, const mf_trimesh_reader *reader,
                            mf_scene_budget *budget)
{
    build_ctx ctx = {-1, NULL, NULL};
    int rc = build_scene(geometry, l0_override, sim, resolved, reader, &ctx, budget);
    mf_scene_meshes_destroy(ctx.meshes);
    return rc;
}

/* -l0 replaces particleSpacing: the same range applies, and a message
 * names the option, not the file. */
static int check_spacing_override(double l0)
{
    const mf_param *p = &geometry_params[1];
    if (!isfinite(l0) || l0 < p->min || l0 > p->max)
        return MF_ERROR(MF_ERR_INPUT, "-l0 %g is out of range [%g, %g] (%s)", l0, p->min, p->max,
                        p->doc);
    return 0;
}

/* The scene's particles times the bytes a particle costs, against the
 * budget: refused before the first particle is allocated. */
static int check_budget(const mf_dict *geometry, const mf_sim *sim,
                        const mf_scene_meshes *meshes, mf_scene_budget *b)
{
    if (!b)
        return 0;
    b->particles = mf_scene_estimate_particles(geometry, sim, meshes);
    const double bytes = b->particles * b->bytes_per_particle;
    if (!(b->max_bytes > 0) || bytes <= b->max_bytes)
        return 0;
    char where[512];
    return MF_ERROR(MF_ERR_INPUT,
                    "%s: the scene would make about %.3g particles at l0 = %g m, %.3g GB at %.0f "
                    "bytes a particle (particle arrays, neighbour lists within %g l0, the "
                    "pressure matrix), more than maxMemory = %.3g GB (%s): use a larger "
                    "particleSpacing (or -l0), or raise maxMemory in system/controlDict",
                    mf_loc_str(geometry->loc, where, sizeof where), b->particles, sim->l0,
                    bytes / 1e9, b->bytes_per_particle, b->radius_l0, b->max_bytes / 1e9,
                    b->limit_source ? b->limit_source : "system/controlDict");
}

static int build_scene(const mf_dict *geometry, double l0_override, mf_sim *sim,
                       mf_dict *resolved, const mf_trimesh_reader *reader, build_ctx *ctx,
                       mf_scene_budget *budget)
{
    geometry_settings g;
    MF_CALL(mf_params_apply(geometry_params, 8, geometry, geometry_extra, &g, NULL));
    if (l0_override > 0 || !isfinite(l0_override))
        MF_CALL(check_spacing_override(l0_override));
    sim->dim = (int)g.dimension;
    sim->l0 = l0_override > 0 ? l0_override : g.spacing;
    if (resolved) {
        MF_CALL(mf_dict_set_number(resolved, "dimension", (double)sim->dim));
        MF_CALL(mf_dict_set_number(resolved, "particleSpacing", sim->l0));
    }
    if (!g.fluid_blocks && !g.walls && !g.obstacles) {
        char where[512];
        return MF_ERROR(MF_ERR_INPUT, "%s: the geometry has neither fluidBlocks nor walls",
                        mf_loc_str(geometry->loc, where, sizeof where));
    }
    MF_CALL(mf_scene_meshes_create(geometry, reader, sim->dim, sim->l0, sim->log, &ctx->meshes));
    MF_CALL(check_budget(geometry, sim, ctx->meshes, budget));
    MF_CALL(mf_particles_create(sim->dim, 1024, &sim->p));
    mf_walls_destroy(sim->walls);
    sim->walls = NULL;
    MF_CALL(mf_walls_create(sim->dim, sim->l0, !sim->wall_weight, &sim->walls));
    if (sim->nfluids > 1)
        MF_CALL(mf_particles_request_field(sim->p, "FluidId", 1, MF_FIELD_INT32, true,
                                           &ctx->fluid_field));
    ctx->resolved = resolved ? mf_dict_set_subdict(resolved, "fluidBlocks") : NULL;
    MF_CALL(for_each_named(g.fluid_blocks, "fluid block", visit_block, sim, ctx));
    ctx->resolved = resolved ? mf_dict_set_subdict(resolved, "walls") : NULL;
    MF_CALL(for_each_named(g.walls, "wall", visit_wall, sim, ctx));
    ctx->resolved = resolved && g.obstacles ? mf_dict_set_subdict(resolved, "obstacles") : NULL;
    MF_CALL(for_each_named(g.obstacles, "obstacle", visit_obstacle, sim, ctx));
    MF_CALL(mf_emitters_create(sim, g.inlets, g.outlets, g.emitters,
                               resolved && g.inlets ? mf_dict_set_subdict(resolved, "inlets") : NULL,
                               resolved && g.outlets ? mf_dict_set_subdict(resolved, "outlets")
                                                     : NULL,
                               resolved && g.emitters ? mf_dict_set_subdict(resolved, "emitters")
                                                      : NULL,
                               &sim->emitters));
    /* The store as built, with 1/16 headroom (mf_particles_add doubles). */
    MF_CALL(mf_particles_fit(sim->p, sim->p->n / 16 + 64));
    return 0;
}

const mf_param_section mf_geometry_sections[] = {
    {"geometry", "constant/geometry: the lattice and the groups of elements", geometry_params,
     NP(geometry_params)},
    {"geometry: fluidBlocks/<name>, type box or sphere", "fluid particles on the lattice",
     block_params, NP(block_params)},
    {"geometry: walls/<name>, type box", "a tank: the closed faces of a box hold the fluid in "
     "(`open (ymax)` lists faces without wall); with particle walls, layers of fixed particles "
     "around the region", wall_params, NP(wall_params)},
};
const size_t mf_geometry_nsections = NP(mf_geometry_sections);
const mf_param_section mf_fluid_sections[] = {
    {"fluids: <name>", "constant/fluids: one sub-dictionary per fluid, numbered in file order",
     fluid_params, NP(fluid_params)},
};
const size_t mf_fluid_nsections = NP(mf_fluid_sections);
