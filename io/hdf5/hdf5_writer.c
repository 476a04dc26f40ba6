/* hdf5_writer.c: write one snapshot file (layout in mf_hdf5.h).
 *
 * On one rank the file is built in memory, written as "<path>.tmp" (by us,
 * not HDF5: write_in_memory), synced and renamed: the real name only ever holds a
 * complete file, and a write that fails (a full disk) leaves no HDF5 handle
 * open. Particles are grouped by kind in storage order; StorageIndex
 * records where each came from.
 *
 * On several ranks (a -parallel run) the file is the same one file, written
 * collectively through MPI-IO (parallel HDF5: write_collective): every rank
 * writes its owned particles of each kind as one block of rows, blocks in
 * rank order (the global storage order: rank 0's particles, then rank 1's,
 * ...), so readers see one snapshot as from a serial run, with each
 * particle's id. The header carries the totals; rank 0 commits the finished
 * file. A disk that fills while HDF5 flushes the file fails its close there
 * (said, the .tmp removed); the in-memory path's guarantee that nothing of
 * HDF5 stays open after such a failure holds on one rank only. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hdf5_internal.h"
#include "mf_bodies.h"
#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_parallel_mpi.h"

/* Rows per chunk when compressing: 16k rows of 3 doubles is 384 KiB, inside
 * HDF5's default 1 MiB chunk cache. */
#define CHUNK_ROWS 16384

typedef struct snap_writer {
    const char *path;   /* the final name, for messages */
    hid_t file;
    int compression;
    const mf_particles *p;
    const mf_parallel *par; /* NULL: one rank writes alone */
    size_t *index;      /* particles of the kind being written */
    size_t count;       /* this rank's rows of that kind */
    hsize_t rows;       /* all ranks' rows of that kind */
    hsize_t first;      /* this rank's first row of that kind */
    int64_t storage0;   /* global storage index of this rank's first particle */
    void *buf;          /* gather buffer: count * max components * 8 bytes */
} snap_writer;

/* Create group name in parent; on failure an MF_ERR_IO naming what (the
 * group's file:/path) and HDF5's reason, and *g < 0. */
static int create_group(hid_t parent, const char *name, const char *what, hid_t *g)
{
    char detail[256];
    *g = H5Gcreate2(parent, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (*g < 0)
        return MF_ERROR(MF_ERR_IO, "%s: cannot create the group (%s)", what,
                        mf_h5_error_detail(detail, sizeof detail));
    return 0;
}

static int write_header(const snap_writer *w, const mf_sim *sim,
                        const int64_t counts[MF_NKINDS])
{
    char what[MF_H5_PATH_MAX];
    snprintf(what, sizeof what, "%s:/Header", w->path);
    hid_t g;
    MF_CALL(create_group(w->file, "Header", what, &g));
    int64_t step = sim->step, next_id = w->p->next_id;
    mf_parallel_max_i64(w->par, &next_id, 1); /* the smallest id no rank has used */
    const int dim = w->p->dim, one = 1;
    int rc = 0;
    MF_CALL_GOTO(rc, mf_h5_attr_write(g, "Time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 0, &sim->time, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_write(g, "Step", H5T_STD_I64LE, H5T_NATIVE_INT64, 0, &step, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_write(g, "TimeStep", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 0, &sim->dt, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_write(g, "NaturalTimeStep", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 0, &sim->dt_natural, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_write(g, "Dimension", H5T_STD_I32LE, H5T_NATIVE_INT, 0, &dim, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_write(g, "ParticleSpacing", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 0, &sim->l0, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_write(g, "NumPart_ThisFile", H5T_STD_I64LE, H5T_NATIVE_INT64, MF_NKINDS, counts, what), done);
    /* One file per snapshot (written by every rank): the totals are the same. */
    MF_CALL_GOTO(rc, mf_h5_attr_write(g, "NumPart_Total", H5T_STD_I64LE, H5T_NATIVE_INT64, MF_NKINDS, counts, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_write(g, "NextId", H5T_STD_I64LE, H5T_NATIVE_INT64, 0, &next_id, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_write(g, "NumFilesPerSnapshot", H5T_STD_I32LE, H5T_NATIVE_INT, 0, &one, what), done);
    /* Every snapshot holds what a restart needs (StorageIndex, all output
     * fields), so each one can be restarted from. */
    MF_CALL_GOTO(rc, mf_h5_attr_write(g, "Flag_Restart", H5T_STD_I32LE, H5T_NATIVE_INT, 0, &one, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_write_string(g, "Code", "mpsflow", what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_write_string(g, "CodeVersion", MPSFLOW_VERSION, what), done);
done:
    H5Gclose(g);
    return rc;
}

static int write_parameters(const snap_writer *w, const mf_dict *params)
{
    char what[MF_H5_PATH_MAX];
    snprintf(what, sizeof what, "%s:/Parameters", w->path);
    hid_t g;
    MF_CALL(create_group(w->file, "Parameters", what, &g));
    int rc = mf_h5_write_dict(g, params, what);
    H5Gclose(g);
    MF_CALL(rc);
    return 0;
}

/* One dataset of w->count rows and ncomp columns (rank 1 when ncomp == 1)
 * from the gathered buffer. */
static int write_dataset(const snap_writer *w, hid_t group, const char *group_name,
                         const char *name, int ncomp, hid_t file_type, hid_t mem_type)
{
    char what[MF_H5_PATH_MAX], detail[256];
    snprintf(what, sizeof what, "%s:/%s/%s", w->path, group_name, name);
    hsize_t dims[2] = {w->rows, (hsize_t)ncomp};
    int rank = ncomp == 1 ? 1 : 2;
    hid_t space = H5Screate_simple(rank, dims, NULL);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    hid_t dset = H5I_INVALID_HID, mem = H5I_INVALID_HID, dxpl = H5P_DEFAULT;
    int rc = 0;
    if (space < 0 || dcpl < 0) {
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot create the dataspace (%s)", what,
                      mf_h5_error_detail(detail, sizeof detail));
        goto done;
    }
    if (w->compression > 0) {
        hsize_t chunk[2] = {w->rows < CHUNK_ROWS ? w->rows : CHUNK_ROWS, (hsize_t)ncomp};
        /* Shuffle groups the bytes of equal significance: gzip then finds
         * the repeated exponents of neighbouring doubles. Both lossless. */
        if (H5Pset_chunk(dcpl, rank, chunk) < 0 || H5Pset_shuffle(dcpl) < 0 ||
            H5Pset_deflate(dcpl, (unsigned)w->compression) < 0) {
            rc = MF_ERROR(MF_ERR_IO, "%s: cannot set up compression (%s)", what,
                          mf_h5_error_detail(detail, sizeof detail));
            goto done;
        }
    }
    dset = H5Dcreate2(group, name, file_type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    herr_t wrc = dset < 0 ? -1 : 0;
    if (wrc == 0 && !w->par) {
        wrc = H5Dwrite(dset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, w->buf);
    } else if (wrc == 0) {
        /* This rank's block of rows; every rank takes part (an empty
         * selection on a rank with none), as a collective write must. */
        hsize_t start[2] = {w->first, 0}, count[2] = {w->count, (hsize_t)ncomp};
        mem = H5Screate_simple(rank, count, NULL);
        dxpl = H5Pcreate(H5P_DATASET_XFER);
        wrc = mem < 0 || dxpl < 0 || H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE) < 0 ? -1 : 0;
        if (wrc == 0)
            wrc = w->count ? H5Sselect_hyperslab(space, H5S_SELECT_SET, start, NULL, count, NULL)
                           : H5Sselect_none(space);
        if (wrc == 0 && !w->count)
            wrc = H5Sselect_none(mem);
        if (wrc == 0)
            wrc = H5Dwrite(dset, mem_type, mem, space, dxpl, w->buf);
    }
    if (wrc < 0) {
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot write the dataset (%s)", what,
                      mf_h5_error_detail(detail, sizeof detail));
        goto done;
    }
    rc = mf_h5_attr_write_string(dset, "Units", mf_h5_unit(name), what);
done:
    if (dxpl != H5P_DEFAULT)
        mf_h5_close(&dxpl);
    mf_h5_close(&mem);
    mf_h5_close(&dset);
    mf_h5_close(&dcpl);
    mf_h5_close(&space);
    return rc;
}

/* For ParaView's Xdmf3 readers (the default for .xdmf), which make no cells
 * of a Polyvertex topology without connectivity: PointIndex (0..n-1, one
 * vertex cell per particle) and Kind (the group's kind, so that the
 * partitioned reader, which merges the groups, can still tell them apart). */
static int write_viewer_datasets(const snap_writer *w, hid_t g, const char *group_name, int kind)
{
    int32_t *index = w->buf;
    for (size_t k = 0; k < w->count; k++)
        index[k] = (int32_t)k;
    MF_CALL(write_dataset(w, g, group_name, "PointIndex", 1, H5T_STD_I32LE, H5T_NATIVE_INT32));
    uint8_t *kinds = w->buf;
    memset(kinds, kind, w->count);
    MF_CALL(write_dataset(w, g, group_name, "Kind", 1, H5T_STD_U8LE, H5T_NATIVE_UINT8));
    return 0;
}

static void gather_double(const snap_writer *w, const double *src, int ncomp)
{
    double *dst = w->buf;
    for (size_t k = 0; k < w->count; k++)
        memcpy(dst + k * (size_t)ncomp, src + w->index[k] * (size_t)ncomp,
               (size_t)ncomp * sizeof *dst);
}

static void gather_int32(const snap_writer *w, const int32_t *src, int ncomp)
{
    int32_t *dst = w->buf;
    for (size_t k = 0; k < w->count; k++)
        memcpy(dst + k * (size_t)ncomp, src + w->index[k] * (size_t)ncomp,
               (size_t)ncomp * sizeof *dst);
}

static int write_kind(snap_writer *w, int kind)
{
    char group_name[32], what[MF_H5_PATH_MAX];
    const mf_particles *p = w->p;
    mf_h5_part_group(kind, group_name, sizeof group_name);
    snprintf(what, sizeof what, "%s:/%s", w->path, group_name);

    w->count = 0;
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->kind[i] == kind)
            w->index[w->count++] = i;
    w->first = (hsize_t)mf_parallel_exscan(w->par, (int64_t)w->count);

    hid_t g;
    MF_CALL(create_group(w->file, group_name, what, &g));
    int rc = 0;
    MF_CALL_GOTO(rc, mf_h5_attr_write_string(g, "KindName", mf_h5_kind_name(kind), what), done);

    gather_double(w, p->pos, 3);
    MF_CALL_GOTO(rc, write_dataset(w, g, group_name, "Coordinates", 3, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE), done);
    gather_double(w, p->vel, 3);
    MF_CALL_GOTO(rc, write_dataset(w, g, group_name, "Velocities", 3, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE), done);
    int64_t *ids = w->buf;
    for (size_t k = 0; k < w->count; k++)
        ids[k] = p->id[w->index[k]];
    MF_CALL_GOTO(rc, write_dataset(w, g, group_name, "ParticleIDs", 1, H5T_STD_I64LE, H5T_NATIVE_INT64), done);
    for (size_t k = 0; k < w->count; k++)
        ids[k] = w->storage0 + (int64_t)w->index[k];
    MF_CALL_GOTO(rc, write_dataset(w, g, group_name, "StorageIndex", 1, H5T_STD_I64LE, H5T_NATIVE_INT64), done);
    MF_CALL_GOTO(rc, write_viewer_datasets(w, g, group_name, kind), done);

    for (int f = 0; f < p->nfields; f++) {
        const mf_field *field = &p->field[f];
        if (!field->output)
            continue;
        if (field->type == MF_FIELD_DOUBLE) {
            gather_double(w, field->data, field->ncomp);
            MF_CALL_GOTO(rc, write_dataset(w, g, group_name, field->name, field->ncomp,
                                           H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE), done);
        } else {
            gather_int32(w, field->data, field->ncomp);
            MF_CALL_GOTO(rc, write_dataset(w, g, group_name, field->name, field->ncomp,
                                           H5T_STD_I32LE, H5T_NATIVE_INT32), done);
        }
    }
done:
    H5Gclose(g);
    return rc;
}

/* What the writer relies on; a failure here is a bug upstream, caught
 * before anything is written. */
static int check_particles(const mf_sim *sim, const char *path, int64_t counts[MF_NKINDS],
                           int *max_ncomp)
{
    const mf_particles *p = sim->p;
    if (!p)
        return MF_ERROR(MF_ERR_INTERNAL, "%s: no particles to write", path);
    if (p->dim != 2 && p->dim != 3)
        return MF_ERROR(MF_ERR_INTERNAL, "%s: particles have dimension %d", path, p->dim);
    if (sim->dim != 0 && sim->dim != p->dim)
        return MF_ERROR(MF_ERR_INTERNAL, "%s: run dimension %d but particle dimension %d",
                        path, sim->dim, p->dim);
    for (int k = 0; k < MF_NKINDS; k++)
        counts[k] = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] >= MF_NKINDS)
            return MF_ERROR(MF_ERR_INTERNAL, "%s: particle %zu has kind %d", path, i,
                            p->kind[i]);
        counts[p->kind[i]]++;
    }
    *max_ncomp = 3;
    for (int f = 0; f < p->nfields; f++) {
        const mf_field *field = &p->field[f];
        if (!field->output)
            continue;
        if (mf_h5_is_core_dataset(field->name))
            return MF_ERROR(MF_ERR_INTERNAL, "%s: field %s has the name of a core dataset",
                            path, field->name);
        if (field->ncomp < 1 || (field->type != MF_FIELD_DOUBLE && field->type != MF_FIELD_INT32))
            return MF_ERROR(MF_ERR_INTERNAL, "%s: field %s has %d components of type %d", path,
                            field->name, field->ncomp, field->type);
        if (field->ncomp > *max_ncomp)
            *max_ncomp = field->ncomp;
    }
    return 0;
}

/* Close whatever is still open in the file (a group or dataset a failed
 * call left), then the file: nothing of it may outlive the call, or HDF5
 * closes it again at exit (inside MPI_Finalize) and crashes there. */
static void close_all(hid_t *file)
{
    if (*file < 0)
        return;
    ssize_t n = H5Fget_obj_count(*file, H5F_OBJ_DATASET | H5F_OBJ_GROUP | H5F_OBJ_DATATYPE |
                                            H5F_OBJ_ATTR | H5F_OBJ_LOCAL);
    if (n > 0) {
        hid_t *ids = malloc((size_t)n * sizeof *ids);
        ssize_t got = ids ? H5Fget_obj_ids(*file, H5F_OBJ_DATASET | H5F_OBJ_GROUP |
                                                      H5F_OBJ_DATATYPE | H5F_OBJ_ATTR |
                                                      H5F_OBJ_LOCAL,
                                           (size_t)n, ids)
                          : 0;
        for (ssize_t k = 0; k < got; k++)
            mf_h5_close(&ids[k]);
        free(ids);
    }
    mf_h5_close(file);
}

/* /RigidBodies/<name>: the state of each body moved by the fluid
 * (mf_bodies.h), as attributes: Mass, Centre, Rotation (body to world,
 * row-major), Velocity, AngularVelocity, AngularMomentum, and the impulses
 * of the last step not yet taken (Impulse, AngularImpulse). */
static int write_bodies(const snap_writer *w, const mf_sim *sim)
{
    const mf_walls *ws = sim->walls;
    if (mf_bodies_count(ws) == 0)
        return 0;
    char what[MF_H5_PATH_MAX];
    snprintf(what, sizeof what, "%s:/RigidBodies", w->path);
    hid_t g;
    MF_CALL(create_group(w->file, "RigidBodies", what, &g));
    int rc = 0;
    for (size_t k = 0; rc == 0 && k < ws->n; k++) {
        if (!ws->w[k].body)
            continue;
        mf_body_momentum b;
        mf_body_get(&ws->w[k], &b);
        snprintf(what, sizeof what, "%s:/RigidBodies/%s", w->path, ws->w[k].name);
        hid_t gb;
        if ((rc = create_group(g, ws->w[k].name, what, &gb)) != 0)
            break;
        const struct {
            const char *name;
            const double *v;
            size_t n;
        } a[] = {{"Mass", &b.mass, 0},           {"Centre", b.centre, 3},
                 {"Rotation", b.rotation, 9},    {"Velocity", b.velocity, 3},
                 {"AngularVelocity", b.omega, 3}, {"AngularMomentum", b.angular, 3},
                 {"Impulse", b.impulse, 3},      {"AngularImpulse", b.angular_impulse, 3}};
        for (size_t i = 0; rc == 0 && i < sizeof a / sizeof a[0]; i++)
            rc = mf_h5_attr_write(gb, a[i].name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, a[i].n,
                                  a[i].v, what);
        H5Gclose(gb);
    }
    H5Gclose(g);
    MF_CALL(rc);
    return 0;
}

/* The header, the parameters and every kind's datasets into w->file. */
static int write_contents(snap_writer *w, const mf_sim *sim, const mf_dict *params,
                          const int64_t counts[MF_NKINDS])
{
    MF_CALL(write_header(w, sim, counts));
    if (params)
        MF_CALL(write_parameters(w, params));
    MF_CALL(write_bodies(w, sim));
    for (int kind = 0; kind < MF_NKINDS; kind++)
        if (counts[kind] > 0) {
            w->rows = (hsize_t)counts[kind];
            MF_CALL(write_kind(w, kind));
        }
    return 0;
}

/* The core driver's memory, allocated through HDF5's file image callbacks
 * (H5Pset_file_image_callbacks) so that we know where it is: the finished
 * image is written to the disk from there, not from a copy of it. */
typedef struct image_store {
    unsigned char *mem; /* the driver's buffer, NULL until its first write */
    size_t size;        /* its allocated bytes (a multiple of the increment) */
} image_store;

static void *image_malloc(size_t size, H5FD_file_image_op_t op, void *udata)
{
    (void)op;
    image_store *store = udata;
    void *mem = malloc(size);
    if (mem) {
        store->mem = mem;
        store->size = size;
    }
    return mem;
}

/* Called only for an image given at open (H5Pset_file_image): none here. */
static void *image_memcpy(void *dest, const void *src, size_t size, H5FD_file_image_op_t op,
                          void *udata)
{
    (void)op;
    (void)udata;
    return memcpy(dest, src, size);
}

static void *image_realloc(void *ptr, size_t size, H5FD_file_image_op_t op, void *udata)
{
    (void)op;
    image_store *store = udata;
    void *mem = realloc(ptr, size);
    if (mem) {
        store->mem = mem;
        store->size = size;
    }
    return mem;
}

static herr_t image_free(void *ptr, H5FD_file_image_op_t op, void *udata)
{
    (void)op;
    image_store *store = udata;
    if (ptr == store->mem) {
        store->mem = NULL;
        store->size = 0;
    }
    free(ptr);
    return 0;
}

/* The fapl is copied into the file: the copy points at the same store. */
static void *image_udata_copy(void *udata) { return udata; }
static herr_t image_udata_free(void *udata)
{
    (void)udata;
    return 0;
}

/* Bytes of the file as written: a run of the driver's buffer, or zeros. */
typedef struct image_piece {
    const unsigned char *bytes;
    size_t size;
} image_piece;

static int write_image(const char *tmp, const image_piece *piece, int npieces);

/* The superblock's file consistency flags (HDF5 file format specification,
 * superblock versions 0 and 1: 4 bytes at offset 20, after the signature,
 * the versions, the sizes and the two group K values). An open file has
 * its write-access bit set there; H5Fget_file_image clears the flags in the
 * image it returns, as a file is left on close. Versions 2 and 3 (which
 * mf_h5_fapl never asks for: the library's default, the earliest format)
 * keep one byte at offset 11 under the superblock's checksum. */
#define SUPERBLOCK_VERSION_AT 8
#define SUPERBLOCK_V01_FLAGS_AT 20
#define SUPERBLOCK_V01_FLAGS_SIZE 4

/* One rank: the snapshot is built in memory (HDF5's core driver, no
 * backing store) and written to tmp by us in one go, from the driver's own
 * buffer, before the file is closed: HDF5 itself never writes to the disk,
 * so a full disk (or any write error) is a failed write() of ours, reported
 * with its errno, after which nothing of HDF5 is left open. With HDF5
 * writing the file itself, a failure while it flushed left the file open
 * inside the library, and closing it at exit crashed. The cost is the
 * file's image in memory while it is built and written, once: taking it
 * with H5Fget_file_image would copy it whole (8.8 MB on the 3-D bench case,
 * which set the run's peak). The bytes written are those H5Fget_file_image
 * returns after the flush: the first eoa bytes of the driver's buffer with
 * the superblock's consistency flags cleared (test_hdf5 checks the two
 * against each other). */
static int write_in_memory(snap_writer *w, const char *tmp, const mf_sim *sim,
                           const mf_dict *params, const int64_t counts[MF_NKINDS])
{
    char detail[256];
    image_store store = {0};
    H5FD_file_image_callbacks_t callbacks = {
        .image_malloc = image_malloc,         .image_memcpy = image_memcpy,
        .image_realloc = image_realloc,       .image_free = image_free,
        .udata_copy = image_udata_copy,       .udata_free = image_udata_free,
        .udata = &store};
    hid_t fapl = mf_h5_fapl();
    if (fapl >= 0 && (H5Pset_fapl_core(fapl, (size_t)1 << 20, 0) < 0 ||
                      H5Pset_file_image_callbacks(fapl, &callbacks) < 0))
        mf_h5_close(&fapl);
    w->file = fapl < 0 ? H5I_INVALID_HID : H5Fcreate(w->path, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    /* Take the message before any other HDF5 call clears the error stack. */
    mf_h5_error_detail(detail, sizeof detail);
    mf_h5_close(&fapl);
    if (w->file < 0)
        return MF_ERROR(MF_ERR_IO, "cannot create %s in memory (%s)", w->path, detail);
    int rc = 0;
    MF_CALL_GOTO(rc, write_contents(w, sim, params, counts), done);
    /* Flushed first: the image must hold the metadata still in HDF5's
     * caches. With no buffer H5Fget_file_image only says the image's size
     * (its end of allocation), all of it written, so inside the buffer. */
    ssize_t n = H5Fflush(w->file, H5F_SCOPE_GLOBAL) < 0 ? -1 : H5Fget_file_image(w->file, NULL, 0);
    if (n <= 0 || !store.mem || (size_t)n > store.size) {
        rc = MF_ERROR(MF_ERR_IO, "cannot finish %s in memory (%s)", w->path,
                      n <= 0 ? mf_h5_error_detail(detail, sizeof detail)
                             : "its end lies past the driver's buffer");
        goto done;
    }
    unsigned version = store.mem[SUPERBLOCK_VERSION_AT];
    if (version > 1 || (size_t)n < SUPERBLOCK_V01_FLAGS_AT + SUPERBLOCK_V01_FLAGS_SIZE) {
        rc = MF_ERROR(MF_ERR_INTERNAL, "%s: superblock version %u (%zd bytes): this writer "
                      "clears the flags of versions 0 and 1 only", w->path, version, n);
        goto done;
    }
    static const unsigned char cleared[SUPERBLOCK_V01_FLAGS_SIZE] = {0};
    const size_t after = SUPERBLOCK_V01_FLAGS_AT + SUPERBLOCK_V01_FLAGS_SIZE;
    const image_piece piece[] = {{store.mem, SUPERBLOCK_V01_FLAGS_AT},
                                 {cleared, SUPERBLOCK_V01_FLAGS_SIZE},
                                 {store.mem + after, (size_t)n - after}};
    rc = write_image(tmp, piece, 3);
done:
    close_all(&w->file);
    return rc;
}

/* Several ranks: tmp written by all of them through MPI-IO, each its block
 * of rows (collective calls throughout). */
static int write_collective(snap_writer *w, const char *tmp, const mf_sim *sim,
                            const mf_dict *params, const int64_t counts[MF_NKINDS])
{
    char detail[256];
    hid_t fapl = mf_h5_fapl();
    if (fapl >= 0 && H5Pset_fapl_mpio(fapl, mf_parallel_comm(w->par), MPI_INFO_NULL) < 0)
        mf_h5_close(&fapl);
    w->file = fapl < 0 ? H5I_INVALID_HID : H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    mf_h5_error_detail(detail, sizeof detail);
    mf_h5_close(&fapl);
    if (w->file < 0)
        return MF_ERROR(MF_ERR_IO, "cannot create %s (%s)", tmp, detail);
    int rc = write_contents(w, sim, params, counts);
    if (rc != 0) {
        close_all(&w->file);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    /* Closing flushes: a full disk shows up here. */
    herr_t closed = H5Fclose(w->file);
    w->file = H5I_INVALID_HID;
    if (closed < 0)
        return MF_ERROR(MF_ERR_IO, "cannot finish writing %s (%s)", tmp,
                        mf_h5_error_detail(detail, sizeof detail));
    return 0;
}

/* The pieces of the file, in order, to tmp, synced: a short write or a
 * failed sync removes tmp. */
static int write_image(const char *tmp, const image_piece *piece, int npieces)
{
    size_t size = 0;
    for (int k = 0; k < npieces; k++)
        size += piece[k].size;
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0)
        return MF_ERROR(MF_ERR_IO, "cannot create %s (%s, errno %d)", tmp, strerror(errno), errno);
    size_t done = 0;
    int err = 0;
    for (int k = 0; k < npieces && !err; k++) {
        size_t put_of = 0;
        while (put_of < piece[k].size && !err) {
            ssize_t put = write(fd, piece[k].bytes + put_of, piece[k].size - put_of);
            if (put < 0 && errno == EINTR)
                continue;
            if (put <= 0)
                err = put < 0 ? errno : ENOSPC;
            else
                put_of += (size_t)put;
        }
        done += put_of;
    }
    if (!err && fsync(fd) != 0 && errno != EINVAL)
        err = errno;
    if (close(fd) != 0 && !err)
        err = errno;
    if (!err)
        return 0;
    unlink(tmp);
    return MF_ERROR(MF_ERR_IO,
                    "cannot write %s: %s (errno %d) after %zu of %zu bytes; it is removed, the "
                    "snapshots written before are whole%s",
                    tmp, strerror(err), err, done, size,
                    err == ENOSPC || err == EDQUOT ? ": free space on that disk and restart "
                                                     "with -latestTime"
                                                   : "");
}

int mf_hdf5_write_snapshot(const char *path, const mf_sim *sim, const mf_dict *params,
                           int compression)
{
    if (compression < 0 || compression > 9)
        return MF_ERROR(MF_ERR_INPUT, "%s: compression level %d is not in 0..9", path,
                        compression);
    int64_t counts[MF_NKINDS];
    int max_ncomp = 3;
    MF_CALL(mf_parallel_agree(sim->par, check_particles(sim, path, counts, &max_ncomp)));
    mf_parallel_sum_i64(sim->par, counts, MF_NKINDS); /* the totals of all ranks */
    char tmp[MF_H5_PATH_MAX];
    int len = snprintf(tmp, sizeof tmp, "%s.tmp", path);
    if (len < 0 || (size_t)len >= sizeof tmp)
        return MF_ERROR(MF_ERR_INPUT, "snapshot path too long: %s", path);

    const mf_particles *p = sim->p;
    snap_writer w = {.path = path, .file = H5I_INVALID_HID, .compression = compression, .p = p,
                     .par = sim->par};
    w.storage0 = mf_parallel_exscan(sim->par, (int64_t)p->n_owned);
    size_t n = p->n_owned > 0 ? p->n_owned : 1;
    w.index = malloc(n * sizeof *w.index);
    w.buf = malloc(n * (size_t)max_ncomp * sizeof(double));
    int rc = !w.index || !w.buf
                 ? MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for %zu particles", path, n)
                 : 0;
    rc = mf_parallel_agree(sim->par, rc);
    if (rc != 0) {
        free(w.index);
        free(w.buf);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }

    mf_h5_quiet quiet;
    mf_h5_quiet_begin(&quiet);
    rc = sim->par ? write_collective(&w, tmp, sim, params, counts)
                  : write_in_memory(&w, tmp, sim, params, counts);
    mf_h5_quiet_end(&quiet);
    free(w.index);
    free(w.buf);
    /* Every rank has closed the file (a collective close) before rank 0
     * renames it. */
    rc = mf_parallel_agree(sim->par, rc);
    const bool root = mf_parallel_is_root(sim->par);
    if (rc == 0 && root)
        rc = mf_h5_commit(tmp, path);
    if (rc != 0 && root)
        unlink(tmp); /* nothing half-written is left behind */
    rc = mf_parallel_agree(sim->par, rc);
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    return 0;
}
