/* mf_fs.h: file-system helpers. */
#ifndef MF_FS_H
#define MF_FS_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

/* Create the folder `path`, whose parent must exist (mkdir). A path that
 * exists already is fine if it is a folder; otherwise, or when the folder
 * cannot be created, MF_ERR_IO naming the path and the reason. */
int mf_mkdir(const char *path);
/* The same, creating any missing parent too (mkdir -p). */
int mf_mkdir_p(const char *path);

#pragma GCC visibility pop
#endif
