/* scene_mesh.c: polygon surfaces into particles (mf_trimesh.h).
 *
 * Walls and obstacles: every lattice point within (wallLayers + dummyLayers)
 * l0 of the surface gets its distance and side from the nearest triangle
 * (a narrow band, visited triangle by triangle along the lattice lines that
 * cross the triangle's plane, so the work follows the surface's area, not
 * its bounding box), then a layer: floor(depth / l0).
 * Fluid meshes: rays along one lattice axis, crossings counted with the sign
 * of the outward normal (a winding number along the line), and the same
 * narrow band near the surface. */
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_emitter.h"
#include "mf_error.h"
#include "mf_hashmap.h"
#include "mf_params.h"
#include "mf_scene.h"
#include "mf_trimesh.h"
#include "trimesh_internal.h"
#include "scene_internal.h"
#include "walls_internal.h"

/* Lattice indices are packed 21 bits per axis around this offset. */
#define LAT_BITS 21
#define LAT_OFF (1L << (LAT_BITS - 1))
#define LAT_MAX (LAT_OFF - 2)
/* Relative tolerance on depth / l0 (a point exactly one layer deep is in
 * the next layer whatever the rounding). */
#define LAYER_EPS 1e-9
/* A mesh this many times larger than the rest of the geometry is taken for
 * a unit error. */
#define UNITS_RATIO 300.0
/* Above this many particles a mesh is refused (a unit error, or a spacing
 * far too fine). */
#define MAX_MESH_PARTICLES 2e9

/* ---- lattice maps: packed lattice keys to entry indices (mf_hashmap.h) ------ */

typedef struct lmap {
    mf_hashmap h;
    size_t n;
} lmap;

static void lmap_free(lmap *m)
{
    mf_hashmap_free(&m->h);
    m->n = 0;
}

/* ---- the lattice ----------------------------------------------------------- */

typedef struct lattice {
    int dim;
    double l0;
} lattice;

static inline double lat_coord(const lattice *L, int axis, long i)
{
    return L->dim == 2 && axis == 2 ? 0.0 : (i + 0.5) * L->l0;
}

static inline uint64_t lat_key(const long i[3])
{
    return (uint64_t)(i[0] + LAT_OFF) | (uint64_t)(i[1] + LAT_OFF) << LAT_BITS |
           (uint64_t)(i[2] + LAT_OFF) << (2 * LAT_BITS);
}

static inline void lat_unkey(uint64_t key, long i[3])
{
    const uint64_t mask = (1ULL << LAT_BITS) - 1;
    for (int a = 0; a < 3; a++)
        i[a] = (long)((key >> (a * LAT_BITS)) & mask) - LAT_OFF;
}

/* Index range [lo, hi] of the lattice points in [a, b] along axis; false
 * when empty. In 2-D the z axis has the one point z = 0. */
static bool lat_range(const lattice *L, int axis, double a, double b, long *lo, long *hi)
{
    if (L->dim == 2 && axis == 2) {
        *lo = *hi = 0;
        return a <= 0 && 0 <= b;
    }
    double fl = ceil(a / L->l0 - 0.5), fh = floor(b / L->l0 - 0.5);
    if (fl > fh)
        return false;
    *lo = (long)fmax(fl, -LAT_MAX - 1.0);
    *hi = (long)fmin(fh, LAT_MAX + 1.0);
    return true;
}

static int check_lattice_span(const lattice *L, const double mn[3], const double mx[3],
                              double grow, const char *what)
{
    for (int a = 0; a < L->dim; a++) {
        double lo = (mn[a] - grow) / L->l0, hi = (mx[a] + grow) / L->l0;
        if (!(lo > -LAT_MAX && hi < LAT_MAX))
            return MF_ERROR(MF_ERR_INPUT,
                            "%s reaches %g m along axis %d, more than %ld particle spacings "
                            "(l0 = %g m) from the origin: check its units (`scale`) or l0",
                            what, fabs(lo) > fabs(hi) ? mn[a] : mx[a], a, (long)LAT_MAX, L->l0);
    }
    return 0;
}

/* ---- the narrow band -------------------------------------------------------- */

/* Lattice points within `width` of the surface: the distance to the
 * nearest triangle and the side (+1 where the normals point, -1 behind, 0
 * on the surface or on its rim's plane). */
typedef struct band {
    lmap map;         /* key -> entry */
    size_t n, cap;
    uint64_t *key;
    double *d2;
    int8_t *side;
} band;

static void band_free(band *b)
{
    lmap_free(&b->map);
    free(b->key);
    free(b->d2);
    free(b->side);
    memset(b, 0, sizeof *b);
}

static int band_push(band *b, uint64_t key, double d2, int side)
{
    size_t slot;
    bool added;
    if (b->n >= UINT32_MAX)
        return MF_ERROR(MF_ERR_MEMORY, "more than %u lattice points near one surface",
                        UINT32_MAX);
    MF_CALL(mf_hashmap_insert(&b->map.h, &b->map.n, key, (uint32_t)b->n, &slot, &added));
    if (!added) {
        uint32_t e = b->map.h.val[slot];
        if (d2 < b->d2[e]) {
            b->d2[e] = d2;
            b->side[e] = (int8_t)side;
        }
        return 0;
    }
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 1024;
        if (mf_resize(&b->key, cap, sizeof *b->key) || mf_resize(&b->d2, cap, sizeof *b->d2) ||
            mf_resize(&b->side, cap, sizeof *b->side))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu lattice points near a surface",
                            cap);
        b->cap = cap;
    }
    b->key[b->n] = key;
    b->d2[b->n] = d2;
    b->side[b->n] = (int8_t)side;
    b->n++;
    return 0;
}

/* The band of half-width `width` around the mesh. For each triangle, the
 * lattice lines along the axis its normal is closest to are visited only
 * where they pass within `width` of the triangle's plane. */
static int band_build(const mf_trimesh *m, const mf_pseudonormals *pn, const lattice *L,
                      double width, band *b)
{
    const double w2 = width * width;
    const double sign_tol = 1e-12 * L->l0;
    for (size_t t = 0; t < m->ntris; t++) {
        const double *v0 = &m->xyz[3 * (size_t)m->tri[3 * t]];
        const double *v1 = &m->xyz[3 * (size_t)m->tri[3 * t + 1]];
        const double *v2 = &m->xyz[3 * (size_t)m->tri[3 * t + 2]];
        long lo[3], hi[3];
        bool empty = false;
        for (int a = 0; a < 3; a++) {
            double mn = fmin(v0[a], fmin(v1[a], v2[a])) - width;
            double mx = fmax(v0[a], fmax(v1[a], v2[a])) + width;
            empty = empty || !lat_range(L, a, mn, mx, &lo[a], &hi[a]);
        }
        if (empty)
            continue;
        const double *n = &pn->face[3 * t];
        /* The free axis most along the normal. */
        int ax = 0;
        for (int a = 1; a < L->dim; a++)
            if (fabs(n[a]) > fabs(n[ax]))
                ax = a;
        int bx = (ax + 1) % 3, cx = (ax + 2) % 3;
        bool restrict_ax = fabs(n[ax]) > 0.1;
        double plane = n[0] * v0[0] + n[1] * v0[1] + n[2] * v0[2];
        long idx[3];
        for (idx[bx] = lo[bx]; idx[bx] <= hi[bx]; idx[bx]++)
            for (idx[cx] = lo[cx]; idx[cx] <= hi[cx]; idx[cx]++) {
                double x[3];
                x[bx] = lat_coord(L, bx, idx[bx]);
                x[cx] = lat_coord(L, cx, idx[cx]);
                long alo = lo[ax], ahi = hi[ax];
                if (restrict_ax) {
                    /* Where the line meets the plane, +- width / |n_ax|. */
                    double at = (plane - n[bx] * x[bx] - n[cx] * x[cx]) / n[ax];
                    double r = width / fabs(n[ax]);
                    long l2, h2;
                    if (!lat_range(L, ax, at - r, at + r, &l2, &h2))
                        continue;
                    alo = l2 > alo ? l2 : alo;
                    ahi = h2 < ahi ? h2 : ahi;
                }
                for (idx[ax] = alo; idx[ax] <= ahi; idx[ax]++) {
                    x[ax] = lat_coord(L, ax, idx[ax]);
                    double q[3];
                    int feat = mf_closest_on_triangle(x, v0, v1, v2, q);
                    double d[3] = {x[0] - q[0], x[1] - q[1], x[2] - q[2]};
                    double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    if (d2 >= w2)
                        continue;
                    const double *pnv = mf_pseudonormal_of(pn, m, t, feat);
                    double s = d[0] * pnv[0] + d[1] * pnv[1] + d[2] * pnv[2];
                    int side = s > sign_tol ? 1 : (s < -sign_tol ? -1 : 0);
                    MF_CALL(band_push(b, lat_key(idx), d2, side));
                }
            }
    }
    return 0;
}

/* ---- the meshes of a scene -------------------------------------------------- */

enum side_mode { SIDE_NORMALS, SIDE_INSIDE, SIDE_OUTSIDE, SIDE_BOTH };
static const char *const side_names[] = {"normals", "inside", "outside", "both", "auto", NULL};

typedef struct mesh_item {
    char group[32], name[64];
    const mf_dict *dict;
    char where[512];      /* "file:line:col: wall 'name'" for messages */
    char label[128];      /* "wall 'name'" */
    mf_trimesh mesh;
    mf_trimesh_report rep;
    double scale;
    bool scale_given;
    mf_pseudonormals pn;
    bool has_pn;
} mesh_item;

struct mf_scene_meshes {
    lattice L;
    mf_log *log;
    size_t n;
    mesh_item *item;
    lmap placed;          /* lattice key -> index of a wall/dummy particle made from a mesh */
};

bool mf_scene_entry_is_mesh(const mf_dict *entry)
{
    const mf_entry *e = entry ? mf_dict_find(entry, "type") : NULL;
    return e && e->n == 1 &&
           (e->items[0]->kind == MF_VAL_WORD || e->items[0]->kind == MF_VAL_STRING) &&
           strcmp(e->items[0]->text, "mesh") == 0;
}

static const char *const mesh_type[] = {"mesh", NULL};

/* Settings of a mesh entry (one struct for the three uses). */
typedef struct mesh_settings {
    const char *type, *file, *side, *fluid;
    double scale, thickness, velocity[3];
    long wall_layers, dummy_layers;
    const mf_dict *scalars, *motion;
} mesh_settings;

#define P_TYPE {"type", MF_PARAM_WORD, NULL, MF_NO_RANGE, mesh_type, \
                offsetof(mesh_settings, type), "mesh: a surface read from a polygon file"}
#define P_FILE {"file", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(mesh_settings, file), \
                "polygon file (OBJ, STL, PLY...), relative to constant/ or constant/triSurface/"}
#define P_SCALE {"scale", MF_PARAM_SCALAR, "1", 1e-12, 1e12, NULL, \
                 offsetof(mesh_settings, scale), \
                 "factor on the file's coordinates (0.001 for millimetres); given, it also " \
                 "turns off the unit check"}
#define P_LAYERS \
    {"wallLayers", MF_PARAM_INT, "1", 1, 3, NULL, offsetof(mesh_settings, wall_layers), \
     "layers of wall particles (in the pressure equation)"}, \
    {"dummyLayers", MF_PARAM_INT, "2", 0, 4, NULL, offsetof(mesh_settings, dummy_layers), \
     "layers of dummy particles behind them (number density only)"}, \
    {"thickness", MF_PARAM_SCALAR, "0", 0, 1e6, NULL, offsetof(mesh_settings, thickness), \
     "side both: thickness of the solid slab, m (0: 2 (wallLayers + dummyLayers) l0)"}, \
    {"velocity", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL, \
     offsetof(mesh_settings, velocity), \
     "velocity of the surface along itself, m/s (a belt: the shape stays)"}, \
    {"motion", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(mesh_settings, motion), \
     "prescribed rigid motion (see geometry: <wall or obstacle>/motion)"}

static const mf_param wall_mesh_params[] = {
    P_TYPE, P_FILE, P_SCALE,
    {"side", MF_PARAM_WORD, "normals", MF_NO_RANGE, side_names, offsetof(mesh_settings, side),
     "where the fluid is: normals (the side they point to), inside or outside a closed "
     "surface, both (a thin plate)"},
    P_LAYERS,
};
static const mf_param obstacle_mesh_params[] = {
    P_TYPE, P_FILE, P_SCALE,
    {"side", MF_PARAM_WORD, "auto", MF_NO_RANGE, side_names, offsetof(mesh_settings, side),
     "where the fluid is: auto (outside a closed surface, both sides of an open one), normals, "
     "inside, outside, both"},
    P_LAYERS,
};
static const mf_param fluid_mesh_params[] = {
    P_TYPE, P_FILE, P_SCALE,
    {"fluid", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(mesh_settings, fluid),
     "name of a fluid in constant/fluids"},
    {"velocity", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL,
     offsetof(mesh_settings, velocity), "initial velocity, m/s"},
    {"scalars", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(mesh_settings, scalars),
     "initial transported scalars (mf_emitter.h)"},
};
#define NPARAMS(t) (sizeof(t) / sizeof((t)[0]))

const mf_param_section mf_mesh_sections[] = {
    {"geometry: walls/<name>, type mesh", "a wall made from a polygon file (mf_trimesh.h)",
     wall_mesh_params, NPARAMS(wall_mesh_params)},
    {"geometry: obstacles/<name>", "a solid body in the fluid, from a polygon file",
     obstacle_mesh_params, NPARAMS(obstacle_mesh_params)},
    {"geometry: fluidBlocks/<name>, type mesh", "fluid filling a closed polygon surface",
     fluid_mesh_params, NPARAMS(fluid_mesh_params)},
};
const size_t mf_mesh_nsections = NPARAMS(mf_mesh_sections);

static const mf_param *params_of(const char *group, size_t *n)
{
    if (strcmp(group, "fluidBlocks") == 0) {
        *n = NPARAMS(fluid_mesh_params);
        return fluid_mesh_params;
    }
    if (strcmp(group, "obstacles") == 0) {
        *n = NPARAMS(obstacle_mesh_params);
        return obstacle_mesh_params;
    }
    *n = NPARAMS(wall_mesh_params);
    return wall_mesh_params;
}

static const char *what_of(const char *group)
{
    return strcmp(group, "fluidBlocks") == 0 ? "fluid block"
           : strcmp(group, "obstacles") == 0 ? "obstacle"
                                             : "wall";
}

static void warn(mf_scene_meshes *sm, const mesh_item *it, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void warn(mf_scene_meshes *sm, const mesh_item *it, const char *fmt, ...)
{
    char text[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    mf_log_printf(sm->log, MF_LOG_QUIET, "Warning: %s: %s: %s\n", it->where, it->mesh.name, text);
}

/* Bounding box of a box entry (min, max) or a point (centre), looked at
 * without marking anything used: the box's own reader checks it later. */
static void peek_extent(const mf_dict *d, double mn[3], double mx[3], bool *any)
{
    static const char *const keys[] = {"min", "max", "centre", "origin"};
    for (int k = 0; k < 4; k++) {
        const mf_entry *e = mf_dict_find(d, keys[k]);
        if (!e || e->n != 1 || e->items[0]->kind != MF_VAL_LIST || e->items[0]->n != 3)
            continue;
        for (int a = 0; a < 3; a++) {
            const mf_value *v = e->items[0]->items[a];
            if (v->kind != MF_VAL_NUMBER)
                continue;
            mn[a] = fmin(mn[a], v->number);
            mx[a] = fmax(mx[a], v->number);
        }
        *any = true;
    }
}

static double extent_of(int dim, const double mn[3], const double mx[3])
{
    double e = 0;
    for (int a = 0; a < dim; a++)
        e = fmax(e, mx[a] - mn[a]);
    return e;
}

static int load_item(mf_scene_meshes *sm, const mf_trimesh_reader *reader, mesh_item *it)
{
    size_t np;
    const mf_param *table = params_of(it->group, &np);
    mesh_settings s;
    MF_CALL(mf_params_apply(table, np, it->dict, NULL, &s, NULL));
    it->scale = s.scale;
    it->scale_given = mf_dict_find(it->dict, "scale") != NULL;
    const mf_entry *fe = mf_dict_find(it->dict, "file");
    char floc[512];
    mf_loc_str(fe->loc, floc, sizeof floc);
    if (!reader || !reader->read)
        return MF_ERROR(MF_ERR_INPUT, "%s: %s: this program has no polygon file reader",
                        floc, it->label);
    int rc = reader->read(reader->ctx, s.file, fe->loc.file, &it->mesh);
    if (rc != 0)
        return MF_ERROR(rc, "%s: %s: %s", floc, it->label, mf_error_message());
    /* A face with fewer than three corners is what a file cut short in the
     * middle of a face line reads as: refuse it rather than build half a wall. */
    if (it->mesh.dropped)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: %s: %s holds %zu points or lines beside its triangles (a file cut "
                        "short in the middle of a face, or edges drawn in it); only triangles "
                        "and polygons make surfaces: repair or re-export the file",
                        floc, it->label, it->mesh.name, it->mesh.dropped);
    if (it->scale != 1)
        mf_trimesh_scale(&it->mesh, it->scale);
    rc = mf_trimesh_check(&it->mesh, &it->rep);
    if (rc != 0)
        return MF_ERROR(rc, "%s: %s", it->where, mf_error_message());
    const mf_trimesh_report *r = &it->rep;
    if (r->ndegenerate)
        warn(sm, it, "removed %zu degenerate (zero-area) triangles, the first near (%g %g %g)",
             r->ndegenerate, r->at_degenerate[0], r->at_degenerate[1], r->at_degenerate[2]);
    return 0;
}

/* A mesh three hundred or more times larger than the rest of the geometry is
 * almost always a file in millimetres (a real scene rarely spans such
 * ratios; a small drop in a large tank is 100 or so): refuse
 * it with the factor to give, unless `scale` says what the units are. */
static int check_units(mf_scene_meshes *sm, const double ref_min[3], const double ref_max[3],
                       bool have_ref)
{
    const int dim = sm->L.dim;
    for (size_t i = 0; i < sm->n; i++) {
        mesh_item *it = &sm->item[i];
        double mn[3], mx[3];
        memcpy(mn, ref_min, sizeof mn);
        memcpy(mx, ref_max, sizeof mx);
        bool any = have_ref;
        for (size_t j = 0; j < sm->n; j++) {
            if (j == i)
                continue;
            for (int a = 0; a < 3; a++) {
                mn[a] = fmin(mn[a], sm->item[j].rep.min[a]);
                mx[a] = fmax(mx[a], sm->item[j].rep.max[a]);
            }
            any = true;
        }
        double own = extent_of(dim, it->rep.min, it->rep.max);
        double ref = any ? extent_of(dim, mn, mx) : 0;
        if (!it->scale_given && ref > 0 && own >= UNITS_RATIO * ref) {
            double ratio = own / ref;
            double suggest = pow(10.0, -3.0 * round(log10(ratio) / 3.0));
            return MF_ERROR(MF_ERR_INPUT,
                            "%s: %s spans %g m, %.0f times the rest of the geometry (%g m): "
                            "are its coordinates in millimetres? Add `scale %g;` to the entry "
                            "(or `scale 1;` if the size is right)",
                            it->where, it->mesh.name, own, ratio, ref, suggest);
        }
        /* Particles it would make: its area over l0^2 per layer (3-D), its
         * extent over l0 per layer (2-D: a section). */
        double per_layer = dim == 3 ? it->rep.area / (sm->L.l0 * sm->L.l0) : own / sm->L.l0;
        if (per_layer * 8 > MAX_MESH_PARTICLES)
            return MF_ERROR(MF_ERR_INPUT,
                            "%s: %s (%g m across, %g m^2) would need about %.3g particles at "
                            "l0 = %g m: is the file in millimetres (`scale 0.001;`), or l0 too "
                            "small?",
                            it->where, it->mesh.name, own, it->rep.area, per_layer * 8, sm->L.l0);
        MF_CALL(check_lattice_span(&sm->L, it->rep.min, it->rep.max, 8 * sm->L.l0, it->where));
    }
    return 0;
}

int mf_scene_meshes_create(const mf_dict *geometry, const mf_trimesh_reader *reader, int dim,
                           double l0, mf_log *log, mf_scene_meshes **out)
{
    *out = NULL;
    static const char *const mesh_groups[] = {"fluidBlocks", "walls", "obstacles"};
    static const char *const box_groups[] = {"fluidBlocks", "walls", "inlets", "outlets",
                                             "emitters"};
    size_t count = 0;
    for (int g = 0; g < 3; g++) {
        const mf_dict *grp = mf_dict_subdict(geometry, mesh_groups[g]);
        for (size_t k = 0; grp && k < grp->n; k++) {
            const mf_entry *e = grp->entries[k];
            if (e->n == 1 && e->items[0]->kind == MF_VAL_DICT &&
                mf_scene_entry_is_mesh(e->items[0]->dict))
                count++;
        }
    }
    if (count == 0)
        return 0;
    mf_scene_meshes *sm = calloc(1, sizeof *sm);
    if (sm)
        sm->item = calloc(count, sizeof *sm->item);
    if (!sm || !sm->item) {
        free(sm);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    }
    sm->L = (lattice){dim, l0};
    sm->log = log;
    *out = sm;
    double rmin[3] = {INFINITY, INFINITY, INFINITY}, rmax[3] = {-INFINITY, -INFINITY, -INFINITY};
    bool have_ref = false;
    for (int g = 0; g < 5; g++) {
        const mf_dict *grp = mf_dict_subdict(geometry, box_groups[g]);
        for (size_t k = 0; grp && k < grp->n; k++) {
            const mf_entry *e = grp->entries[k];
            if (e->n == 1 && e->items[0]->kind == MF_VAL_DICT &&
                !mf_scene_entry_is_mesh(e->items[0]->dict))
                peek_extent(e->items[0]->dict, rmin, rmax, &have_ref);
        }
    }
    for (int g = 0; g < 3; g++) {
        const mf_dict *grp = mf_dict_subdict(geometry, mesh_groups[g]);
        for (size_t k = 0; grp && k < grp->n; k++) {
            const mf_entry *e = grp->entries[k];
            if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT ||
                !mf_scene_entry_is_mesh(e->items[0]->dict))
                continue;
            mesh_item *it = &sm->item[sm->n++];
            snprintf(it->group, sizeof it->group, "%s", mesh_groups[g]);
            snprintf(it->name, sizeof it->name, "%s", e->key);
            it->dict = e->items[0]->dict;
            mf_trimesh_init(&it->mesh);
            char loc[400];
            snprintf(it->label, sizeof it->label, "%s '%s'", what_of(mesh_groups[g]), e->key);
            snprintf(it->where, sizeof it->where, "%s: %s '%s'",
                     mf_loc_str(e->loc, loc, sizeof loc), what_of(mesh_groups[g]), e->key);
            MF_CALL(load_item(sm, reader, it));
        }
    }
    return check_units(sm, rmin, rmax, have_ref);
}

double mf_scene_meshes_estimate(const mf_scene_meshes *sm)
{
    double count = 0;
    for (size_t i = 0; sm && i < sm->n; i++) {
        const mesh_item *it = &sm->item[i];
        const int dim = sm->L.dim;
        const double l0 = sm->L.l0;
        double mn[3], mx[3];
        mf_trimesh_bounds(&it->mesh, mn, mx);
        if (strcmp(it->group, "fluidBlocks") == 0) {
            double v = 1;
            for (int a = 0; a < dim; a++)
                v *= floor((mx[a] - mn[a]) / l0) + 1;
            count += v;
            continue;
        }
        double layers = 3; /* wallLayers + dummyLayers by default */
        double w = 1, d = 2;
        if (mf_dict_get_number_or(it->dict, "wallLayers", 1, &w) == 0 &&
            mf_dict_get_number_or(it->dict, "dummyLayers", 2, &d) == 0)
            layers = w + d;
        mf_error_clear();
        if (dim == 3)
            count += it->rep.area / (l0 * l0) * (layers + 1);
        else
            count += 2 * ((mx[0] - mn[0]) + (mx[1] - mn[1])) / l0 * (layers + 1);
    }
    return count;
}

void mf_scene_meshes_destroy(mf_scene_meshes *sm)
{
    if (!sm)
        return;
    for (size_t i = 0; i < sm->n; i++) {
        mf_trimesh_free(&sm->item[i].mesh);
        mf_pseudonormals_free(&sm->item[i].pn);
    }
    free(sm->item);
    lmap_free(&sm->placed);
    free(sm);
}

static int find_item(mf_scene_meshes *sm, const char *group, const char *name, mesh_item **out)
{
    for (size_t i = 0; sm && i < sm->n; i++)
        if (strcmp(sm->item[i].group, group) == 0 && strcmp(sm->item[i].name, name) == 0) {
            *out = &sm->item[i];
            if (!sm->item[i].has_pn) {
                MF_CALL(mf_pseudonormals_build(&sm->item[i].mesh, &sm->item[i].pn));
                sm->item[i].has_pn = true;
            }
            return 0;
        }
    return MF_ERROR(MF_ERR_INTERNAL, "%s '%s' was not read with the scene's meshes", group, name);
}

/* Where a side must be decided from the surface, it must be closed. */
static int require_closed(const mesh_item *it, const char *why)
{
    const mf_trimesh_report *r = &it->rep;
    if (r->closed && r->orientable)
        return 0;
    if (!r->orientable)
        return MF_ERROR(MF_ERR_INPUT, "%s: %s: no consistent winding exists (a one-sided "
                        "surface); %s", it->where, it->mesh.name, why);
    char open[200] = "", nonman[200] = "";
    if (r->nboundary)
        snprintf(open, sizeof open, "%zu open edges (the first at (%g %g %g))", r->nboundary,
                 r->at_boundary[0], r->at_boundary[1], r->at_boundary[2]);
    if (r->nnonmanifold)
        snprintf(nonman, sizeof nonman, "%s%zu edges shared by more than two triangles (the "
                 "first at (%g %g %g))", r->nboundary ? ", " : "", r->nnonmanifold,
                 r->at_nonmanifold[0], r->at_nonmanifold[1], r->at_nonmanifold[2]);
    return MF_ERROR(MF_ERR_INPUT, "%s: %s is not a closed surface: %s%s; %s", it->where,
                    it->mesh.name, open, nonman, why);
}

static void report_orientation(mf_scene_meshes *sm, const mesh_item *it)
{
    if (it->rep.nflipped)
        warn(sm, it, "%zu triangles were wound against their neighbours and have been turned "
             "(in each connected piece the winding of most triangles is kept)",
             it->rep.nflipped);
}

/* ---- walls and obstacles -------------------------------------------------- */

static int place_fixed(mf_scene_meshes *sm, mf_sim *sim, uint64_t key, int kind, size_t *nwall,
                       size_t *ndummy)
{
    size_t slot;
    bool added;
    if (sim->p->n >= UINT32_MAX)
        return MF_ERROR(MF_ERR_MEMORY, "too many particles for the mesh lattice map");
    MF_CALL(mf_hashmap_insert(&sm->placed.h, &sm->placed.n, key, (uint32_t)sim->p->n, &slot,
                              &added));
    if (!added) {
        /* Two meshes meet here: the point is a wall if either says so. */
        uint32_t i = sm->placed.h.val[slot];
        if (kind == MF_WALL && sim->p->kind[i] == MF_DUMMY) {
            sim->p->kind[i] = MF_WALL;
            (*nwall)++;
            (*ndummy)--;
        }
        return 0;
    }
    long idx[3];
    lat_unkey(key, idx);
    double x[3];
    for (int a = 0; a < 3; a++)
        x[a] = lat_coord(&sm->L, a, idx[a]);
    const double v0[3] = {0, 0, 0};
    MF_CALL(mf_particles_add(sim->p, kind, x, v0, NULL));
    if (kind == MF_WALL)
        (*nwall)++;
    else
        (*ndummy)++;
    return 0;
}

/* Which side of the surface is solid, and how deep a band point lies in
 * it (mf_trimesh.h: side). */
typedef struct side_rule {
    int mode;
    int out_sign; /* +1 when the normals of a closed surface point out */
    double half;  /* side both: half the slab's thickness */
} side_rule;

static bool solid_depth(const side_rule *r, const band *b, size_t e, double *depth)
{
    const double dist = sqrt(b->d2[e]);
    const int side = b->side[e];
    switch (r->mode) {
    case SIDE_NORMALS: /* fluid where the normals point: solid behind or on */
        *depth = dist;
        return side <= 0;
    case SIDE_INSIDE: /* fluid inside: solid outside or on */
        *depth = dist;
        return r->out_sign * side >= 0;
    case SIDE_OUTSIDE:
        *depth = dist;
        return r->out_sign * side <= 0;
    default: /* both: the slab |d| < half */
        *depth = r->half - dist;
        return dist < r->half * (1 - LAYER_EPS);
    }
}

/* A solid point with a fluid-side point among its lattice neighbours (26 in
 * 3-D, 8 in 2-D) must be a wall particle whatever its distance: along the
 * edges and at the corners of the fluid region the nearest solid points can
 * lie more than l0 from the surface (a wall 0.97 l0 deep meets a floor
 * 0.5 l0 deep at 1.08 l0), and a dummy particle there, which has no
 * pressure, is where the fluid gets through. Outside the band lies deep
 * solid, except around a slab (side both), whose band is the slab. */
static bool touches_fluid(const side_rule *r, const band *b, uint64_t key, int dim)
{
    long idx[3];
    lat_unkey(key, idx);
    for (int dz = dim == 3 ? -1 : 0; dz <= (dim == 3 ? 1 : 0); dz++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                if (!dx && !dy && !dz)
                    continue;
                long n[3] = {idx[0] + dx, idx[1] + dy, idx[2] + dz};
                size_t slot = mf_hashmap_find(&b->map.h, lat_key(n));
                if (slot == SIZE_MAX) {
                    if (r->mode == SIDE_BOTH)
                        return true;
                    continue;
                }
                double depth;
                if (!solid_depth(r, b, b->map.h.val[slot], &depth))
                    return true;
            }
    return false;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

int mf_scene_mesh_wall(mf_scene_meshes *sm, mf_sim *sim, const char *name, const mf_dict *d,
                       bool obstacle, mf_dict *resolved)
{
    const char *group = obstacle ? "obstacles" : "walls";
    mesh_item *it;
    MF_CALL(find_item(sm, group, name, &it));
    size_t np;
    const mf_param *table = params_of(group, &np);
    mesh_settings s;
    MF_CALL(mf_params_apply(table, np, d, NULL, &s, resolved));
    const double l0 = sm->L.l0;
    const mf_trimesh_report *r = &it->rep;
    int mode = SIDE_NORMALS;
    for (int k = 0; k < 4; k++)
        if (strcmp(s.side, side_names[k]) == 0)
            mode = k;
    if (strcmp(s.side, "auto") == 0)
        mode = r->closed && r->orientable ? SIDE_OUTSIDE : SIDE_BOTH;
    if (resolved)
        MF_CALL(mf_dict_set_word(resolved, "side", side_names[mode]));
    if (mode == SIDE_INSIDE || mode == SIDE_OUTSIDE)
        MF_CALL(require_closed(it, "side inside or outside needs a closed surface (use side "
                               "normals or both for an open one)"));
    if (mode == SIDE_NORMALS) {
        if (!r->orientable)
            MF_CALL(require_closed(it, "side normals needs a surface whose triangles can be "
                                   "wound consistently"));
        if (r->nnonmanifold)
            warn(sm, it, "%zu edges are shared by more than two triangles (the first at "
                 "(%g %g %g)): points nearest to them take the side of the sum of those faces' "
                 "normals", r->nnonmanifold, r->at_nonmanifold[0], r->at_nonmanifold[1],
                 r->at_nonmanifold[2]);
    }
    if (mode != SIDE_BOTH)
        report_orientation(sm, it);
    /* Outward: the signed volume of a closed surface is positive when its
     * normals point out. */
    const int out_sign = r->volume >= 0 ? 1 : -1;
    const long nlayers = s.wall_layers + s.dummy_layers;
    const double half = mode == SIDE_BOTH
                            ? (s.thickness > 0 ? 0.5 * s.thickness : (double)nlayers * l0)
                            : 0;
    if (mode == SIDE_BOTH && resolved)
        MF_CALL(mf_dict_set_number(resolved, "thickness", 2 * half));
    const double width = (mode == SIDE_BOTH ? half : (double)nlayers * l0) * (1 + 1e-9);

    mf_wall solid;
    MF_CALL(mf_scene_solid_init(sim, name, d, s.velocity, s.motion, MF_SOLID_MESH, obstacle,
                                &solid));
    const size_t first = sim->p->n;
    int rc = 0;
    if (sim->wall_weight) { /* the surface itself, kept for the run */
        rc = mf_wall_mesh_create(&it->mesh, mode, out_sign, half, 4 * l0, sim->dim, &solid.mesh);
        if (rc == 0)
            rc = mf_scene_solid_add(sim, &solid, first);
        if (rc == 0)
            mf_log_printf(sm->log, MF_LOG_NORMAL,
                          "%s mesh '%s': %s, %zu triangles, %s, side %s: wall weight, no "
                          "particles\n", obstacle ? "Obstacle" : "Wall", name, it->mesh.name,
                          it->mesh.ntris, r->closed ? "closed" : "open", side_names[mode]);
        if (rc != 0) {
            mf_motion_free(&solid.motion);
            mf_wall_mesh_destroy(solid.mesh);
        }
        return rc;
    }

    band b;
    memset(&b, 0, sizeof b);
    rc = band_build(&it->mesh, &it->pn, &sm->L, width, &b);
    uint64_t *keys = NULL;
    size_t nkeys = 0, nwall = 0, ndummy = 0;
    if (rc == 0) {
        keys = malloc(b.n * sizeof *keys + 1);
        if (!keys)
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    }
    const side_rule rule = {mode, out_sign, half};
    for (size_t e = 0; rc == 0 && e < b.n; e++) {
        double depth;
        if (!solid_depth(&rule, &b, e, &depth))
            continue;
        long layer = (long)floor(depth / l0 + LAYER_EPS);
        if (layer >= nlayers) {
            if (mode != SIDE_BOTH)
                continue;
            layer = nlayers - 1; /* the middle of a thick slab */
        }
        bool wall = layer < s.wall_layers || touches_fluid(&rule, &b, b.key[e], sm->L.dim);
        /* The kind goes in the key's spare top bit until placement. */
        keys[nkeys++] = b.key[e] | (wall ? 1ULL << 63 : 0);
    }
    if (rc == 0) {
        if (nkeys > 1)
            qsort(keys, nkeys, sizeof *keys, cmp_u64);
        for (size_t k = 0; rc == 0 && k < nkeys; k++) {
            int kind = keys[k] >> 63 ? MF_WALL : MF_DUMMY;
            rc = place_fixed(sm, sim, keys[k] & ~(1ULL << 63), kind, &nwall, &ndummy);
        }
    }
    free(keys);
    band_free(&b);
    /* a rigid body keeps its surface: its mass properties (mf_body_create)
     * and its distance for the contacts (body_contact.c) need it */
    if (rc == 0 && solid.motion.kind == MF_MOTION_RIGID)
        rc = mf_wall_mesh_create(&it->mesh, mode, out_sign, half, 4 * l0, sim->dim, &solid.mesh);
    if (rc == 0)
        rc = mf_scene_solid_add(sim, &solid, first);
    if (rc != 0) {
        mf_motion_free(&solid.motion);
        mf_wall_mesh_destroy(solid.mesh); /* not taken over: NULL, or still ours */
    }
    MF_CALL(rc);
    if (nwall == 0)
        warn(sm, it, "no wall particle was placed (is the surface outside the domain, or, in "
             "2-D, does it not cross z = 0?)");
    mf_log_printf(sm->log, MF_LOG_NORMAL,
                  "%s %s '%s': %s, %zu triangles, %s, side %s: %zu wall and %zu dummy "
                  "particles\n",
                  obstacle ? "Obstacle" : "Wall", "mesh", name, it->mesh.name, it->mesh.ntris,
                  r->closed ? "closed" : "open", side_names[mode], nwall, ndummy);
    return 0;
}

/* ---- fluid meshes ----------------------------------------------------------- */

typedef struct crossing {
    size_t col;
    double at;
    int delta; /* +1 entering, -1 leaving, walking up the axis */
} crossing;

static int cmp_crossing(const void *pa, const void *pb)
{
    const crossing *a = pa, *b = pb;
    if (a->col != b->col) return a->col < b->col ? -1 : 1;
    if (a->at != b->at) return a->at < b->at ? -1 : 1;
    return a->delta < b->delta ? -1 : a->delta > b->delta;
}

/* Lattice lines along axis `ax` through the mesh's bounding box, and where
 * each crosses the surface. (ax, bx, cx) is a cyclic permutation of (x, y,
 * z), so the projected area of a triangle on the (bx, cx) plane has the
 * sign of its normal along ax. The lines are moved by 1e-7 l0 across, so
 * that they do not pass exactly through edges and vertices of meshes drawn
 * on round numbers; the particles are not moved. */
static int fill_points(const mesh_item *it, const lattice *L, int out_sign, const band *b,
                       uint64_t **keys_out, size_t *nkeys_out)
{
    const mf_trimesh *m = &it->mesh;
    const int ax = L->dim == 3 ? 2 : 0, bx = (ax + 1) % 3, cx = (ax + 2) % 3;
    const double eps_b = 1.4142135623e-7 * L->l0, eps_c = 1.7320508075e-7 * L->l0;
    const double tol = 1e-9 * L->l0;
    long lo[3], hi[3];
    for (int a = 0; a < 3; a++)
        if (!lat_range(L, a, it->rep.min[a], it->rep.max[a], &lo[a], &hi[a])) {
            *keys_out = NULL;
            *nkeys_out = 0;
            return 0;
        }
    const size_t nb = (size_t)(hi[bx] - lo[bx] + 1);
    crossing *cr = NULL;
    size_t ncr = 0, capcr = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        const double *v[3];
        for (int k = 0; k < 3; k++)
            v[k] = &m->xyz[3 * (size_t)m->tri[3 * t + k]];
        double area2 = (v[1][bx] - v[0][bx]) * (v[2][cx] - v[0][cx]) -
                       (v[1][cx] - v[0][cx]) * (v[2][bx] - v[0][bx]);
        if (area2 == 0)
            continue; /* parallel to the lines */
        long blo, bhi, clo, chi;
        if (!lat_range(L, bx, fmin(v[0][bx], fmin(v[1][bx], v[2][bx])) - eps_b,
                       fmax(v[0][bx], fmax(v[1][bx], v[2][bx])) - eps_b, &blo, &bhi) ||
            !lat_range(L, cx, fmin(v[0][cx], fmin(v[1][cx], v[2][cx])) - eps_c,
                       fmax(v[0][cx], fmax(v[1][cx], v[2][cx])) - eps_c, &clo, &chi))
            continue;
        for (long j = blo; j <= bhi; j++)
            for (long k = clo; k <= chi; k++) {
                double qb = lat_coord(L, bx, j) + eps_b, qc = lat_coord(L, cx, k) + eps_c;
                double w[3];
                for (int e = 0; e < 3; e++) {
                    const double *p = v[(e + 1) % 3], *q = v[(e + 2) % 3];
                    w[e] = (q[bx] - p[bx]) * (qc - p[cx]) - (q[cx] - p[cx]) * (qb - p[bx]);
                }
                bool in = area2 > 0 ? (w[0] >= 0 && w[1] >= 0 && w[2] >= 0)
                                    : (w[0] <= 0 && w[1] <= 0 && w[2] <= 0);
                if (!in)
                    continue;
                if (ncr == capcr) {
                    size_t cap = capcr ? 2 * capcr : 1024;
                    if (mf_resize(&cr, cap, sizeof *cr)) {
                        free(cr);
                        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu ray crossings",
                                        cap);
                    }
                    capcr = cap;
                }
                double at = (w[0] * v[0][ax] + w[1] * v[1][ax] + w[2] * v[2][ax]) / area2;
                /* The outward normal against the walk: the line enters. */
                int delta = (area2 > 0 ? -1 : 1) * out_sign;
                cr[ncr++] = (crossing){(size_t)(k - lo[cx]) * nb + (size_t)(j - lo[bx]), at,
                                       delta};
            }
    }
    if (ncr > 1) /* qsort may not be handed NULL, which cr is with no crossing */
        qsort(cr, ncr, sizeof *cr, cmp_crossing);
    uint64_t *keys = NULL;
    size_t nkeys = 0, capk = 0;
    for (size_t s = 0; s < ncr;) {
        size_t e = s;
        while (e < ncr && cr[e].col == cr[s].col)
            e++;
        long idx[3];
        idx[bx] = lo[bx] + (long)(cr[s].col % nb);
        idx[cx] = lo[cx] + (long)(cr[s].col / nb);
        int wind = 0;
        for (size_t q = s; q + 1 < e; q++) {
            wind += cr[q].delta;
            if (wind <= 0)
                continue;
            long a0, a1;
            if (!lat_range(L, ax, cr[q].at + tol, cr[q + 1].at - tol, &a0, &a1))
                continue;
            for (idx[ax] = a0; idx[ax] <= a1; idx[ax]++) {
                uint64_t key = lat_key(idx);
                size_t slot = mf_hashmap_find(&b->map.h, key);
                if (slot != SIZE_MAX && out_sign * b->side[b->map.h.val[slot]] >= 0)
                    continue; /* on the surface or outside by the walls' own reckoning */
                if (nkeys == capk) {
                    size_t cap = capk ? 2 * capk : 4096;
                    if (mf_resize(&keys, cap, sizeof *keys)) {
                        free(keys);
                        free(cr);
                        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu fluid points",
                                        cap);
                    }
                    capk = cap;
                }
                keys[nkeys++] = key;
            }
        }
        s = e;
    }
    free(cr);
    *keys_out = keys;
    *nkeys_out = nkeys;
    return 0;
}

int mf_scene_mesh_fluid(mf_scene_meshes *sm, mf_sim *sim, const char *name, const mf_dict *d,
                        int fluid_field, mf_dict *resolved)
{
    mesh_item *it;
    MF_CALL(find_item(sm, "fluidBlocks", name, &it));
    mesh_settings s;
    MF_CALL(mf_params_apply(fluid_mesh_params, NPARAMS(fluid_mesh_params), d, NULL, &s,
                            resolved));
    int fid = 0;
    if (mf_scene_fluid_index(sim, s.fluid, &fid) != 0) {
        char where[512];
        return MF_ERROR(MF_ERR_INPUT, "%s: fluid block '%s': %s",
                        mf_loc_str(mf_dict_find(d, "fluid")->loc, where, sizeof where), name,
                        mf_error_message());
    }
    MF_CALL(require_closed(it, "a fluid mesh must be closed (watertight) to be filled"));
    report_orientation(sm, it);
    const int out_sign = it->rep.volume >= 0 ? 1 : -1;
    band b;
    memset(&b, 0, sizeof b);
    uint64_t *keys = NULL;
    size_t nkeys = 0;
    int rc = band_build(&it->mesh, &it->pn, &sm->L, sm->L.l0, &b);
    if (rc == 0)
        rc = fill_points(it, &sm->L, out_sign, &b, &keys, &nkeys);
    band_free(&b);
    if (rc == 0 && nkeys)
        qsort(keys, nkeys, sizeof *keys, cmp_u64);
    size_t before = sim->p->n;
    for (size_t k = 0; rc == 0 && k < nkeys; k++) {
        long idx[3];
        lat_unkey(keys[k], idx);
        double x[3];
        for (int a = 0; a < 3; a++)
            x[a] = lat_coord(&sm->L, a, idx[a]);
        rc = mf_particles_add(sim->p, MF_FLUID, x, s.velocity, NULL);
    }
    free(keys);
    MF_CALL(rc);
    if (sim->p->n == before)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: %s holds no lattice point (l0 = %g m)%s", it->where, it->mesh.name,
                        sm->L.l0, sm->L.dim == 2 ? "; in 2-D the surface must cross z = 0" : "");
    if (fluid_field >= 0) {
        int32_t *f = mf_particles_fi(sim->p, fluid_field);
        for (size_t i = before; i < sim->p->n; i++)
            f[i] = fid;
    }
    if (s.scalars)
        MF_CALL(mf_scene_block_scalars(sim, s.scalars, before, sim->p->n,
                                       resolved ? mf_dict_set_subdict(resolved, "scalars")
                                                : NULL));
    mf_log_printf(sm->log, MF_LOG_NORMAL,
                  "Fluid block mesh '%s': %s, %zu triangles, volume %g m^3: %zu particles of %s\n",
                  name, it->mesh.name, it->mesh.ntris, fabs(it->rep.volume), sim->p->n - before,
                  s.fluid);
    return 0;
}
