/* mps_periodic.c: a periodic x axis for the MPS solver, by image particles.
 *
 * Cheapest correct way in this code: every operator, the PPE assembly and
 * the force modules compute pair vectors from positions directly, so a
 * minimum-image convention would touch all of them. Images touch none: for
 * the duration of a step, particles within the largest operator radius of a
 * periodic face get a copy shifted by -+L, appended after the owned
 * particles (the halo slots [n_owned, n) of mf_particles, which every
 * operator already reads as neighbours and never updates). The solver keeps
 * the images' masks, PPE rows and pressures equal to their owners'
 * (mps_periodic_sync, mps_owner), so an image is the same unknown as its
 * owner and the matrices stay symmetric. Images are rebuilt at each grid
 * build (at r^n and at r*) and removed at the end of the step, so the
 * writer, the watch and the emitters never see them. Fluid leaving the
 * period is wrapped back in.
 *
 * Set up: `MPSCoeffs { periodicLength L; periodicOrigin x0; }`, the walls
 * open at xmin and xmax and every particle inside [x0, x0 + L) (the lattice
 * of a box of length L fits exactly when L is a multiple of l0). L must
 * exceed twice the largest radius, so that no pair meets twice. Without a
 * period none of this runs (d->periodic is NULL: one test per phase).
 */
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mps.h"

typedef struct mps_periodic {
    double x0, L, rmax;
    size_t *owner; /* image k -> owned particle */
    size_t cap;
} mps_periodic;

int mps_periodic_create(mps_data *d, mf_sim *sim, double rmax)
{
    const double L = d->s.periodic_length, x0 = d->s.periodic_origin;
    if (L <= 2.0 * rmax)
        return MF_ERROR(MF_ERR_INPUT,
                        "MPSCoeffs: periodicLength %g m must exceed twice the largest operator "
                        "radius (%g m): make the periodic box longer",
                        L, 2.0 * rmax);
    const mf_particles *p = sim->p;
    const double tol = 1e-9 * L;
    for (size_t i = 0; i < p->n_owned; i++) {
        double x = p->pos[3 * i];
        if (x < x0 - tol || x >= x0 + L + tol)
            return MF_ERROR(MF_ERR_INPUT,
                            "MPSCoeffs: periodicOrigin %g, periodicLength %g: a %s particle (id "
                            "%lld) is at x = %g, outside [%g, %g): open the walls at xmin and "
                            "xmax (walls { ... open (xmin xmax); }) and keep the blocks inside",
                            x0, L, mf_particle_kind_name(p->kind[i]), (long long)p->id[i], x,
                            x0, x0 + L);
    }
    mps_periodic *pp = calloc(1, sizeof *pp);
    if (!pp)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    pp->x0 = x0;
    pp->L = L;
    pp->rmax = rmax;
    d->periodic = pp;
    mf_log_printf(sim->log, MF_LOG_NORMAL, "Periodic in x: [%g, %g), images within %g m\n", x0,
                  x0 + L, rmax);
    return 0;
}

void mps_periodic_destroy(mps_periodic *pp)
{
    if (!pp)
        return;
    free(pp->owner);
    free(pp);
}

static void wrap(const mps_periodic *pp, mf_particles *p)
{
    const double x0 = pp->x0, x1 = pp->x0 + pp->L;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        double *x = &p->pos[3 * i];
        while (*x < x0)
            *x += pp->L;
        while (*x >= x1)
            *x -= pp->L;
    }
}

int mps_periodic_begin(mps_data *d, mf_sim *sim)
{
    if (d->rho || d->mu)
        return MF_ERROR(MF_ERR_INPUT, "periodicLength: a periodic axis needs solver MPS "
                                      "(one fluid)");
    mf_particles *p = sim->p;
    p->n = p->n_owned;
    d->image_owner = NULL;
    wrap(d->periodic, p);
    return 0;
}

void mps_periodic_end(mps_data *d, mf_sim *sim)
{
    mf_particles *p = sim->p;
    p->n = p->n_owned;
    d->image_owner = NULL;
    wrap(d->periodic, p);
}

int mps_periodic_add_images(mps_data *d, mf_sim *sim)
{
    mps_periodic *pp = d->periodic;
    mf_particles *p = sim->p;
    const size_t n = p->n_owned;
    const double lo = pp->x0 + pp->rmax, hi = pp->x0 + pp->L - pp->rmax;
    size_t count = 0;
    for (size_t i = 0; i < n; i++)
        count += (p->pos[3 * i] < lo) + (p->pos[3 * i] >= hi);
    if (count > pp->cap) {
        size_t cap = count + count / 4 + 64;
        if (mf_resize(&pp->owner, cap, sizeof *pp->owner))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu periodic images", count);
        pp->cap = cap;
    }
    MF_CALL(mf_particles_reserve(p, n + count));
    MF_CALL(mps_reserve(d, n + count));
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        const double x = p->pos[3 * i];
        if (x < lo)
            pp->owner[k++] = i;
        if (x >= hi)
            pp->owner[k++] = i;
    }
    for (size_t m = 0; m < count; m++) {
        const size_t i = pp->owner[m], j = n + m;
        /* Near the lower face: the image is up by L; near the upper, down
         * (L > 2 rmax: never both). */
        const double shift = p->pos[3 * i] < lo ? pp->L : -pp->L;
        memcpy(&p->pos[3 * j], &p->pos[3 * i], 3 * sizeof(double));
        p->pos[3 * j] += shift;
        memcpy(&p->vel[3 * j], &p->vel[3 * i], 3 * sizeof(double));
        p->kind[j] = p->kind[i];
        p->id[j] = p->id[i];
        for (int f = 0; f < p->nfields; f++) {
            const mf_field *fd = &p->field[f];
            const size_t bytes =
                (size_t)fd->ncomp * (fd->type == MF_FIELD_DOUBLE ? sizeof(double) : sizeof(int32_t));
            memcpy((char *)fd->data + j * bytes, (const char *)fd->data + i * bytes, bytes);
        }
        d->is_fluid[j] = d->is_fluid[i];
        d->not_dummy[j] = d->not_dummy[i];
        d->in_ppe[j] = d->in_ppe[i];
        d->dirichlet[j] = d->dirichlet[i];
    }
    p->n = n + count;
    d->image_owner = pp->owner;
    return 0;
}

void mps_periodic_sync(const mps_data *d, const mf_particles *p, void *values, size_t size)
{
    if (!d->image_owner)
        return;
    char *v = values;
    for (size_t j = p->n_owned; j < p->n; j++)
        memcpy(v + j * size, v + d->image_owner[j - p->n_owned] * size, size);
}
