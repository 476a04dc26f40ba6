/* control_shape.h: the regions and targets of the control forces
 * (solvers/force/control/): a box, a sphere (a disk in 2-D) or a closed
 * polygon mesh read through core/scene's mesh import (the reader the driver
 * puts in sim->mesh_reader), each with a level-set offset: the region is
 * {x : phi(x) < offset}, phi the shape's signed distance (negative inside).
 *
 * The keys are flat, in the force's own parameter table (CONTROL_SHAPE_PARAMS
 * below), so that `mpsflow modules NAME` lists them with their ranges:
 *
 *   shape box;    min (0.6 0 0); max (0.9 0.3 0);
 *   shape sphere; centre (0.75 0.15 0); radius 0.15;
 *   shape mesh;   file "target.obj"; scale 1;   // constant/, constant/triSurface/
 *
 * A mesh is sampled once, at create, on the case's lattice x = (i + 1/2) l0
 * (generalised winding number > 1/2: inside), so a point's test afterwards is
 * a look-up, whatever the mesh's size. Its phi is the lattice's: -l0/2 inside,
 * +l0/2 outside; offset must be 0 for a mesh (it says so). A point (its
 * centre) has no inside: it is a target, sampled by one control particle. */
#ifndef CONTROL_SHAPE_H
#define CONTROL_SHAPE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mf_modules.h"

typedef enum { CONTROL_BOX, CONTROL_SPHERE, CONTROL_MESH, CONTROL_POINT } control_shape_type;

/* The shape's keys as they land in a force's settings struct. */
typedef struct control_shape_settings {
    const char *shape;
    double min[3], max[3];
    double centre[3], radius;
    const char *file;
    double scale;
    double offset;
} control_shape_settings;

extern const char *const control_shape_types[];

/* The shape's rows of a force's parameter table, for a settings struct
 * `type` holding a control_shape_settings named `field`. */
#define CONTROL_SHAPE_PARAMS(type, field, what)                                                   \
    {"shape", MF_PARAM_WORD, "sphere", MF_NO_RANGE, control_shape_types,                          \
     offsetof(type, field.shape), what ": box (min, max), sphere (centre, radius; a disk in "    \
                                  "2-D), mesh (file, scale: a closed surface) or point (centre)"}, \
    {"min", MF_PARAM_VECTOR, "(0 0 0)", -1e6, 1e6, NULL, offsetof(type, field.min),             \
     "lower corner, m (shape box)"},                                                             \
    {"max", MF_PARAM_VECTOR, "(0.1 0.1 0.1)", -1e6, 1e6, NULL, offsetof(type, field.max),       \
     "upper corner, m (shape box)"},                                                             \
    {"centre", MF_PARAM_VECTOR, "(0 0 0)", -1e6, 1e6, NULL, offsetof(type, field.centre),       \
     "centre, m (shape sphere)"},                                                                \
    {"radius", MF_PARAM_SCALAR, "0.1", 1e-9, 1e6, NULL, offsetof(type, field.radius),           \
     "radius, m (shape sphere)"},                                                                \
    {"file", MF_PARAM_WORD, "none", MF_NO_RANGE, NULL, offsetof(type, field.file),              \
     "polygon file (shape mesh): OBJ, STL or PLY, in constant/ or constant/triSurface/"},        \
    {"scale", MF_PARAM_SCALAR, "1", 1e-9, 1e9, NULL, offsetof(type, field.scale),               \
     "factor on the mesh's coordinates (0.001 for millimetres)"},                                \
    {"offset", MF_PARAM_SCALAR, "0", -1e6, 1e6, NULL, offsetof(type, field.offset),             \
     "level set: the region is phi < offset, phi the shape's signed distance, m (box, sphere)"}

typedef struct control_shape {
    control_shape_type type;
    int dim;
    control_shape_settings s;
    double lo[3], hi[3]; /* bounds of the region (phi < offset) */
    /* mesh: inside flags on the lattice points of [lo, hi] */
    double l0;
    long base[3], n[3];  /* lattice indices base + [0, n) per axis */
    uint8_t *inside;
} control_shape;

/* Build the shape from its settings (`who` names the force in messages). */
int control_shape_create(const control_shape_settings *s, const char *who, const mf_sim *sim,
                         control_shape *out);
void control_shape_free(control_shape *sh);
/* The signed distance minus offset (negative: in the region), at x shifted
 * back by `shift` (the region translated by shift; NULL: none). */
double control_shape_phi(const control_shape *sh, const double x[3], const double shift[3]);
static inline bool control_shape_contains(const control_shape *sh, const double x[3],
                                          const double shift[3])
{
    return control_shape_phi(sh, x, shift) < 0;
}
/* The lattice points x = (i + 1/2) h of the region (3 doubles each, z = 0 in
 * 2-D), at most cap of them written to xyz (may be NULL); returns how many
 * there are; a point: its centre. */
size_t control_shape_lattice(const control_shape *sh, double h, double *xyz, size_t cap);

#endif
