/* mf_hdf5.h: HDF5 snapshots (output and restart) and their XDMF index.
 *
 * Layout of a case's output (SWIFT/Gadget-like, so h5py scripts written for
 * those codes need few changes):
 *
 *   <case>/output/snapshot_000000.h5, snapshot_000001.h5, ...
 *   <case>/output/particles.xdmf      the index ParaView opens
 *
 * A snapshot holds
 *   /Header       attributes Time, Step, TimeStep, NaturalTimeStep, Dimension, ParticleSpacing,
 *                 NumPart_ThisFile[5], NumPart_Total[5], NextId, Code,
 *                 CodeVersion, Flag_Restart, NumFilesPerSnapshot
 *   /Parameters   the resolved case dictionary: sub-dictionaries are groups,
 *                 every other entry a string attribute with its value text
 *   /PartTypeK    one group per particle kind present (0 fluid, 1 wall,
 *                 2 dummy, 3 inlet, 4 outlet), attribute KindName, datasets
 *                 Coordinates (N x 3), Velocities (N x 3), ParticleIDs (N),
 *                 StorageIndex (N) and every optional field with output set,
 *                 under its own name (N or N x ncomp); attribute Units on each.
 *
 * StorageIndex is the particle's index in the storage arrays: a restart puts
 * every particle back at the same index, so sums over particles come out
 * bit-identical to the run that wrote the snapshot.
 *
 * Files are written under "<name>.tmp" and renamed: a crash never leaves a
 * half-written file under a real name. Readers ignore *.tmp files.
 *
 * Numbering: the writer continues after the newest snapshot present in the
 * output folder, and a restart (-latestTime) continues from the newest
 * snapshot. The XDMF index lists the snapshots of the current run: walking
 * back from the newest, each earlier snapshot is listed while its time is
 * before the one after it (stale snapshots of an older, longer run, which
 * would make the time axis go backwards in ParaView, are left out).
 *
 * All functions return 0 or a negative mf_error status with a message that
 * names the file (and the dataset). HDF5's own error printing is switched
 * off while they run.
 */
#ifndef MF_HDF5_H
#define MF_HDF5_H

#include <stddef.h>
#include <stdint.h>

#include "mf_dict.h"
#include "mf_modules.h"
#include "mf_particles.h"
#include "mf_sim.h"

/* The writer module (kind writer, name "hdf5"). */
extern const mf_writer_ops mf_writer_hdf5;

/* What /Header says, read without touching the particle data. */
typedef struct mf_hdf5_header {
    double time;
    long step;
    double dt;                     /* TimeStep: the last step taken */
    double dt_natural;             /* NaturalTimeStep: the step controller's state (0 if absent) */
    int dim;
    double l0;                     /* ParticleSpacing */
    int64_t npart[MF_NKINDS];      /* NumPart_ThisFile */
    int64_t npart_total[MF_NKINDS];
    int64_t next_id;
    char code_version[64];
} mf_hdf5_header;

/* Read and check /Header of a snapshot. */
int mf_hdf5_read_header(const char *path, mf_hdf5_header *h);

/* Write one snapshot of sim (its owned particles) to `path`, through
 * "<path>.tmp" and a rename. params may be NULL (no /Parameters group).
 * compression: 0 contiguous datasets, 1..9 gzip level (chunked, shuffled). */
int mf_hdf5_write_snapshot(const char *path, const mf_sim *sim, const mf_dict *params,
                           int compression);

/* Restore time, step, dt, next id and the particles from a snapshot.
 * If sim->p is NULL, particles are created with the file's dimension and
 * every stored field (tools: validate, surface reconstruction). Otherwise
 * the dimension must match, the stored fields that sim->p has are filled
 * (shape and type must match), stored fields it lacks are skipped, and its
 * fields that the file lacks are zeroed. sim->dim and sim->l0 are taken
 * from the file when zero (a non-zero sim->dim must match). On failure the
 * particle contents are unspecified (a particles object created here is
 * destroyed again). */
int mf_hdf5_read_snapshot(const char *path, mf_sim *sim);

/* The newest complete snapshot of a case: the highest index whose file
 * opens and has a valid /Header. Writes its path and index (either may be
 * NULL / len 0). MF_ERR_INPUT if there is none. */
int mf_hdf5_latest_snapshot(const char *case_dir, char *path, size_t len, int *index);

/* Rebuild <output_dir>/particles.xdmf from the snapshots in the folder. */
int mf_hdf5_write_xdmf_index(const char *output_dir);

#endif
