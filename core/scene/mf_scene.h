/* mf_scene.h: build the particles of a case from constant/geometry.
 *
 *   dimension        2;
 *   particleSpacing  0.005;          // l0: the one number that makes a
 *                                    // coarse preview or a fine run
 *   fluidBlocks { column { type box; min (0 0 0); max (0.25 0.5 0);
 *                          fluid water; velocity (0 0 0); } }
 *   walls       { tank   { type box; min (0 0 0); max (1 0.6 0);
 *                          open (ymax); wallLayers 1; dummyLayers 2; } }
 *
 * Particles sit on the lattice min + (i + 1/2) l0 of each block, so fluid
 * and walls built from the same corners line up. A wall box encloses the
 * region [min, max]: its first layer (at l0/2 outside) is MF_WALL and takes
 * part in the pressure equation, the outer layers are MF_DUMMY (number
 * density only). Faces listed in `open` get no wall.
 */
#ifndef MF_SCENE_H
#define MF_SCENE_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include "mf_dict.h"
#include "mf_params.h"
#include "mf_sim.h"

/* Read fluids (constant/fluids: one sub-dictionary per fluid with rho, nu,
 * sigma) into sim->fluid. Fluids are numbered in file order. */
int mf_scene_read_fluids(const mf_dict *fluids, mf_sim *sim);

/* Build sim->p (and sim->dim, sim->l0) from the geometry dictionary.
 * `l0_override` > 0 replaces particleSpacing (coarse preview / fine run).
 * With more than one fluid, a "FluidId" field is created; with one, not.
 * `resolved` (may be NULL) receives the geometry as used. */
int mf_scene_build(const mf_dict *geometry, double l0_override, mf_sim *sim, mf_dict *resolved);
/* The same, reading the polygon files of `type mesh` entries (fluidBlocks,
 * walls, obstacles: mf_trimesh.h) with `reader` (the driver passes io's,
 * mf_mesh_import.h). mf_scene_build is this with no reader: a mesh entry is
 * then an error. */
struct mf_trimesh_reader;
int mf_scene_build_with_reader(const mf_dict *geometry, double l0_override, mf_sim *sim,
                               mf_dict *resolved, const struct mf_trimesh_reader *reader);

/* A memory budget checked before the scene allocates a particle: the
 * particles the geometry will make (mf_scene_estimate_particles) times the
 * bytes a particle costs must fit in max_bytes. */
typedef struct mf_scene_budget {
    double max_bytes;          /* 0: no limit */
    double bytes_per_particle; /* mf_memory_per_particle */
    double radius_l0;          /* the neighbour radius it was computed at, for messages */
    const char *limit_source;  /* what set max_bytes, for messages */
    double particles;          /* out: the estimate */
} mf_scene_budget;
/* mf_scene_build_with_reader, refusing (MF_ERR_INPUT, naming the count,
 * the bytes and the key maxMemory) a scene over budget (may be NULL). */
int mf_scene_build_budgeted(const mf_dict *geometry, double l0_override, mf_sim *sim,
                            mf_dict *resolved, const struct mf_trimesh_reader *reader,
                            mf_scene_budget *budget);
/* The particles the geometry makes at sim->l0 in sim->dim (sim->end_time
 * bounds what nozzles add), without making any: exact for boxes, from the
 * volume for spheres, from the bounding box or area for meshes (meshes may
 * be NULL when there are none). Entries that do not read are skipped: the
 * builder reports them. */
struct mf_scene_meshes;
double mf_scene_estimate_particles(const mf_dict *geometry, const mf_sim *sim,
                                   const struct mf_scene_meshes *meshes);

/* Refuse particles closer than l0/2 (overlapping blocks, a block inside a
 * wall), naming the first pair. */
int mf_scene_check_overlap(const mf_sim *sim);
/* The same, naming the entries of the geometry the two particles belong
 * to (file:line:col) where their shapes tell. */
int mf_scene_check_overlap_in(const mf_dict *geometry, const mf_sim *sim);
/* What the run would refuse at step 0, refused before it (the dry run
 * included), each naming its entry: overlapping particles, no fluid and no
 * inlet or nozzle, fluid past a closed wall face, an inlet, outlet or nozzle
 * that does not reach the walls' domain (scene_check.c). */
int mf_scene_check_start(const mf_dict *geometry, const mf_sim *sim);
/* True when fluid particle i is past a closed face of a wall box (the
 * wall-particle line, l0/2 outside the region), within that face's extent:
 * *box, *axis, *side (0 min, 1 max) say which. The watch's throughWall. */
bool mf_scene_past_wall(const mf_sim *sim, size_t i, size_t *box, int *axis, int *side);

/* Index of a fluid by name, or an error listing the fluids. */
int mf_scene_fluid_index(const mf_sim *sim, const char *name, int *index);

/* The parameter tables of constant/geometry and constant/fluids, printed by
 * `mpsflow modules geometry|fluids` and in docs/reference.md: the tables
 * the builder applies. */
extern const mf_param_section mf_geometry_sections[];
extern const size_t mf_geometry_nsections;
extern const mf_param_section mf_mesh_sections[];
extern const size_t mf_mesh_nsections;
extern const mf_param_section mf_emitter_sections[];
extern const size_t mf_emitter_nsections;
extern const mf_param_section mf_fluid_sections[];
extern const size_t mf_fluid_nsections;

#pragma GCC visibility pop
#endif
