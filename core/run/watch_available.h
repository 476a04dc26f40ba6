/* watch_available.h: the geometry of the watch's availableEnergy criterion
 * (mf_watch.h): the container's floor, the fluid's potential energy and
 * that of the same fluid laid level on the floor. Internal to core/run. */
#ifndef MF_WATCH_AVAILABLE_H
#define MF_WATCH_AVAILABLE_H

#include <stddef.h>

#include "mf_sim.h"
#include "mf_watch.h"

/* The floor of the case's container into *f (f->applies), or why the
 * criterion does not apply (f->applies false, `why` filled, n bytes). */
void mf_watch_floor_find(const mf_sim *sim, mf_watch_floor *f, char *why, size_t n);
/* sum m |g| h over the fluid particles of every rank, h = f->up x[axis]
 * their height (against g, from the world's origin). */
double mf_watch_fluid_pe(const mf_sim *sim, const mf_watch_floor *f);
/* The potential energy of the fluid of every rank laid level on the floor
 * where it is now, each fluid a layer of its volume (particles times l0^d,
 * mass / rho) over the floor's area, the densest lowest: the least a fluid
 * in this container can have (obstacles only raise it), heights as above;
 * *above_floor (may be NULL): the part of it above the floor, sum over the
 * layers of M_k |g| times the height of their middle (M |g| H / 2 for one
 * fluid H deep), the energy scale of the fluid at rest in this tank. */
double mf_watch_level_pe(const mf_sim *sim, const mf_watch_floor *f, double *above_floor);

#endif
