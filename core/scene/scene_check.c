/* scene_check.c: refuse, before step 0, a scene the run would refuse at
 * step 0 or that makes no sense, naming the entry of constant/geometry (its
 * file:line:col) where a shape can say which one:
 *  - particles closer than l0/2 (blocks that overlap each other, a block
 *    reaching into a wall, an obstacle inside the fluid): the run would
 *    start with a pressure spike (silent nonsense);
 *  - a fluid particle past a closed face of a wall box (the watch's
 *    throughWall criterion, mf_scene_past_wall, would stop the run at step 0);
 *  - no fluid, and no inlet or nozzle to bring any (nothing to compute);
 *  - an inlet, outlet or nozzle that does not reach the domain the walls
 *    enclose (its fluid would never enter). */
#include <math.h>
#include <string.h>

#include "mf_emitter.h"
#include "mf_error.h"
#include "mf_neighbours.h"
#include "mf_pairs.h"
#include "mf_scene.h"
#include "mf_walls.h"

bool mf_scene_past_wall(const mf_sim *sim, size_t i, size_t *box, int *axis, int *side)
{
    const double *x = &sim->p->pos[3 * i];
    for (size_t b = 0; sim->walls && b < sim->walls->n; b++)
        if (mf_wall_passed(&sim->walls->w[b], sim->l0, sim->dim, x, axis, side)) {
            *box = b;
            return true;
        }
    return false;
}

size_t mf_scene_tank_number(const mf_sim *sim, size_t wall)
{
    size_t k = 0;
    for (size_t b = 0; b <= wall && b < sim->walls->n; b++)
        k += sim->walls->w[b].shape == MF_SOLID_TANK;
    return k;
}

/* ---- which entry of the geometry a point belongs to ---------------------- */

static bool vector_of(const mf_dict *d, const char *key, double v[3])
{
    bool ok = mf_dict_find(d, key) && mf_dict_get_vector(d, key, v) == 0;
    mf_error_clear();
    return ok;
}

/* Does entry d (a fluid block, wall, inlet...) hold point x? Boxes by their
 * corners (walls with their layers), spheres by their radius; meshes cannot
 * say (their files are not kept): false. */
static bool entry_holds(const mf_dict *d, const double x[3], int dim, double margin)
{
    double mn[3], mx[3], c[3], r = 0;
    if (vector_of(d, "min", mn) && vector_of(d, "max", mx)) {
        for (int a = 0; a < dim; a++)
            if (x[a] < mn[a] - margin || x[a] > mx[a] + margin)
                return false;
        return true;
    }
    if (vector_of(d, "centre", c) && mf_dict_get_number_or(d, "radius", 0, &r) == 0 && r > 0) {
        double d2 = 0;
        for (int a = 0; a < dim; a++)
            d2 += (x[a] - c[a]) * (x[a] - c[a]);
        return d2 <= (r + margin) * (r + margin);
    }
    mf_error_clear();
    return false;
}

/* "file:line:col: fluid block 'column'" of the entry of `group` holding x,
 * or of the group itself (or the geometry) when none can be told. */
static const char *locate(const mf_dict *geometry, const char *group, const char *what,
                          const double x[3], const mf_sim *sim, char *buf, size_t len)
{
    const mf_dict *g = mf_dict_subdict(geometry, group);
    char where[512];
    const double margin = 4 * sim->l0; /* walls: their layers outside the region */
    for (size_t k = 0; g && k < g->n; k++) {
        const mf_entry *e = g->entries[k];
        if (e->n == 1 && e->items[0]->kind == MF_VAL_DICT &&
            entry_holds(e->items[0]->dict, x, sim->dim, strcmp(group, "walls") ? 0.5 * sim->l0 : margin)) {
            snprintf(buf, len, "%s: %s '%s'", mf_loc_str(e->loc, where, sizeof where), what,
                     e->key);
            return buf;
        }
    }
    snprintf(buf, len, "%s: %s", mf_loc_str(g ? g->loc : geometry->loc, where, sizeof where),
             g ? group : "the geometry");
    return buf;
}

static const char *group_of(int kind)
{
    switch (kind) {
    case MF_FLUID: return "fluidBlocks";
    case MF_INLET: return "inlets";
    case MF_OUTLET: return "outlets";
    default: return "walls";
    }
}

static const char *what_of(const char *group)
{
    if (strcmp(group, "fluidBlocks") == 0) return "fluid block";
    if (strcmp(group, "inlets") == 0) return "inlet";
    if (strcmp(group, "outlets") == 0) return "outlet";
    return "wall";
}

/* ---- the checks ------------------------------------------------------------ */

typedef struct overlap_acc {
    size_t pairs, first_i, first_j;
} overlap_acc;

/* Each pair once (j > i); the first in (i, list) order is named. */
static inline bool overlap_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    (void)ctx;
    overlap_acc *a = acc;
    if (pr->j > pr->i && a->pairs++ == 0) {
        a->first_i = pr->i;
        a->first_j = pr->j;
    }
    return true;
}


int mf_scene_check_overlap_in(const mf_dict *geometry, const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    if (p->n < 2)
        return 0;
    const double radius = 0.5 * sim->l0;
    mf_neighbours *nb = NULL;
    MF_CALL(mf_neighbours_create(&nb));
    int h = 0;
    mf_pairs v;
    int rc = mf_neighbours_request(nb, radius, radius, &h);
    if (rc == 0)
        rc = mf_neighbours_pairs(nb, p, h, &v);
    overlap_acc acc = {0, 0, 0};
    /* Every particle: the scene has no halos yet. */
    for (size_t i = 0; rc == 0 && i < p->n; i++)
        mf_pairs_row_r2(&v, i, NULL, overlap_pair, NULL, &acc);
    mf_neighbours_destroy(nb);
    MF_CALL(rc);
    if (acc.pairs == 0)
        return 0;
    const size_t pairs = acc.pairs, first_i = acc.first_i, first_j = acc.first_j;
    const double *a = &p->pos[3 * first_i], *b = &p->pos[3 * first_j];
    char here[700] = "constant/geometry", there[700] = "";
    if (geometry) {
        const char *ga = group_of(p->kind[first_i]), *gb = group_of(p->kind[first_j]);
        locate(geometry, ga, what_of(ga), a, sim, here, sizeof here);
        /* A wall particle that no wall box holds is a mesh's: an obstacle or a mesh wall. */
        locate(geometry, gb, what_of(gb), b, sim, there, sizeof there);
        if (strcmp(gb, "walls") == 0 && !strstr(there, "wall '") &&
            mf_dict_subdict(geometry, "obstacles"))
            locate(geometry, "obstacles", "obstacle", b, sim, there, sizeof there);
    }
    return MF_ERROR(MF_ERR_INPUT,
                    "%s: %zu pairs of particles start closer than l0/2 = %g m, e.g. a %s particle "
                    "at (%g %g %g) and a %s particle at (%g %g %g)%s%s: do two fluid blocks "
                    "overlap, or does a block reach into a wall or an obstacle?",
                    here, pairs, radius, mf_particle_kind_name(p->kind[first_i]), a[0], a[1],
                    a[2], mf_particle_kind_name(p->kind[first_j]), b[0], b[1], b[2],
                    there[0] ? " of " : "", there);
}

int mf_scene_check_overlap(const mf_sim *sim)
{
    return mf_scene_check_overlap_in(NULL, sim);
}

static int check_fluid_in_walls(const mf_dict *geometry, const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    static const char *const faces[3][2] = {{"xmin", "xmax"}, {"ymin", "ymax"}, {"zmin", "zmax"}};
    for (size_t i = 0; i < p->n_owned; i++) {
        size_t b;
        int a, s;
        if (p->kind[i] != MF_FLUID || !mf_scene_past_wall(sim, i, &b, &a, &s))
            continue;
        const double *x = &p->pos[3 * i];
        char where[700];
        const mf_wall *w = &sim->walls->w[b];
        if (w->shape != MF_SOLID_TANK)
            continue; /* check_obstacles says more */
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: fluid at (%g %g %g) is outside wall box %zu (%g %g %g) to (%g %g %g), "
                        "past its %s face: the run would stop at step 0 (throughWall). Move the "
                        "block inside the walls, or open that face",
                        locate(geometry, "fluidBlocks", "fluid block", x, sim, where, sizeof where),
                        x[0], x[1], x[2], mf_scene_tank_number(sim, b), w->min[0], w->min[1],
                        w->min[2], w->max[0], w->max[1], w->max[2], faces[a][s]);
    }
    return 0;
}

/* Fluid closer than l0/2 to an obstacle's surface, or inside it: refused,
 * naming both entries (a block that reaches into a body starts with a
 * pressure spike, or with fluid inside the body). Polygon obstacles are
 * checked through their particles (mf_scene_check_overlap_in), or, without
 * particles, through their surface. */
static int check_obstacles(const mf_dict *geometry, const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    for (size_t b = 0; sim->walls && b < sim->walls->n; b++) {
        const mf_wall *w = &sim->walls->w[b];
        if (!w->obstacle || (w->shape == MF_SOLID_MESH && !w->mesh))
            continue;
        size_t count = 0, first = 0;
        double dmin = INFINITY;
        for (size_t i = 0; i < p->n_owned; i++) {
            if (p->kind[i] != MF_FLUID)
                continue;
            const double d = mf_wall_distance(w, &p->pos[3 * i], NULL);
            if (d < 0.5 * sim->l0 * (1 - 1e-6)) {
                if (count++ == 0 || d < dmin) {
                    first = i;
                    dmin = d;
                }
            }
        }
        if (count == 0)
            continue;
        const double *x = &p->pos[3 * first];
        char where[700];
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: %zu fluid particles overlap obstacle '%s' (%s), e.g. at (%g %g %g), "
                        "%s %g m: fluid must stay l0/2 = %g m outside an obstacle. Move or "
                        "shrink the block, or move the obstacle",
                        locate(geometry, "fluidBlocks", "fluid block", x, sim, where, sizeof where),
                        count, w->name, w->where, x[0], x[1], x[2],
                        dmin < 0 ? "inside it by" : "from its surface,", fabs(dmin),
                        0.5 * sim->l0);
    }
    return 0;
}

static bool has_entries(const mf_dict *geometry, const char *group)
{
    const mf_dict *g = mf_dict_subdict(geometry, group);
    return g && g->n > 0;
}

static int check_some_fluid(const mf_dict *geometry, const mf_sim *sim)
{
    size_t counts[MF_NKINDS];
    mf_particles_count_kinds(sim->p, counts);
    if (counts[MF_FLUID] > 0 || has_entries(geometry, "inlets") ||
        has_entries(geometry, "emitters"))
        return 0;
    const mf_dict *fb = mf_dict_subdict(geometry, "fluidBlocks");
    char where[512];
    return MF_ERROR(MF_ERR_INPUT,
                    "%s: the scene has no fluid: %s, and no inlet or emitter adds any. Add a "
                    "block, e.g. fluidBlocks { column { type box; min (0 0 0); max (0.1 0.2 0); "
                    "fluid water; } }",
                    mf_loc_str(fb ? fb->loc : geometry->loc, where, sizeof where),
                    fb ? "fluidBlocks holds no block" : "there is no fluidBlocks entry");
}

/* The domain: the bounding box of the wall and dummy particles (box and mesh
 * walls alike) and of the tanks, grown by one spacing. */
static bool domain_of(const mf_sim *sim, double mn[3], double mx[3])
{
    const mf_particles *p = sim->p;
    bool any = false;
    for (int a = 0; a < 3; a++) {
        mn[a] = a < sim->dim ? INFINITY : 0;
        mx[a] = a < sim->dim ? -INFINITY : 0;
    }
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_WALL && p->kind[i] != MF_DUMMY)
            continue;
        any = true;
        for (int a = 0; a < sim->dim; a++) {
            mn[a] = fmin(mn[a], p->pos[3 * i + a] - sim->l0);
            mx[a] = fmax(mx[a], p->pos[3 * i + a] + sim->l0);
        }
    }
    for (size_t b = 0; sim->walls && b < sim->walls->n; b++) {
        const mf_wall *w = &sim->walls->w[b];
        if (w->shape != MF_SOLID_TANK)
            continue;
        any = true;
        for (int a = 0; a < sim->dim; a++) {
            mn[a] = fmin(mn[a], w->min[a] - sim->l0);
            mx[a] = fmax(mx[a], w->max[a] + sim->l0);
        }
    }
    return any;
}

static int check_sources_reach(const mf_dict *geometry, const mf_sim *sim)
{
    double dmn[3], dmx[3];
    if (!domain_of(sim, dmn, dmx))
        return 0; /* no walls: no domain to leave */
    static const char *const groups[] = {"inlets", "outlets", "emitters"};
    static const char *const whats[] = {"inlet", "outlet", "nozzle"};
    char where[512];
    for (int g = 0; g < 3; g++) {
        const mf_dict *grp = mf_dict_subdict(geometry, groups[g]);
        for (size_t k = 0; grp && k < grp->n; k++) {
            const mf_entry *e = grp->entries[k];
            if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT)
                continue;
            const mf_dict *d = e->items[0]->dict;
            double mn[3], mx[3];
            if (g < 2) {
                if (!vector_of(d, "min", mn) || !vector_of(d, "max", mx))
                    continue;
            } else if (vector_of(d, "centre", mn)) {
                memcpy(mx, mn, sizeof mx);
            } else {
                continue;
            }
            bool meets = true;
            for (int a = 0; a < sim->dim; a++)
                meets = meets && mx[a] >= dmn[a] && mn[a] <= dmx[a];
            if (meets)
                continue;
            char span[200];
            if (g < 2)
                snprintf(span, sizeof span, "(%g %g %g) to (%g %g %g)", mn[0], mn[1], mn[2],
                         mx[0], mx[1], mx[2]);
            else
                snprintf(span, sizeof span, "(%g %g %g)", mn[0], mn[1], mn[2]);
            return MF_ERROR(MF_ERR_INPUT,
                            "%s: %s '%s' at %s does not reach the domain the walls span, (%g %g "
                            "%g) to (%g %g %g): its fluid would never enter",
                            mf_loc_str(e->loc, where, sizeof where), whats[g], e->key, span,
                            dmn[0], dmn[1], dmn[2], dmx[0], dmx[1], dmx[2]);
        }
    }
    return 0;
}

int mf_scene_check_start(const mf_dict *geometry, const mf_sim *sim)
{
    MF_CALL(check_obstacles(geometry, sim));
    MF_CALL(mf_scene_check_overlap_in(geometry, sim));
    MF_CALL(check_some_fluid(geometry, sim));
    MF_CALL(check_fluid_in_walls(geometry, sim));
    MF_CALL(check_sources_reach(geometry, sim));
    return 0;
}
