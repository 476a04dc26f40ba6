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
#include "mf_neighbours.h"

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
    mf_grid grid;
    mf_nlist nl;
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
    drag_data *d = data;
    if (!d)
        return;
    mf_grid_free(&d->grid);
    mf_nlist_free(&d->nl);
    free(d);
}

static int drag_create(const void *settings, mf_sim *sim, void **data)
{
    drag_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    d->s = *(const drag_settings *)settings;
    d->coef = 3.0 * d->s.cd * d->s.alpha / (4.0 * d->s.diameter * sim->l0);
    d->re = d->s.radius * sim->l0;
    mf_grid_init(&d->grid);
    mf_nlist_init(&d->nl);
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "drag: C_D = %g, alpha = %g, d_p = %g m, u_bar within %g l0%s\n", d->s.cd,
                  d->s.alpha, d->s.diameter * sim->l0, d->s.radius,
                  d->s.walls ? " (walls included)" : "");
    *data = d;
    return 0;
}

static int drag_accumulate(void *data, const mf_sim *sim, double *acc)
{
    drag_data *d = data;
    const mf_particles *p = sim->p;
    const mf_nlist *nl = sim->neighbours;
    if (!nl || nl->radius < d->re || nl->n < p->n_owned) {
        MF_CALL(mf_grid_build(&d->grid, p, d->re));
        MF_CALL(mf_nlist_build(&d->nl, &d->grid, p, d->re));
        nl = &d->nl;
    }
    const double re = d->re;
    const long np = (long)p->n_owned;
#pragma omp parallel for schedule(static)
    for (long i = 0; i < np; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        double sw = 0, su[3] = {0, 0, 0};
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            size_t j = nl->j[k];
            bool fluid = p->kind[j] == MF_FLUID;
            if (!fluid && !(d->s.walls && p->kind[j] == MF_WALL))
                continue;
            double r2 = 0;
            for (int c = 0; c < 3; c++) {
                double dx = p->pos[3 * j + c] - p->pos[3 * i + c];
                r2 += dx * dx;
            }
            double w = mf_weight(sqrt(r2), re);
            sw += w;
            if (fluid)
                for (int c = 0; c < 3; c++)
                    su[c] += w * p->vel[3 * j + c];
        }
        if (!(sw > 0))
            continue;
        double du[3], a[3];
        for (int c = 0; c < 3; c++)
            du[c] = su[c] / sw - p->vel[3 * i + c]; /* eq. 41: u_bar - u */
        drag_law(d->coef, du, a);
        for (int c = 0; c < 3; c++)
            acc[3 * i + c] += a[c];
    }
    return 0;
}

double mf_drag_radius(const void *data)
{
    return ((const drag_data *)data)->re;
}

const mf_force_ops mf_force_drag = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "drag",
             "drag toward the neighbourhood's mean velocity, a permeable layer (Appendix B)",
             drag_params, DRAG_NPARAMS, sizeof(drag_settings)},
    .create = drag_create,
    .accumulate = drag_accumulate,
    .destroy = drag_destroy,
};
