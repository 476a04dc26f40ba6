/* scene_estimate.c: how many particles a geometry will make, before any is
 * made (the memory budget of mf_scene_build_budgeted). The lattice counts of
 * boxes are those the builder places (scene.c, emitter.c); spheres and
 * meshes are estimated from their volume, area or bounding box. Sums are in
 * double: a spacing of 1e-9 m over a metre must not overflow a count. */
#include <math.h>
#include <string.h>

#include "mf_error.h"
#include "mf_scene.h"
#include "mf_trimesh.h"
#include "scene_lattice.h"

/* Lattice points in [a, b] along one axis, as the builders place them. */
static double span(double a, double b, double l0)
{
    double n = mf_lattice_span(a, b, l0);
    return n > 0 ? n : 0;
}

static bool read_box(const mf_dict *d, double mn[3], double mx[3])
{
    bool ok = mf_dict_get_vector(d, "min", mn) == 0 && mf_dict_get_vector(d, "max", mx) == 0;
    mf_error_clear();
    return ok;
}

static double box_points(const double mn[3], const double mx[3], int dim, double l0)
{
    double n = 1;
    for (int a = 0; a < dim; a++)
        n *= span(mn[a], mx[a], l0);
    return n;
}

static double fluid_block(const mf_dict *d, int dim, double l0)
{
    const char *type = "box";
    if (mf_dict_get_word_or(d, "type", "box", &type) != 0) {
        mf_error_clear();
        return 0;
    }
    if (strcmp(type, "sphere") == 0) {
        double r = 0;
        if (mf_dict_get_number(d, "radius", &r) != 0 || !(r > 0)) {
            mf_error_clear();
            return 0;
        }
        double m = ceil(r / l0);
        return pow(2 * m, dim) * (dim == 3 ? M_PI / 6 : M_PI / 4);
    }
    double mn[3], mx[3], amp = 0;
    if (!read_box(d, mn, mx))
        return 0;
    if (mf_dict_get_number_or(d, "topAmplitude", 0, &amp) == 0)
        mx[1] += fabs(amp);
    mf_error_clear();
    return box_points(mn, mx, dim, l0);
}

/* The box and its layers on the closed faces, less the inside. */
static double wall_box(const mf_dict *d, int dim, double l0)
{
    double mn[3], mx[3], w = 1, dl = 2;
    if (!read_box(d, mn, mx))
        return 0;
    if (mf_dict_get_number_or(d, "wallLayers", 1, &w) != 0 ||
        mf_dict_get_number_or(d, "dummyLayers", 2, &dl) != 0) {
        mf_error_clear();
        return 0;
    }
    double inner = 1, outer = 1;
    for (int a = 0; a < dim; a++) {
        double n = span(mn[a], mx[a], l0);
        inner *= n;
        outer *= n + 2 * (w + dl); /* open faces only make it smaller */
    }
    return outer - inner;
}

/* What a nozzle adds over the run: its rate (or its opening times its
 * speed) over the time it is open. */
static double nozzle(const mf_dict *d, int dim, double l0, double end_time)
{
    double rate = 0, diameter = 0, start = 0, end = 1e30, v[3] = {0, 0, 0};
    if (mf_dict_get_number_or(d, "rate", 0, &rate) != 0 ||
        mf_dict_get_number_or(d, "start", 0, &start) != 0 ||
        mf_dict_get_number_or(d, "end", 1e30, &end) != 0 ||
        mf_dict_get_number(d, "diameter", &diameter) != 0 ||
        mf_dict_get_vector(d, "velocity", v) != 0) {
        mf_error_clear();
        return 0;
    }
    double speed = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(rate > 0))
        rate = speed * (dim == 3 ? M_PI * diameter * diameter / 4 : diameter);
    if (end_time > 0 && end > end_time)
        end = end_time;
    double open = end - start;
    return open > 0 && isfinite(open) ? rate * open / pow(l0, dim) : 0;
}

static double each(const mf_dict *geometry, const char *group, const mf_sim *sim,
                   double (*count)(const mf_dict *, int, double))
{
    const mf_dict *g = mf_dict_subdict(geometry, group);
    double n = 0;
    for (size_t k = 0; g && k < g->n; k++) {
        const mf_entry *e = g->entries[k];
        if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT ||
            mf_scene_entry_is_mesh(e->items[0]->dict))
            continue; /* meshes: mf_scene_meshes_estimate */
        n += count(e->items[0]->dict, sim->dim, sim->l0);
    }
    return n;
}

static double inlet_box(const mf_dict *d, int dim, double l0)
{
    double mn[3], mx[3];
    return read_box(d, mn, mx) ? box_points(mn, mx, dim, l0) : 0;
}

double mf_scene_estimate_particles(const mf_dict *geometry, const mf_sim *sim,
                                   const struct mf_scene_meshes *meshes)
{
    double n = each(geometry, "fluidBlocks", sim, fluid_block) +
               each(geometry, "walls", sim, wall_box) + each(geometry, "inlets", sim, inlet_box) +
               each(geometry, "outlets", sim, inlet_box);
    const mf_dict *em = mf_dict_subdict(geometry, "emitters");
    for (size_t k = 0; em && k < em->n; k++) {
        const mf_entry *e = em->entries[k];
        if (e->n == 1 && e->items[0]->kind == MF_VAL_DICT)
            n += nozzle(e->items[0]->dict, sim->dim, sim->l0, sim->end_time);
    }
    return n + mf_scene_meshes_estimate(meshes);
}
