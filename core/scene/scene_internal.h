/* scene_internal.h: what the scene builder's files (scene.c, scene_mesh.c,
 * scene_solids.c) share; not installed. */
#ifndef MF_SCENE_INTERNAL_H
#define MF_SCENE_INTERNAL_H

#include "mf_dict.h"
#include "mf_params.h"
#include "mf_sim.h"
#include "mf_walls.h"

/* Name, where (entry file:line:col), surface velocity and motion of a solid
 * from its entry d (motion: its motion sub-dictionary or NULL). */
int mf_scene_solid_init(const mf_sim *sim, const char *name, const mf_dict *d,
                        const double velocity[3], const mf_dict *motion, int shape,
                        bool obstacle, mf_wall *w);
/* Add w to sim->walls; its particles are [first, sim->p->n) (none for a
 * wall weight scene): they take its surface velocity, and those of a moving
 * solid its index in the WallId field. */
int mf_scene_solid_add(mf_sim *sim, mf_wall *w, size_t first);

/* Warn (naming the entry) when the lattice makes a shape of extent `want`
 * (m, per axis) into particles spanning half a spacing or more more or
 * less: the particles [first, sim->p->n) of kind `kind` (-1: any), their
 * span measured as the outermost centres plus l0. */
void mf_scene_warn_extent(const mf_sim *sim, const char *where, const char *what,
                          const char *name, const double want[3], size_t first, int kind);
/* The same for a sphere (a disk in 2-D): the radius of a ball of the
 * particles' volume against `radius`. */
void mf_scene_warn_radius(const mf_sim *sim, const char *where, const char *what,
                          const char *name, double radius, size_t count);

/* obstacles/<name> of type box, cylinder or sphere (scene_solids.c). */
int mf_scene_obstacle(mf_sim *sim, const char *name, const mf_dict *d, mf_dict *resolved);

#endif
