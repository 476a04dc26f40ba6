/* mf_fs.h: file-system helpers. */
#ifndef MF_FS_H
#define MF_FS_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdio.h>

/* Create the folder `path`, whose parent must exist (mkdir). A path that
 * exists already is fine if it is a folder; otherwise, or when the folder
 * cannot be created, MF_ERR_IO naming the path and the reason. */
int mf_mkdir(const char *path);
/* The same, creating any missing parent too (mkdir -p). */
int mf_mkdir_p(const char *path);

/* A file written whole or not at all. The text goes to "<path>.tmp";
 * mf_replace_commit syncs it, renames it over path and syncs the folder, so
 * a crash, a kill or a full disk leaves the old file or the new one, never
 * half of one, and no .tmp (a .tmp left by a killed process is a write that
 * never finished: driver/app/stale_tmp.c). `path` must outlive the write.
 *
 *     mf_replace out;
 *     MF_CALL(mf_replace_open(&out, path, "w"));
 *     int rc = write_everything(out.f);          // the caller's own status
 *     MF_CALL(mf_replace_commit(&out, rc));      // rc != 0: abandoned */
typedef struct mf_replace {
    FILE *f;
    const char *path;
    char tmp[4608];
} mf_replace;

/* Open "<path>.tmp" with fopen's mode ("w", "wb"). MF_ERR_IO naming it. */
int mf_replace_open(mf_replace *r, const char *path, const char *mode);
/* Close the stream; with status 0 and no write error, commit it over the
 * path (mf_rename_synced); otherwise remove the .tmp. Returns status when
 * it is not 0 (the caller's error travels on), else 0 or MF_ERR_IO naming
 * the path and the reason (a full disk: "No space left on device"). */
int mf_replace_commit(mf_replace *r, int status);
/* Make a finished file `tmp` the file `final`: fsync it, rename it, fsync
 * the folder (a rename is durable only once its folder is). For writers
 * that do not write through a FILE (the HDF5 snapshots). */
int mf_rename_synced(const char *tmp, const char *final);

#pragma GCC visibility pop
#endif
