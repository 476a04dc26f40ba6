/* mps_halo.c: the copies the MPS phases read but do not own: other ranks'
 * particles on a -parallel run and the images of a periodic x axis, both
 * through one core halo (core/parallel/mf_halo.h).
 *
 * Images are the cheapest correct periodic axis in this code: every
 * operator, the PPE assembly and the force modules compute pair vectors
 * from positions directly, so a minimum-image convention would touch all of
 * them. Copies touch none: for the duration of a step, particles within the
 * largest operator radius of a rank's owned particles (of a periodic face,
 * shifted by -+L) are copied after the owned particles, into the slots
 * [n_owned, n) that every operator reads as neighbours and never updates.
 * The solver keeps the copies' masks, PPE rows (global numbers) and
 * pressures equal to their owners' (mps_halo_sync after each phase that
 * computes them), so a copy is the same unknown as its owner and the
 * matrices stay symmetric across ranks and across the period. Copies are
 * rebuilt at each neighbour build (at r^n and at r*) and dropped at the end
 * of the step, so the writer, the watch and the emitters never see them.
 *
 * At the first build of a step the particles that crossed into another
 * rank's region move there (with a new partition when the load has become
 * unbalanced: mf_parallel_balance), and fluid that left the period is
 * wrapped back in.
 *
 * Periodic set-up: `MPSCoeffs { periodicLength L; periodicOrigin x0; }`,
 * the walls open at xmin and xmax and every particle inside [x0, x0 + L)
 * (the lattice of a box of length L fits exactly when L is a multiple of
 * l0). L must exceed twice the largest radius, so that no pair meets twice.
 * A serial run without a period has no halo (d->halo is NULL: one test per
 * phase).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_halo.h"
#include "mps.h"

typedef struct mps_halo {
    mf_halo *h;
    mf_halo_spec spec;  /* at r^n: velocities and the fields of the explicit phase */
    mf_halo_spec star;  /* at r*: what the pressure phase reads */
    double rmax;        /* the operators' largest radius */
} mps_halo;

static double largest_radius(const mps_data *d)
{
    double r = d->k_nd.re;
    if (d->k_grad.re > r) r = d->k_grad.re;
    if (d->k_lap.re > r) r = d->k_lap.re;
    return r;
}

static int check_period(const mps_data *d, const mf_sim *sim, double rmax)
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
    return 0;
}

int mps_halo_create(mps_data *d, mf_sim *sim)
{
    const bool periodic = d->s.periodic_length > 0;
    if (!periodic && !sim->par)
        return 0; /* serial, no period: no copies */
    const double rmax = largest_radius(d);
    if (periodic)
        MF_CALL(check_period(d, sim, rmax));
    mps_halo *mh = calloc(1, sizeof *mh);
    if (!mh)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    int rc = mf_halo_create(&mh->h);
    if (rc != 0) {
        free(mh);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    mh->rmax = rmax; /* the copies' reach: mps_halo_add */
    mh->spec.velocities = true; /* viscosity, the collision model, the forces */
    if (periodic) {
        mh->spec.periodic_axis = 0;
        mh->spec.periodic_origin = d->s.periodic_origin;
        mh->spec.periodic_length = d->s.periodic_length;
        mf_log_printf(sim->log, MF_LOG_NORMAL, "Periodic in x: [%g, %g), images within %g m\n",
                      d->s.periodic_origin, d->s.periodic_origin + d->s.periodic_length, rmax);
    }
    mh->star = mh->spec;
    /* At r* the paper's PPE and the correction read no velocity; the other
     * sources read the neighbours' u* (div u*, Dn/Dt at r*: mps_source_terms). */
    mh->star.velocities = d->sc.source != MPS_SOURCE_DENSITY;
    d->halo = mh;
    return 0;
}

void mps_halo_destroy(mps_halo *mh)
{
    if (!mh)
        return;
    mf_halo_destroy(mh->h);
    free(mh);
}

static int add_to(mf_halo_spec *s, int field)
{
    for (int k = 0; k < s->nfields; k++)
        if (s->field[k] == field)
            return 0;
    if (s->nfields == MF_MAX_FIELDS)
        return MF_ERROR(MF_ERR_INTERNAL, "too many halo fields");
    s->field[s->nfields++] = field;
    return 0;
}

int mps_halo_add_field(mps_data *d, int field, int when)
{
    mps_halo *mh = d->halo;
    if (!mh)
        return 0;
    if (when & MPS_HALO_START)
        MF_CALL(add_to(&mh->spec, field));
    if (when & MPS_HALO_STAR)
        MF_CALL(add_to(&mh->star, field));
    return 0;
}

/* d->dirichlet (scratch until the surface phase): the owned walls that
 * were unknowns of the last pressure equation (no free-surface flag). */
static void pressure_walls(mps_data *d, const mf_particles *p)
{
    const int32_t *flags = mf_particles_fi(p, d->f_flags);
    for (size_t i = 0; i < p->n_owned; i++)
        d->dirichlet[i] = p->kind[i] == MF_WALL && !(flags[i] & MPS_FLAG_SURFACE);
}

int mps_halo_begin(mps_data *d, mf_sim *sim, bool step_start)
{
    mps_halo *mh = d->halo;
    mf_particles *p = sim->p;
    mf_halo_drop(mh->h, p);
    mf_halo_wrap(&mh->spec, p);
    if (!step_start || !sim->par)
        return 0;
    mf_parallel_stats *st = mf_parallel_statistics(sim->par);
    const long before = st->rebalances;
    MF_CALL(mf_parallel_migrate(sim->par, p));
    /* The load: walls beside the fluid are unknowns of the pressure
     * equation (no free-surface flag after the last step), the others only
     * count in the neighbour lists. */
    MF_CALL(mps_reserve(d, p->n));
    pressure_walls(d, p);
    MF_CALL(mf_parallel_rebalance(sim->par, p, false, d->dirichlet));
    if (st->rebalances != before) { /* the flags moved with the particles */
        MF_CALL(mps_reserve(d, p->n));
        pressure_walls(d, p);
        st->imbalance_after = mf_parallel_imbalance(sim->par, p, d->dirichlet);
        mf_log_printf(sim->log, MF_LOG_NORMAL, "Rebalanced: load imbalance %.3f, now %.3f\n",
                      st->imbalance_before, st->imbalance);
    }
    return 0;
}

int mps_halo_add(mps_data *d, mf_sim *sim, bool at_star)
{
    mps_halo *mh = d->halo;
    mf_particles *p = sim->p;
    /* The copies reach every loop: the operators' and the forces' (their
     * requests to the neighbour service, through the same copies). */
    mh->spec.radius = mh->star.radius =
        fmax(mh->rmax, mf_neighbours_max_radius(sim->neighbours));
    MF_CALL(mf_halo_build(mh->h, sim->par, p, at_star ? &mh->star : &mh->spec));
    MF_CALL(mps_reserve(d, p->n));
    /* What a copy is follows from its kind; what the phases compute later
     * (free surface, PPE rows, pressure) comes from its owner by sync. */
    for (size_t j = p->n_owned; j < p->n; j++) {
        d->is_fluid[j] = p->kind[j] == MF_FLUID;
        d->not_dummy[j] = p->kind[j] != MF_DUMMY;
        d->in_ppe[j] = d->dirichlet[j] = 0;
    }
    sim->halo = mh->h;
    return 0;
}

void mps_halo_end(mps_data *d, mf_sim *sim)
{
    mps_halo *mh = d->halo;
    mf_halo_drop(mh->h, sim->p);
    mf_halo_wrap(&mh->spec, sim->p);
    sim->halo = NULL;
}

int mps_halo_sync(const mps_data *d, const mf_sim *sim, void *values, size_t size)
{
    if (!d->halo)
        return 0;
    MF_CALL(mf_halo_update(d->halo->h, sim->par, sim->p, values, size));
    return 0;
}

int mps_halo_sync_motion(const mps_data *d, const mf_sim *sim)
{
    if (!d->halo)
        return 0;
    MF_CALL(mf_halo_update_motion(d->halo->h, sim->par, sim->p));
    return 0;
}

int mps_global_rows(const mps_data *d, const mf_sim *sim, long *row, size_t nrows,
                    long *global, int64_t *offset, int64_t *nglobal, const long **global_col)
{
    const mf_particles *p = sim->p;
    *offset = mf_parallel_exscan(sim->par, (int64_t)nrows);
    *nglobal = (int64_t)nrows;
    mf_parallel_sum_i64(sim->par, nglobal, 1);
    *global_col = NULL;
    if (!sim->par) { /* one rank: an image is its owner's local row */
        MF_CALL(mps_halo_sync(d, sim, row, sizeof *row));
        return 0;
    }
    for (size_t i = 0; i < p->n_owned; i++)
        global[i] = row[i] >= 0 ? (long)*offset + row[i] : -1;
    MF_CALL(mps_halo_sync(d, sim, global, sizeof *global));
    for (size_t j = p->n_owned; j < p->n; j++) /* a copy: has a column or not */
        row[j] = global[j] >= 0 ? 0 : -1;
    *global_col = global;
    return 0;
}
