/* path_follow.c: a region of fluid that follows a path, a table of
 * positions against time (OpenFOAM's table habit):
 *
 *   pathFollow { shape sphere; centre (0.2 0.3 0); radius 0.08;
 *                path { table ((0 (0.2 0.3 0)) (1 (0.6 0.3 0))); } }
 *
 * The region is the shape as given, translated with the path: by P(t) -
 * P(t_0), t_0 the table's first time (P linear between entries, held at its
 * end values outside them). Its fluid is pulled along:
 *
 *   a_i = rate (P'(t) + gain (P(t) - X(t)) - u_i)   for fluid i in the region,
 *
 * X the centroid (mass-weighted) of the region's fluid: each particle's
 * velocity relaxed at `rate` toward the path's velocity corrected by the
 * centroid's lag. Against a steady acceleration g that the path does not
 * account for (gravity on a path that does not climb) the centroid settles
 * |g| / (rate gain) from the path. Without a table the region holds its
 * fluid's centroid at the shape's centre. X is a global sum
 * (control_allreduce_sum). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "control.h"
#include "force/forces.h"
#include "mf_error.h"

typedef struct path_settings {
    control_shape_settings region;
    const mf_dict *path;
    double rate, gain;
} path_settings;

static const mf_param path_params[] = {
    CONTROL_SHAPE_PARAMS(path_settings, region, "region shape (at the table's first time)"),
    {"path", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(path_settings, path),
     "{ table ((t0 (x y z)) (t1 (x y z)) ...); }: the centroid's positions against time, s and "
     "m (none: hold at the shape's centre)"},
    {"rate", MF_PARAM_SCALAR, "20", 0, 1e6, NULL, offsetof(path_settings, rate),
     "relaxation rate of the region's fluid velocity, 1/s"},
    {"gain", MF_PARAM_SCALAR, "5", 0, 1e6, NULL, offsetof(path_settings, gain),
     "centroid correction: velocity per metre of lag, 1/s"},
};
#define PATH_NPARAMS (sizeof path_params / sizeof path_params[0])

typedef struct path_data {
    path_settings s;
    control_shape region;
    size_t n;
    double *t, *x; /* n times, 3 n positions */
    int fluid_field;
} path_data;

static void path_destroy(void *data)
{
    path_data *d = data;
    if (!d)
        return;
    control_shape_free(&d->region);
    free(d->t);
    free(d->x);
    free(d);
}

/* The table: ((t (x y z)) ...), times strictly increasing. */
static int read_table(path_data *d, const mf_dict *path)
{
    char where[512];
    mf_entry *e = mf_dict_find(path, "table");
    if (!e || e->n != 1 || e->items[0]->kind != MF_VAL_LIST || e->items[0]->n == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: force pathFollow: path needs table ((t0 (x y z)) "
                        "(t1 (x y z)) ...);", mf_loc_str(path->loc, where, sizeof where));
    e->used = true;
    for (size_t k = 0; k < path->n; k++)
        if (strcmp(path->entries[k]->key, "table") != 0)
            return MF_ERROR(MF_ERR_INPUT, "%s: force pathFollow: unknown key '%s' in path "
                            "(valid: table)",
                            mf_loc_str(path->entries[k]->loc, where, sizeof where),
                            path->entries[k]->key);
    const mf_value *list = e->items[0];
    d->n = list->n;
    d->t = malloc(d->n * sizeof *d->t);
    d->x = malloc(3 * d->n * sizeof *d->x);
    if (!d->t || !d->x)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    for (size_t k = 0; k < d->n; k++) {
        const mf_value *row = list->items[k];
        if (row->kind != MF_VAL_LIST || row->n != 2)
            return MF_ERROR(MF_ERR_INPUT, "%s: force pathFollow: table row %zu must be "
                            "(t (x y z))", mf_loc_str(row->loc, where, sizeof where), k);
        MF_CALL(mf_value_number(row->items[0], "path time", &d->t[k]));
        MF_CALL(mf_value_vector(row->items[1], "path position", &d->x[3 * k]));
        if (k > 0 && !(d->t[k] > d->t[k - 1]))
            return MF_ERROR(MF_ERR_INPUT, "%s: force pathFollow: table times must increase "
                            "(%g after %g)", mf_loc_str(row->loc, where, sizeof where), d->t[k],
                            d->t[k - 1]);
    }
    return 0;
}

/* The region's centre, the default path's one point. */
static void shape_centre(const control_shape *sh, double c[3])
{
    for (int a = 0; a < 3; a++)
        c[a] = a < sh->dim ? 0.5 * (sh->lo[a] + sh->hi[a]) : 0;
}

static int path_create(const void *settings, mf_sim *sim, void **data)
{
    path_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->s = *(const path_settings *)settings;
    d->fluid_field = mf_particles_field_index(sim->p, "FluidId");
    int rc = control_shape_create(&d->s.region, "pathFollow", sim, &d->region);
    if (rc == 0 && d->region.type == CONTROL_POINT)
        rc = MF_ERROR(MF_ERR_INPUT, "force pathFollow: a point has no inside: use a box, sphere "
                      "or mesh region");
    if (rc == 0 && d->s.path) {
        rc = read_table(d, d->s.path);
    } else if (rc == 0) {
        d->n = 1;
        d->t = calloc(1, sizeof *d->t);
        d->x = calloc(3, sizeof *d->x);
        if (!d->t || !d->x)
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
        else
            shape_centre(&d->region, d->x);
    }
    if (rc != 0) {
        path_destroy(d);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "pathFollow: the %s region's fluid along %zu table points (t %g to %g s), "
                  "rate %g 1/s, gain %g 1/s\n", d->s.region.shape, d->n, d->t[0],
                  d->t[d->n - 1], d->s.rate, d->s.gain);
    *data = d;
    return 0;
}

/* P(t) and P'(t): linear between the entries, held outside them. */
static void path_at(const path_data *d, double t, double P[3], double V[3])
{
    size_t k = 0;
    while (k + 1 < d->n && d->t[k + 1] <= t)
        k++;
    if (k + 1 >= d->n || t < d->t[0]) {
        const size_t e = t < d->t[0] ? 0 : d->n - 1;
        for (int a = 0; a < 3; a++) {
            P[a] = d->x[3 * e + a];
            V[a] = 0;
        }
        return;
    }
    const double dt = d->t[k + 1] - d->t[k], f = (t - d->t[k]) / dt;
    for (int a = 0; a < 3; a++) {
        V[a] = (d->x[3 * (k + 1) + a] - d->x[3 * k + a]) / dt;
        P[a] = d->x[3 * k + a] + f * (d->x[3 * (k + 1) + a] - d->x[3 * k + a]);
    }
}

static int path_accumulate(void *data, const mf_sim *sim, double *acc)
{
    const path_data *d = data;
    const mf_particles *p = sim->p;
    double P[3], V[3], shift[3];
    path_at(d, sim->time, P, V);
    for (int a = 0; a < 3; a++)
        shift[a] = P[a] - d->x[a];
    /* The region's fluid: its mass and first moment, summed over the ranks. */
    double sum[4] = {0, 0, 0, 0};
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID || !control_shape_contains(&d->region, &p->pos[3 * i], shift))
            continue;
        const double m = mf_sim_particle_mass(sim, d->fluid_field, i);
        sum[0] += m;
        for (int a = 0; a < 3; a++)
            sum[1 + a] += m * p->pos[3 * i + a];
    }
    MF_CALL(control_allreduce_sum(sim, sum, 4));
    if (!(sum[0] > 0))
        return 0; /* the region is empty: nothing to pull */
    double target[3];
    for (int a = 0; a < 3; a++)
        target[a] = V[a] + d->s.gain * (P[a] - sum[1 + a] / sum[0]);
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID || !control_shape_contains(&d->region, &p->pos[3 * i], shift))
            continue;
        for (int q = 0; q < p->dim; q++)
            acc[3 * i + q] += d->s.rate * (target[q] - p->vel[3 * i + q]);
    }
    return 0;
}

/* Explicit relaxation: rate dt <= 1. */
static int path_stable_dt(void *data, const mf_sim *sim, double *dt)
{
    (void)sim;
    const path_data *d = data;
    *dt = d->s.rate > 0 ? 1 / d->s.rate : INFINITY;
    return 0;
}

const mf_force_ops mf_force_pathFollow = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "pathFollow",
             "a region of fluid pulled along a table of positions against time",
             path_params, PATH_NPARAMS, sizeof(path_settings)},
    .create = path_create,
    .accumulate = path_accumulate,
    .destroy = path_destroy,
    .stable_dt = path_stable_dt,
};
