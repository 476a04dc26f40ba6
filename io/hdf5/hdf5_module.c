/* hdf5_module.c: the writer module "hdf5": snapshots into <case>/output,
 * the XDMF index beside them, and restart from the newest snapshot.
 *
 * Numbering continues after the newest snapshot already in the folder, so
 * a restart (or a second run) never overwrites earlier output; a leftover
 * .tmp of a crashed write is simply overwritten. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mf_alloc.h"
#include "hdf5_internal.h"
#include "mf_error.h"
#include "mf_fs.h"
#include "mf_hdf5.h"

typedef struct hdf5_settings {
    long compression;
} hdf5_settings;

static const mf_param hdf5_params[] = {
    {"compression", MF_PARAM_INT, "0", 0, 9, NULL, offsetof(hdf5_settings, compression),
     "gzip level of the snapshot datasets (0: none, contiguous; 1-9: chunked, shuffled)"},
};

typedef struct hdf5_writer {
    char case_dir[MF_H5_PATH_MAX];
    char output_dir[MF_H5_PATH_MAX];
    int compression;
    int next_index;       /* index of the next snapshot written */
    mf_xdmf_index xdmf;   /* the readable snapshots of the folder */
    int *written;         /* indices this writer wrote, oldest first (purgeWrite) */
    size_t nwritten, capwritten;
} hdf5_writer;

static int hdf5_create(const void *settings, const char *case_dir, void **data)
{
    hdf5_settings defaults = {.compression = 0};
    const hdf5_settings *s = settings ? settings : &defaults;
    if (s->compression < 0 || s->compression > 9)
        return MF_ERROR(MF_ERR_INPUT, "hdf5 writer: compression %ld is not in 0..9",
                        s->compression);
    if (s->compression > 0 && H5Zfilter_avail(H5Z_FILTER_DEFLATE) <= 0)
        return MF_ERROR(MF_ERR_LIBRARY,
                        "hdf5 writer: compression %ld asked for, but this HDF5 has no gzip "
                        "filter (use compression 0)",
                        s->compression);
    hdf5_writer *w = calloc(1, sizeof *w);
    if (!w)
        return MF_ERROR(MF_ERR_MEMORY, "hdf5 writer: out of memory");
    w->compression = (int)s->compression;
    int rc = 0;
    if (strlen(case_dir) >= sizeof w->case_dir) {
        rc = MF_ERROR(MF_ERR_INPUT, "case path too long: %s", case_dir);
        goto fail;
    }
    memcpy(w->case_dir, case_dir, strlen(case_dir) + 1);
    MF_CALL_GOTO(rc, mf_h5_output_dir(case_dir, w->output_dir, sizeof w->output_dir), fail);
    MF_CALL_GOTO(rc, mf_mkdir(w->output_dir), fail);

    int *indices;
    size_t n;
    MF_CALL_GOTO(rc, mf_h5_scan_snapshots(w->output_dir, &indices, &n), fail);
    /* After every file with a snapshot name, readable or not: an unreadable
     * file is evidence of a problem and must not be overwritten. */
    w->next_index = n > 0 ? indices[n - 1] + 1 : 0;
    free(indices);
    MF_CALL_GOTO(rc, mf_xdmf_index_scan(&w->xdmf, w->output_dir), fail);
    *data = w;
    return 0;
fail:
    mf_xdmf_index_free(&w->xdmf);
    free(w);
    return rc;
}

static int hdf5_write(void *data, const mf_sim *sim, const mf_dict *params)
{
    hdf5_writer *w = data;
    char path[MF_H5_PATH_MAX];
    MF_CALL(mf_h5_snapshot_path(w->output_dir, w->next_index, path, sizeof path));
    MF_CALL(mf_hdf5_write_snapshot(path, sim, params, w->compression));
    int index = w->next_index++;
    if (w->nwritten == w->capwritten) {
        size_t cap = w->capwritten ? 2 * w->capwritten : 64;
        if (mf_resize(&w->written, cap, sizeof *w->written))
            return MF_ERROR(MF_ERR_MEMORY, "hdf5 writer: out of memory");
        w->capwritten = cap;
    }
    w->written[w->nwritten++] = index;
    mf_xdmf_snap s;
    MF_CALL(mf_xdmf_describe(w->output_dir, index, &s));
    MF_CALL(mf_xdmf_index_add(&w->xdmf, &s));
    MF_CALL(mf_xdmf_index_write(&w->xdmf, w->output_dir));
    return 0;
}

static void hdf5_destroy(void *data)
{
    hdf5_writer *w = data;
    if (!w)
        return;
    mf_xdmf_index_free(&w->xdmf);
    free(w->written);
    free(w);
}

static int hdf5_read_latest(void *data, mf_sim *sim)
{
    hdf5_writer *w = data;
    int *indices;
    size_t n;
    MF_CALL(mf_h5_scan_snapshots(w->output_dir, &indices, &n));
    int newest = n > 0 ? indices[n - 1] : -1;
    free(indices);
    if (n == 0)
        return MF_ERROR(MF_ERR_INPUT,
                        "no snapshot to restart from in %s (run without -latestTime first)",
                        w->output_dir);
    char path[MF_H5_PATH_MAX];
    int index;
    MF_CALL(mf_hdf5_latest_snapshot(w->case_dir, path, sizeof path, &index));
    if (index < newest && sim->log)
        mf_log_printf(sim->log, MF_LOG_QUIET,
                      "--> mpsflow Warning: the snapshot(s) after snapshot_%06d.h5 up to "
                      "snapshot_%06d.h5 could not be read; restarting from %s\n",
                      index, newest, path);
    /* A restart goes on with the case's scene: a snapshot of another
     * spacing or dimension would be read, and blow up steps later. */
    mf_hdf5_header h;
    MF_CALL(mf_hdf5_read_header(path, &h));
    if (sim->dim != 0 && h.dim != sim->dim)
        return MF_ERROR(MF_ERR_INPUT,
                        "cannot restart: %s is %d-D, the case (constant/geometry) is %d-D", path,
                        h.dim, sim->dim);
    if (sim->l0 > 0 && fabs(h.l0 - sim->l0) > 1e-9 * sim->l0)
        return MF_ERROR(MF_ERR_INPUT,
                        "cannot restart: %s has particle spacing l0 = %.10g, this run %.10g "
                        "(constant/geometry or -l0): restart with -l0 %.10g, or start a new run",
                        path, h.l0, sim->l0, h.l0);
    MF_CALL(mf_hdf5_read_snapshot(path, sim));
    return 0;
}

/* purgeWrite: the snapshots this writer wrote, oldest first, are in
 * w->written; delete all but the newest `keep` (never snapshot 0, the
 * initial state), and list what is left. */
static int hdf5_purge(void *data, long keep)
{
    hdf5_writer *w = data;
    size_t purgeable = 0;
    for (size_t k = 0; k < w->nwritten; k++)
        purgeable += w->written[k] != 0;
    if (keep < 0 || purgeable <= (size_t)keep)
        return 0;
    size_t excess = purgeable - (size_t)keep, m = 0;
    char path[MF_H5_PATH_MAX];
    for (size_t k = 0; k < w->nwritten; k++) {
        int index = w->written[k];
        if (index == 0 || excess == 0) {
            w->written[m++] = index;
            continue;
        }
        MF_CALL(mf_h5_snapshot_path(w->output_dir, index, path, sizeof path));
        if (unlink(path) != 0 && errno != ENOENT)
            return MF_ERROR(MF_ERR_IO, "purgeWrite: cannot remove %s (%s)", path, strerror(errno));
        mf_xdmf_index_remove(&w->xdmf, index);
        excess--;
    }
    w->nwritten = m;
    MF_CALL(mf_xdmf_index_write(&w->xdmf, w->output_dir));
    return 0;
}

const mf_writer_ops mf_writer_hdf5 = {
    .info = {MF_ABI_VERSION, MF_KIND_WRITER, "hdf5",
             "HDF5 snapshots in output/ (restart with -latestTime) and an XDMF index for ParaView",
             hdf5_params, sizeof hdf5_params / sizeof hdf5_params[0], sizeof(hdf5_settings)},
    .create = hdf5_create,
    .write = hdf5_write,
    .destroy = hdf5_destroy,
    .read_latest = hdf5_read_latest,
    .purge = hdf5_purge,
};
