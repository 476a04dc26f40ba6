/* parallel_internal.h: the state behind mf_parallel.h, shared by the files
 * of core/parallel only (MPI and Zoltan types stay out of the public
 * headers, so that plugins and the serial build never see them). */
#ifndef MF_PARALLEL_INTERNAL_H
#define MF_PARALLEL_INTERNAL_H

#include <mpi.h>

#include "mf_parallel.h"

struct Zoltan_Struct;

struct mf_parallel {
    mf_parallel_settings s;
    MPI_Comm comm; /* a duplicate of MPI_COMM_WORLD: our messages never meet hypre's */
    int rank, size;
    struct Zoltan_Struct *zz; /* created at the first partition */
    bool partitioned;         /* cuts are known: mf_parallel_owner_of works */
    int geom_dim;             /* coordinates Zoltan sees (2 or 3) */
    const mf_particles *zp;   /* the particles Zoltan's callbacks read */
    const uint8_t *zwalls;    /* and their pressure walls (may be NULL) */
    bool has_box;             /* RCB: this rank's region is the box below */
    double box[6];            /* min x, y, z, max x, y, z */
    double margin;            /* a particle this close outside its region stays */
    mf_parallel_stats stats;
};

/* mf_decompose.c */
void mf_decompose_free(mf_parallel *par);

/* Tags of our point-to-point messages (Zoltan_Comm plans). */
enum { MF_TAG_MIGRATE = 7301, MF_TAG_HALO = 7311, MF_TAG_HALO_UPDATE = 7321 };

#endif
