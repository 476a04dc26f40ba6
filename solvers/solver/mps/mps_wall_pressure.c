/* mps_wall_pressure.c: the wall particles' pressure from the fluid's, by the
 * Neumann condition of a wall at rest, for the pressure gradient
 * (MPSCoeffs `wallPressure extrapolated`).
 *
 * Adami, Hu & Adams 2012 (J. Comput. Phys. 231, 7057-7075, eq. 27): a wall
 * particle w takes the weighted average of its fluid neighbours' pressure,
 * each continued hydrostatically to w,
 *     p_w = sum_f (p_f + rho f_f . (r_w - r_f)) w_wf / sum_f w_wf,
 * with f_f the force acceleration of f (gravity; a wall at rest, a_w = 0)
 * and w the gradient's weight (eq. 3). Why (docs/notes/mps.md, 2026-12-03):
 * with the pressure the PPE solves, a wall particle beside the top fluid
 * row is an unknown with p > 0 while the fluid beside it is on the surface
 * (p = 0): eq. 5 at the corner particle (p^_i = p_i = 0) then has a wall
 * neighbour's p_j with no fluid one to balance it and throws the particle
 * off the wall. The continued pressure is that of the fluid at the wall
 * particle's height, which is ~0 at the surface row. The PPE keeps its own
 * wall unknowns (their rows close the Laplacian); only the gradient reads
 * these. */
#include "mf_kernel.h"
#include "mps.h"

typedef struct {
    const double *p, *f, *pos;
    double rho, re;
} wall_pressure_ctx;

typedef struct {
    double sum_wp, sum_w;
} wall_pressure_acc;

static inline bool wall_pressure_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const wall_pressure_ctx *c = ctx;
    wall_pressure_acc *a = acc;
    const double w = mf_weight(pr->len, c->re);
    const double *f = &c->f[3 * pr->j];
    /* r_w - r_f = -r_ij (r_ij = r_j - r_i, i the wall particle) */
    const double cont = -c->rho * (f[0] * pr->r[0] + f[1] * pr->r[1] + f[2] * pr->r[2]);
    a->sum_wp += w * (c->p[pr->j] + cont);
    a->sum_w += w;
    return true;
}

void mps_wall_pressure_extrapolate(const mps_data *d, const mf_sim *sim, const mf_pairs *v,
                                   const double *pressure, double *out)
{
    const mf_particles *p = sim->p;
    const wall_pressure_ctx c = {pressure, d->acc, p->pos, sim->fluid[0].rho, d->k_grad.re};
    for (size_t i = 0; i < p->n; i++) {
        out[i] = pressure[i];
        if (d->is_fluid[i] || !d->not_dummy[i] || i >= p->n_owned)
            continue;
        wall_pressure_acc a = {0.0, 0.0};
        mf_pairs_row(v, i, d->is_fluid, wall_pressure_pair, &c, &a);
        out[i] = a.sum_w > 0 ? a.sum_wp / a.sum_w : 0.0;
        if (out[i] < 0)
            out[i] = 0; /* a wall pushes, never pulls (as the clipped wall sources) */
    }
}
