/* drag.c: the drag force of the paper's Appendix B, between a fluid
 * particle and its neighbourhood (a permeable layer):
 *   (40) f_i = (3 C_D / (4 d_p)) alpha |u_bar_i - u_i| (u_bar_i - u_i)
 *   (41) u_bar_i = sum_j u_j w(|r_ij|) / sum_j w(|r_ij|)
 * C_D the drag coefficient, alpha a model constant, d_p the particle
 * diameter; f_i is an acceleration (m/s^2). The neighbours j are the fluid
 * particles within the radius and, with includeWalls, the wall particles
 * (at rest), so that a fluid layer passing along or through a wall is held
 * back. The sum runs over j != i; a particle with no neighbour feels none. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "forces.h"
#include "mf_error.h"
#include "mf_kernel.h"
#include "mf_pairs.h"

typedef struct drag_settings {
    double cd, alpha, diameter, radius;
    bool walls;
} drag_settings;

static const mf_param drag_params[] = {
    {"Cd", MF_PARAM_SCALAR, "1", 0, 1e6, NULL, offsetof(drag_settings, cd),
     "drag coefficient C_D (eq. 40)"},
    {"alpha", MF_PARAM_SCALAR, "1", 0, 1e6, NULL, offsetof(drag_settings, alpha),
     "model constant alpha (eq. 40)"},
    {"diameter", MF_PARAM_SCALAR, "1", 1e-6, 1e6, NULL, offsetof(drag_settings, diameter),
     "particle diameter d_p, in l0 (eq. 40)"},
    {"radius", MF_PARAM_SCALAR, "2.1", 1.01, 10, NULL, offsetof(drag_settings, radius),
     "radius of the neighbourhood average u_bar (eq. 41), in l0"},
    {"includeWalls", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL, offsetof(drag_settings, walls),
     "wall particles (u = 0) take part in u_bar"},
};
#define DRAG_NPARAMS (sizeof drag_params / sizeof drag_params[0])

typedef struct drag_data {
    drag_settings s;
    double coef; /* 3 C_D alpha / (4 d_p) */
    double re;   /* m */
    int pairs;   /* neighbour request (sim->neighbours) */
} drag_data;

/* eq. 40 for one particle: the acceleration toward the neighbourhood's velocity. */
static inline void drag_law(double coef, const double du[3], double out[3])
{
    double mag = sqrt(du[0] * du[0] + du[1] * du[1] + du[2] * du[2]);
    for (int c = 0; c < 3; c++)
        out[c] = coef * mag * du[c];
}

static void drag_destroy(void *data)
{
    free(data);
}

static int drag_create(const void *settings, mf_sim *sim, void **data)
{
    drag_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->s = *(const drag_settings *)settings;
    d->coef = 3.0 * d->s.cd * d->s.alpha / (4.0 * d->s.diameter * sim->l0);
    d->re = d->s.radius * sim->l0;
    /* Shared: the solver's lists where they reach (their order, too). */
    int rc = mf_neighbours_request(sim->neighbours, d->re, 0, &d->pairs);
    if (rc != 0) {
        free(d);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "drag: C_D = %g, alpha = %g, d_p = %g m, u_bar within %g l0%s\n", d->s.cd,
                  d->s.alpha, d->s.diameter * sim->l0, d->s.radius,
                  d->s.walls ? " (walls included)" : "");
    *data = d;
    return 0;
}

typedef struct drag_ctx {
    const drag_data *d;
    const mf_particles *p;
    const mf_pairs *v;
    double *acc;
} drag_ctx;

typedef struct drag_acc {
    double sw, su[3];
} drag_acc;

/* eq. 41's sums: w and w u_j over the fluid (and wall) neighbours. */
static inline bool drag_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const drag_ctx *c = ctx;
    drag_acc *a = acc;
    const mf_particles *p = c->p;
    const bool fluid = p->kind[pr->j] == MF_FLUID;
    if (!fluid && !(c->d->s.walls && p->kind[pr->j] == MF_WALL))
        return true;
    const double w = mf_weight(pr->len, c->d->re);
    a->sw += w;
    if (fluid)
        for (int q = 0; q < 3; q++)
            a->su[q] += w * p->vel[3 * pr->j + q];
    return true;
}

static void drag_row(const void *ctx, size_t i)
{
    const drag_ctx *c = ctx;
    const mf_particles *p = c->p;
    if (p->kind[i] != MF_FLUID)
        return;
    drag_acc a = {0, {0, 0, 0}};
    mf_pairs_row(c->v, i, NULL, drag_pair, c, &a);
    if (!(a.sw > 0))
        return;
    double du[3], f[3];
    for (int q = 0; q < 3; q++)
        du[q] = a.su[q] / a.sw - p->vel[3 * i + q]; /* eq. 41: u_bar - u */
    drag_law(c->d->coef, du, f);
    for (int q = 0; q < 3; q++)
        c->acc[3 * i + q] += f[q];
}

static int drag_accumulate(void *data, const mf_sim *sim, double *acc)
{
    drag_data *d = data;
    mf_pairs v;
    MF_CALL(mf_neighbours_pairs(sim->neighbours, sim->p, d->pairs, &v));
    const drag_ctx c = {d, sim->p, &v, acc};
    mf_pairs_each(&v, NULL, drag_row, &c);
    return 0;
}

const mf_force_ops mf_force_drag = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "drag",
             "drag toward the neighbourhood's mean velocity, a permeable layer (Appendix B)",
             drag_params, DRAG_NPARAMS, sizeof(drag_settings)},
    .create = drag_create,
    .accumulate = drag_accumulate,
    .destroy = drag_destroy,
};
