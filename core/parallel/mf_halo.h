/* mf_halo.h: copies of the particles a rank's neighbour loops read but do
 * not own, in the slots [n_owned, n) of its mf_particles.
 *
 * Two sources, one mechanism:
 *   - other ranks' particles within the halo radius of this rank's owned
 *     particles (the bounding box of its owned particles grown by the
 *     radius: every particle within the radius of an owned one is inside);
 *   - periodic images: along a periodic axis, particles within the radius
 *     of the lower face are copied shifted by +L, those within the radius of
 *     the upper face by -L (on this rank, or sent to the rank that needs
 *     them), so that the loops see across the period without a minimum-image
 *     rule in any kernel.
 * Each copy keeps its owner's id, kind and position (shifted for an image),
 * plus its velocity and the optional fields when the caller asks for them:
 * nothing else crosses the network. Later values of an array computed on the owned
 * particles reach the copies through mf_halo_update with the same plan (the
 * pressure after the solve, a particle's global matrix row, a mask), so an
 * image or a remote copy is always the same unknown as its owner.
 *
 * A serial run without a periodic axis builds no halo (mf_halo_build sets
 * n = n_owned and returns). Copies are never updated by the loops (they
 * write only owned particles) and are dropped (mf_halo_drop) before
 * particles are added, removed, migrated or written.
 */
#ifndef MF_HALO_H
#define MF_HALO_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stddef.h>

#include "mf_parallel.h"
#include "mf_particles.h"

typedef struct mf_halo mf_halo;

typedef struct mf_halo_spec {
    double radius;        /* the largest radius the phase's loops read */
    /* A periodic axis (length 0: none): particles live in [origin, origin + length). */
    int periodic_axis;
    double periodic_origin, periodic_length;
    /* Velocities copied (else the copies' are zero: a phase that reads none). */
    bool velocities;
    /* Optional fields copied with positions, kinds and ids. */
    int nfields;
    int field[MF_MAX_FIELDS];
} mf_halo_spec;

int mf_halo_create(mf_halo **out);
void mf_halo_destroy(mf_halo *h);

/* Drop the old copies and build new ones for the positions now (collective
 * when par is not NULL). On return [n_owned, n) holds the copies. */
int mf_halo_build(mf_halo *h, mf_parallel *par, mf_particles *p, const mf_halo_spec *spec);
/* values holds n elements of `size` bytes (an array that follows the
 * particles: a field, a mask, a row number): the copies get their owner's
 * value (collective). */
int mf_halo_update(mf_halo *h, mf_parallel *par, const mf_particles *p, void *values,
                   size_t size);
/* The same for an optional field of p, and for the positions (shifted for
 * periodic images) and velocities. */
int mf_halo_update_field(mf_halo *h, mf_parallel *par, mf_particles *p, int field);
int mf_halo_update_motion(mf_halo *h, mf_parallel *par, mf_particles *p);
/* Fluid that left the period along the periodic axis is put back inside
 * [origin, origin + length) (nothing without a period). */
void mf_halo_wrap(const mf_halo_spec *spec, mf_particles *p);
/* n = n_owned. */
void mf_halo_drop(mf_halo *h, mf_particles *p);

/* Whether any copy is present after the last build (false for a serial run
 * without a period: nothing to synchronise). */
bool mf_halo_active(const mf_halo *h);
/* For a copy j of a particle of this rank (a periodic image on one rank),
 * the owned index; SIZE_MAX for a copy of another rank's particle. */
size_t mf_halo_local_owner(const mf_halo *h, const mf_particles *p, size_t j);

#pragma GCC visibility pop
#endif
