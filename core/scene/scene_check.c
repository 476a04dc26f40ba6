/* scene_check.c: refuse a scene whose particles overlap. Two particles
 * closer than l0/2 at the start mean blocks that overlap each other or reach
 * into a wall: the run would start with a pressure spike (silent nonsense),
 * so it is an error that says where. */
#include <math.h>

#include "mf_error.h"
#include "mf_neighbours.h"
#include "mf_pairs.h"
#include "mf_scene.h"

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

int mf_scene_check_overlap(const mf_sim *sim)
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
    overlap_acc a = {0, 0, 0};
    /* Every particle: the scene has no halos yet. */
    for (size_t i = 0; rc == 0 && i < p->n; i++)
        mf_pairs_row_r2(&v, i, NULL, overlap_pair, NULL, &a);
    mf_neighbours_destroy(nb);
    MF_CALL(rc);
    if (a.pairs == 0)
        return 0;
    const double *x = &p->pos[3 * a.first_i], *y = &p->pos[3 * a.first_j];
    return MF_ERROR(MF_ERR_INPUT,
                    "constant/geometry: %zu pairs of particles start closer than l0/2 = %g m, "
                    "e.g. a %s particle at (%g %g %g) and a %s particle at (%g %g %g): do two "
                    "fluid blocks overlap, or does a block reach into a wall?",
                    a.pairs, radius, mf_particle_kind_name(p->kind[a.first_i]), x[0], x[1], x[2],
                    mf_particle_kind_name(p->kind[a.first_j]), y[0], y[1], y[2]);
}
