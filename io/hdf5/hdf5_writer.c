/* hdf5_writer.c: write one snapshot file (layout in mf_hdf5.h).
 *
 * HDF5 writes "<path>.tmp" itself (write_file): through the sec2 driver
 * (plain POSIX writes) on one rank, through MPI-IO on several (a -parallel
 * run: parallel HDF5, collective calls). The file is then synced and
 * renamed: the real name only ever holds a complete file. A write that
 * fails (a full disk) closes what it can, removes the .tmp and says which
 * file and why; the snapshots written before are not touched. Particles
 * are grouped by kind in storage order; StorageIndex records where each
 * came from. Each dataset is written in pieces of PIECE_ROWS rows through
 * a staging buffer of that size, not one whole column: neither the file's
 * image nor a whole column is held in memory.
 *
 * On several ranks the file is the same one file: every rank writes its
 * owned particles of each kind as one block of rows, blocks in rank order
 * (the global storage order: rank 0's particles, then rank 1's, ...), so
 * readers see one snapshot as from a serial run, with each particle's id.
 * The header carries the totals; rank 0 commits the finished file. */
/* memfd_create (Linux, glibc 2.27): see move_to_memory. */
#define _GNU_SOURCE
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/mman.h>
#endif

#include "hdf5_internal.h"
#include "mf_bodies.h"
#include "mf_error.h"
#include "mf_fs.h"
#include "mf_hdf5.h"
#include "mf_parallel_mpi.h"

/* Rows per chunk when compressing: 16k rows of 3 doubles is 384 KiB, inside
 * HDF5's default 1 MiB chunk cache. */
#define CHUNK_ROWS 16384
/* Rows staged and written at a time. One chunk: a compressed chunk is then
 * written whole, once (one written in parts would be compressed, stored,
 * read back and stored again elsewhere: another file than one whole write
 * makes); the staging buffer is 384 KiB for 3 doubles a row, not the whole
 * column (2.4 MB on the 3-D bench case's 99,009 particles). */
#define PIECE_ROWS CHUNK_ROWS

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
    void *buf;          /* staging buffer: PIECE_ROWS * max components * 8 bytes */
    int io_errno;       /* errno of the first failed HDF5 write or close, 0 if none */
} snap_writer;

/* What a dataset's rows are made from (fill_piece). */
typedef enum {
    COLUMN_DOUBLE,      /* data: ncomp doubles a particle */
    COLUMN_INT32,       /* data: ncomp int32 a particle */
    COLUMN_ID,          /* the particles' ids */
    COLUMN_STORAGE,     /* their global storage index */
    COLUMN_POINT_INDEX, /* 0..count-1 within the kind */
    COLUMN_KIND         /* the kind, one byte */
} column_source;

typedef struct column {
    const char *name;
    column_source source;
    const void *data;   /* COLUMN_DOUBLE, COLUMN_INT32 */
    int ncomp;
    int kind;           /* COLUMN_KIND */
    hid_t file_type, mem_type;
} column;

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

/* Rows from .. from + n of this rank's particles of the kind into w->buf. */
static void fill_piece(const snap_writer *w, const column *c, size_t from, size_t n)
{
    const size_t *index = w->index + from;
    const size_t nc = (size_t)c->ncomp;
    switch (c->source) {
    case COLUMN_DOUBLE:
    case COLUMN_INT32: {
        /* Rows of ncomp values copied as bytes, from the particle's row. */
        const size_t row = nc * (c->source == COLUMN_DOUBLE ? sizeof(double) : sizeof(int32_t));
        unsigned char *dst = w->buf;
        const unsigned char *src = c->data;
        for (size_t k = 0; k < n; k++)
            memcpy(dst + k * row, src + index[k] * row, row);
        break;
    }
    case COLUMN_ID: {
        int64_t *dst = w->buf;
        for (size_t k = 0; k < n; k++)
            dst[k] = w->p->id[index[k]];
        break;
    }
    case COLUMN_STORAGE: {
        int64_t *dst = w->buf;
        for (size_t k = 0; k < n; k++)
            dst[k] = w->storage0 + (int64_t)index[k];
        break;
    }
    case COLUMN_POINT_INDEX: {
        int32_t *dst = w->buf;
        for (size_t k = 0; k < n; k++)
            dst[k] = (int32_t)(from + k);
        break;
    }
    case COLUMN_KIND:
        memset(w->buf, c->kind, n);
        break;
    }
}

/* This rank's rows from .. from + n (n may be 0: an empty selection, for a
 * collective write needs every rank) of the dataset, from w->buf. */
static herr_t write_piece(const snap_writer *w, hid_t dset, hid_t space, int rank, int ncomp,
                          hid_t mem_type, size_t from, size_t n)
{
    hsize_t start[2] = {w->first + from, 0}, count[2] = {n, (hsize_t)ncomp};
    hid_t mem = H5Screate_simple(rank, count, NULL);
    hid_t dxpl = H5Pcreate(H5P_DATASET_XFER);
    herr_t rc = mem < 0 || dxpl < 0 ? -1 : 0;
    if (rc == 0 && w->par)
        rc = H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE);
    if (rc == 0)
        rc = n ? H5Sselect_hyperslab(space, H5S_SELECT_SET, start, NULL, count, NULL)
               : H5Sselect_none(space);
    if (rc == 0 && !n)
        rc = H5Sselect_none(mem);
    if (rc == 0)
        rc = H5Dwrite(dset, mem_type, mem, space, dxpl, w->buf);
    mf_h5_close(&dxpl);
    mf_h5_close(&mem);
    return rc;
}

/* One dataset of w->rows rows and c->ncomp columns (rank 1 when ncomp ==
 * 1), this rank's w->count of them written PIECE_ROWS at a time (every
 * rank the same number of pieces). A failed write or close notes its errno
 * in w->io_errno: closing the dataset writes what HDF5 still holds of it
 * (its sieve buffer), so that close can fail on a full disk too. */
static int write_dataset(snap_writer *w, hid_t group, const char *group_name, const column *c)
{
    char what[MF_H5_PATH_MAX], detail[256];
    snprintf(what, sizeof what, "%s:/%s/%s", w->path, group_name, c->name);
    hsize_t dims[2] = {w->rows, (hsize_t)c->ncomp};
    int rank = c->ncomp == 1 ? 1 : 2;
    hid_t space = H5Screate_simple(rank, dims, NULL);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    hid_t dset = H5I_INVALID_HID;
    int rc = 0;
    if (space < 0 || dcpl < 0) {
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot create the dataspace (%s)", what,
                      mf_h5_error_detail(detail, sizeof detail));
        goto done;
    }
    if (w->compression > 0) {
        hsize_t chunk[2] = {w->rows < CHUNK_ROWS ? w->rows : CHUNK_ROWS, (hsize_t)c->ncomp};
        /* Shuffle groups the bytes of equal significance: gzip then finds
         * the repeated exponents of neighbouring doubles. Both lossless. */
        if (H5Pset_chunk(dcpl, rank, chunk) < 0 || H5Pset_shuffle(dcpl) < 0 ||
            H5Pset_deflate(dcpl, (unsigned)w->compression) < 0) {
            rc = MF_ERROR(MF_ERR_IO, "%s: cannot set up compression (%s)", what,
                          mf_h5_error_detail(detail, sizeof detail));
            goto done;
        }
    }
    dset = H5Dcreate2(group, c->name, c->file_type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    herr_t wrc = dset < 0 ? -1 : 0;
    int64_t pieces = (int64_t)((w->count + PIECE_ROWS - 1) / PIECE_ROWS);
    mf_parallel_max_i64(w->par, &pieces, 1);
    for (int64_t k = 0; wrc >= 0 && k < pieces; k++) {
        size_t from = (size_t)k * PIECE_ROWS;
        size_t n = from >= w->count ? 0 : w->count - from < PIECE_ROWS ? w->count - from
                                                                        : PIECE_ROWS;
        fill_piece(w, c, from, n);
        wrc = write_piece(w, dset, space, rank, c->ncomp, c->mem_type, from, n);
    }
    if (wrc < 0) {
        if (!w->io_errno)
            w->io_errno = errno;
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot write the dataset (%s)", what,
                      mf_h5_error_detail(detail, sizeof detail));
        goto done;
    }
    MF_CALL_GOTO(rc, mf_h5_attr_write_string(dset, "Units", mf_h5_unit(c->name), what), done);
    herr_t closed = H5Dclose(dset);
    dset = H5I_INVALID_HID;
    if (closed < 0) {
        if (!w->io_errno)
            w->io_errno = errno;
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot finish the dataset (%s)", what,
                      mf_h5_error_detail(detail, sizeof detail));
    }
done:
    mf_h5_close(&dset);
    mf_h5_close(&dcpl);
    mf_h5_close(&space);
    return rc;
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

    /* PointIndex (0..n-1, one vertex cell per particle) and Kind (the
     * group's kind) are for ParaView's Xdmf3 readers (the default for
     * .xdmf), which make no cells of a Polyvertex topology without
     * connectivity, and whose partitioned reader merges the groups. */
    const column core[] = {
        {"Coordinates", COLUMN_DOUBLE, p->pos, 3, 0, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE},
        {"Velocities", COLUMN_DOUBLE, p->vel, 3, 0, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE},
        {"ParticleIDs", COLUMN_ID, NULL, 1, 0, H5T_STD_I64LE, H5T_NATIVE_INT64},
        {"StorageIndex", COLUMN_STORAGE, NULL, 1, 0, H5T_STD_I64LE, H5T_NATIVE_INT64},
        {"PointIndex", COLUMN_POINT_INDEX, NULL, 1, 0, H5T_STD_I32LE, H5T_NATIVE_INT32},
        {"Kind", COLUMN_KIND, NULL, 1, kind, H5T_STD_U8LE, H5T_NATIVE_UINT8}};
    for (size_t k = 0; k < sizeof core / sizeof core[0]; k++)
        MF_CALL_GOTO(rc, write_dataset(w, g, group_name, &core[k]), done);

    for (int f = 0; f < p->nfields; f++) {
        const mf_field *field = &p->field[f];
        if (!field->output)
            continue;
        const bool dbl = field->type == MF_FIELD_DOUBLE;
        const column c = {field->name, dbl ? COLUMN_DOUBLE : COLUMN_INT32, field->data,
                          field->ncomp, 0, dbl ? H5T_IEEE_F64LE : H5T_STD_I32LE,
                          dbl ? H5T_NATIVE_DOUBLE : H5T_NATIVE_INT32};
        MF_CALL_GOTO(rc, write_dataset(w, g, group_name, &c), done);
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

/* A system call under HDF5 failed with err (a full disk: ENOSPC): which
 * file, why, that it is removed and that the snapshots before are whole;
 * HDF5's own message after. */
static int io_failure(const char *tmp, int err)
{
    char inner[1024];
    snprintf(inner, sizeof inner, "%s", mf_error_message());
    return MF_ERROR(MF_ERR_IO,
                    "cannot write %s: %s (errno %d); it is removed, the snapshots written "
                    "before are whole%s (%s)",
                    tmp, strerror(err), err,
                    err == ENOSPC || err == EDQUOT ? ": free space on that disk and restart "
                                                     "with -latestTime"
                                                   : "",
                    inner);
}

/* After a failed write on one rank: HDF5's descriptor of tmp (the sec2
 * driver's) is pointed at an anonymous file in memory (memfd_create, dup2)
 * and the file flushed there, so that what HDF5 still holds cannot fail
 * again for want of disk space and the file can be closed; tmp itself is
 * removed by the caller. Emptying tmp instead was not enough: the metadata
 * left to flush lies across the file, a page of disk each, more than a
 * nearly full disk has (a 300 KiB tmpfs, docs/notes/speed.md, memory4).
 * False if that cannot be done (then the file must stay open). */
static bool move_to_memory(hid_t file)
{
#ifdef __linux__
    int *fd = NULL;
    if (H5Fget_vfd_handle(file, H5P_DEFAULT, (void **)&fd) < 0 || !fd)
        return false;
    int mem = memfd_create("mpsflow-failed-snapshot", MFD_CLOEXEC);
    if (mem < 0)
        return false;
    bool moved = dup2(mem, *fd) >= 0;
    close(mem);
    return moved && H5Fflush(file, H5F_SCOPE_GLOBAL) >= 0;
#else
    (void)file;
    return false;
#endif
}

/* tmp written by HDF5 itself: the sec2 driver on one rank, MPI-IO on
 * several (collective calls throughout, each rank its block of rows).
 *
 * The file is flushed before it is closed: a close that fails (a disk that
 * fills while HDF5 writes its metadata) leaves HDF5 1.10 holding a file it
 * has half freed, and its next close (ours, or the library's at exit,
 * inside MPI_Finalize) crashes; a failed flush leaves the file whole and
 * open, to be flushed again. After a failure on one rank the file is
 * moved to memory (move_to_memory) and closed, everything of it. If that
 * cannot be done, the file is left open rather than closed into the
 * crash. Several ranks: HDF5 writes through MPI-IO, there is no descriptor
 * to move; a failure closes what it can, as before. */
static int write_file(snap_writer *w, const char *tmp, const mf_sim *sim,
                      const mf_dict *params, const int64_t counts[MF_NKINDS])
{
    char detail[256];
    hid_t fapl = mf_h5_fapl();
    if (fapl >= 0 &&
        (w->par ? H5Pset_fapl_mpio(fapl, mf_parallel_comm(w->par), MPI_INFO_NULL)
                : H5Pset_fapl_sec2(fapl)) < 0)
        mf_h5_close(&fapl);
    w->file = fapl < 0 ? H5I_INVALID_HID : H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    /* Take the message before any other HDF5 call clears the error stack. */
    mf_h5_error_detail(detail, sizeof detail);
    mf_h5_close(&fapl);
    if (w->file < 0)
        return MF_ERROR(MF_ERR_IO, "cannot create %s (%s)", tmp, detail);
    errno = 0;
    w->io_errno = 0;
    int rc = write_contents(w, sim, params, counts);
    if (rc == 0 && H5Fflush(w->file, H5F_SCOPE_GLOBAL) < 0) {
        w->io_errno = errno;
        rc = MF_ERROR(MF_ERR_IO, "cannot finish writing %s (%s)", tmp,
                      mf_h5_error_detail(detail, sizeof detail));
    }
    if (rc == 0) {
        herr_t closed = H5Fclose(w->file);
        w->file = H5I_INVALID_HID; /* never closed twice (above) */
        if (closed < 0) {
            w->io_errno = errno;
            rc = MF_ERROR(MF_ERR_IO, "cannot close %s (%s)", tmp,
                          mf_h5_error_detail(detail, sizeof detail));
        }
    }
    if (rc == 0)
        return 0;
    if (w->par || w->file < 0 || move_to_memory(w->file))
        close_all(&w->file);
    if (w->io_errno)
        return io_failure(tmp, w->io_errno);
    return mf_error_trace(rc, __FILE__, __LINE__, __func__);
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
    w.buf = malloc((n < PIECE_ROWS ? n : PIECE_ROWS) * (size_t)max_ncomp * sizeof(double));
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
    rc = write_file(&w, tmp, sim, params, counts);
    mf_h5_quiet_end(&quiet);
    free(w.index);
    free(w.buf);
    /* Every rank has closed the file (a collective close) before rank 0
     * renames it. */
    rc = mf_parallel_agree(sim->par, rc);
    const bool root = mf_parallel_is_root(sim->par);
    if (rc == 0 && root)
        rc = mf_rename_synced(tmp, path);
    if (rc != 0 && root)
        unlink(tmp); /* nothing half-written is left behind */
    rc = mf_parallel_agree(sim->par, rc);
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    return 0;
}
