/* mf_particles.h: particle storage, a structure of arrays.
 *
 * Hot data that the neighbour loops read (positions, kinds) are compact
 * arrays; everything else is an optional field that exists only when a
 * module asks for it (no pressure array in a pure advection test, no fluid
 * id for one fluid).
 *
 * Vectors are stored with three components even in 2-D (z = 0): one code
 * path, and the 2-D memory overhead is small next to the neighbour lists.
 *
 * MPI layout: a rank owns particles [0, n_owned) and holds halo copies of
 * other ranks' particles (and periodic images) after them, [n_owned, n)
 * (core/parallel/mf_halo.h). Ids are 64-bit, unique across ranks without
 * communication: rank r of P hands out the interleaved block id_base + r +
 * k P (id_stride = P), so one rank's ids are exactly today's serial ones.
 * Globally indexed objects (matrix rows) are a per-rank range plus an
 * offset (global_offset).
 */
#ifndef MF_PARTICLES_H
#define MF_PARTICLES_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef enum {
    MF_FLUID = 0,
    MF_WALL = 1,   /* first layer of fixed particles: in the pressure equation */
    MF_DUMMY = 2,  /* outer fixed layers: only in the number density */
    MF_INLET = 3,
    MF_OUTLET = 4,
    MF_NKINDS
} mf_particle_kind;

const char *mf_particle_kind_name(int kind);

/* Optional per-particle fields, requested by modules by name. */
#define MF_MAX_FIELDS 32
typedef struct mf_field {
    char name[32];
    int ncomp;        /* 1 scalar, 3 vector */
    int type;         /* MF_FIELD_DOUBLE or MF_FIELD_INT32 */
    void *data;       /* ncomp * cap elements */
    bool output;      /* written to snapshots */
    bool step_scratch; /* written in full by every step before it is read:
                          a failed step's retry need not save it (run.c) */
} mf_field;

enum { MF_FIELD_DOUBLE = 0, MF_FIELD_INT32 = 1 };

typedef struct mf_particles {
    int dim;            /* 2 or 3 */
    size_t n;           /* owned + halo */
    size_t n_owned;
    size_t cap;
    double *pos;        /* 3 * cap */
    double *vel;        /* 3 * cap */
    uint8_t *kind;      /* cap */
    int64_t *id;        /* cap */
    int nfields;
    mf_field field[MF_MAX_FIELDS];
    /* Distributed layout. */
    int rank, nranks;
    int64_t global_offset; /* first global row of this rank's owned particles */
    int64_t id_base;       /* first id of the run's blocks (all ranks) */
    int64_t next_id;       /* next id this rank hands out (>= id_base) */
    int64_t id_stride;     /* ranks sharing the id space (1: serial) */
} mf_particles;

int mf_particles_create(int dim, size_t cap, mf_particles **out);
void mf_particles_destroy(mf_particles *p);
int mf_particles_reserve(mf_particles *p, size_t cap);
/* Shrink the arrays to p->n + headroom particles (a built scene: what
 * mf_particles_add's doubling left unused). */
int mf_particles_fit(mf_particles *p, size_t headroom);

/* Append one owned particle; a fresh unique id is assigned and returned in
 * *id_out (may be NULL). Optional fields of the new particle are zero. */
int mf_particles_add(mf_particles *p, int kind, const double x[3], const double v[3],
                     int64_t *id_out);
/* Remove the particles whose flag is set (n entries): compacts in place,
 * keeping the order of the rest; ids are never reused. Returns the count
 * removed in *nremoved. */
int mf_particles_remove(mf_particles *p, const uint8_t *remove_flag, size_t *nremoved);
/* Apply a permutation: new index k holds old index perm[k]. Every array,
 * optional fields included, follows. */
int mf_particles_permute(mf_particles *p, const size_t *perm);

/* Optional fields. Requesting an existing name with the same shape returns
 * it; with another shape is an error. */
int mf_particles_request_field(mf_particles *p, const char *name, int ncomp, int type,
                               bool output, int *index);
int mf_particles_field_index(const mf_particles *p, const char *name); /* -1 if absent */
/* Say that field index is rewritten in full by every step before anything
 * reads it (a scratch of the step, such as the forces' accelerations):
 * the time loop then keeps no copy of it to retry a failed step. One
 * requester saying so is enough; it must hold for every reader. */
int mf_particles_set_step_scratch(mf_particles *p, int index);
static inline double *mf_particles_fd(const mf_particles *p, int index)
{
    return (double *)p->field[index].data;
}
static inline int32_t *mf_particles_fi(const mf_particles *p, int index)
{
    return (int32_t *)p->field[index].data;
}

/* Ids from here on: rank `rank` of `nranks` hands out first + rank + k nranks
 * (first: the smallest id no rank has used, e.g. a snapshot's NextId). */
void mf_particles_set_id_block(mf_particles *p, int64_t first, int rank, int nranks);

/* Bytes of one particle's element of a field. */
size_t mf_particles_field_bytes(const mf_field *f);
/* Whole particles packed into one buffer (every array, fields included, in
 * the order of the store), so that they can move between ranks:
 * mf_particles_packed_bytes is the size of one; pack writes n of them
 * (indices idx) at buf; append_packed appends n owned particles from buf
 * (no halo may be present). */
size_t mf_particles_packed_bytes(const mf_particles *p);
void mf_particles_pack(const mf_particles *p, const size_t *idx, size_t n, void *buf);
int mf_particles_append_packed(mf_particles *p, const void *buf, size_t n);

void mf_particles_count_kinds(const mf_particles *p, size_t counts[MF_NKINDS]);
size_t mf_particles_memory(const mf_particles *p); /* bytes held */

/* What a run holds per particle, bytes, before it has any: the particle
 * arrays (with a dozen optional fields) twice (the time loop keeps a copy
 * to retry a step from), the cell grid, two neighbour lists and a sparse
 * pressure-matrix row (kept twice: assembly and solver copies) at the
 * largest radius `radius_l0` (in particle spacings), whose entries are the
 * lattice points within it, and a snapshot's image (built in memory, then
 * written: io/hdf5/hdf5_writer.c). A model for refusing a scene before it is
 * built, not an accounting: docs/validation-and-performance.md compares it with peak
 * memory measured on the tutorials. */
double mf_memory_per_particle(int dim, double radius_l0);

#pragma GCC visibility pop
#endif
