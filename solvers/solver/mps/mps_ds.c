/* mps_ds.c: dynamic stabilisation after the pressure correction (Tsuruta,
 * Khayyer & Gotoh 2013, "A short note on Dynamic Stabilization of Moving
 * Particle Semi-implicit method", Computers & Fluids 82, 158-164; MPSCoeffs
 * `dynamicStabilisation`, docs/notes/mps.md "rest").
 *
 * A pair (i, j) closer than d = dsDistance l0 whose relative velocity along
 * e_ij = r_ij / |r_ij| approaches (v_n = (u_j - u_i) . e_ij < 0) gets the
 * relative velocity along e_ij that takes it back to d in one step,
 * v_n' = (d - |r_ij|) / dt: the pair's change dV = v_n' - v_n is shared by
 * mass, i takes -m_j / (m_i + m_j) dV e_ij (all of it against a wall or
 * dummy particle, which does not move), so the pair's momentum is kept.
 * Pairs that separate, or are farther than d, are left alone. Every pair of
 * i is read at the corrected velocities u (one Jacobi pass, as the paper's
 * sum over j); positions follow the velocity change, r += dt du, as in the
 * correction (eq. 17). Read from the paper's description, not its text
 * (not at hand): the paper writes the same pair velocity as a pressure
 * P_ij^DS in eq. 5's form; here it is applied as the velocity itself. */
#include <math.h>

#include "mf_error.h"
#include "mf_pairs.h"
#include "mps.h"

typedef struct {
    const mf_pairs *v;
    const uint8_t *movable; /* the fluid: the others take no share */
    const double *rho;      /* per particle, or NULL: one density */
    const double *vel;
    double d, dt;
    double *out;            /* 3 per particle: du */
} ds_ctx;

/* One pair of the DS (see the top): adds i's share of dV to acc (du_i). */
static inline bool ds_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const ds_ctx *c = ctx;
    if (!(pr->r2 > 0))
        return true;
    const double len = pr->len, *r = pr->r;
    const double *ui = c->vel + 3 * pr->i, *uj = c->vel + 3 * pr->j;
    const double vn = ((uj[0] - ui[0]) * r[0] + (uj[1] - ui[1]) * r[1] +
                       (uj[2] - ui[2]) * r[2]) / len;
    if (!(vn < 0))
        return true;
    const double dV = (c->d - len) / c->dt - vn; /* > 0: len < d, vn < 0 */
    const size_t i = pr->i, j = pr->j;
    const double share = !c->movable[j] ? 1.0
                         : c->rho       ? c->rho[j] / (c->rho[i] + c->rho[j])
                                        : 0.5;
    double *du = acc;
    for (int q = 0; q < 3; q++)
        du[q] -= share * dV * r[q] / len;
    return true;
}

static void ds_row(const void *ctx, size_t i)
{
    const ds_ctx *c = ctx;
    double du[3] = {0, 0, 0};
    mf_pairs_row(c->v, i, NULL, ds_pair, c, du);
    for (int q = 0; q < 3; q++)
        c->out[3 * i + q] = du[q];
}

int mps_dynamic_stabilisation(mps_data *d, mf_sim *sim, double dt)
{
    if (!d->s.dynamic_stabilisation)
        return 0;
    mf_particles *p = sim->p;
    if (d->halo) /* the copies' corrected motion */
        MF_CALL(mps_halo_sync_motion(d, sim));
    mf_pairs v;
    MF_CALL(mps_pairs(d, sim, d->h_ds, &v));
    double *du = d->grad; /* scratch: the gradient is applied */
    const ds_ctx c = {&v, d->is_fluid, d->rho, p->vel, d->s.ds_distance * sim->l0, dt, du};
    mf_pairs_each(&v, d->is_fluid, ds_row, &c);
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!d->is_fluid[i])
            continue;
        for (int q = 0; q < 3; q++) {
            p->vel[3 * i + q] += du[3 * i + q];
            p->pos[3 * i + q] += dt * du[3 * i + q];
        }
    }
    return 0;
}
