/* scene_check.c: refuse a scene whose particles overlap. Two particles
 * closer than l0/2 at the start mean blocks that overlap each other or reach
 * into a wall: the run would start with a pressure spike (silent nonsense),
 * so it is an error that says where. */
#include <math.h>

#include "mf_error.h"
#include "mf_neighbours.h"
#include "mf_scene.h"

int mf_scene_check_overlap(const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    if (p->n < 2)
        return 0;
    mf_grid g;
    mf_nlist nl;
    mf_grid_init(&g);
    mf_nlist_init(&nl);
    const double radius = 0.5 * sim->l0;
    int rc = mf_grid_build(&g, p, radius);
    if (rc == 0)
        rc = mf_nlist_build(&nl, &g, p, radius);
    size_t pairs = 0, first_i = 0, first_j = 0;
    for (size_t i = 0; rc == 0 && i < p->n; i++)
        for (size_t k = nl.start[i]; k < nl.start[i + 1]; k++)
            if (nl.j[k] > i && pairs++ == 0) {
                first_i = i;
                first_j = nl.j[k];
            }
    mf_grid_free(&g);
    mf_nlist_free(&nl);
    MF_CALL(rc);
    if (pairs == 0)
        return 0;
    const double *a = &p->pos[3 * first_i], *b = &p->pos[3 * first_j];
    return MF_ERROR(MF_ERR_INPUT,
                    "constant/geometry: %zu pairs of particles start closer than l0/2 = %g m, "
                    "e.g. a %s particle at (%g %g %g) and a %s particle at (%g %g %g): do two "
                    "fluid blocks overlap, or does a block reach into a wall?",
                    pairs, radius, mf_particle_kind_name(p->kind[first_i]), a[0], a[1], a[2],
                    mf_particle_kind_name(p->kind[first_j]), b[0], b[1], b[2]);
}
