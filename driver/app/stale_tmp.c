/* stale_tmp.c: temporary files a killed run left behind.
 *
 * Everything mpsflow writes into a case's output/ and postProcessing/ is
 * written as "<name>.tmp" and renamed when complete, so a file ending in
 * .tmp there is always a write that never finished (a run killed by
 * SIGKILL, a crash, a power cut): nothing will ever complete it, and
 * readers ignore it. A run removes such files when it starts, and says so. */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mf_app.h"
#include "mf_error.h"

static bool is_tmp_name(const char *name)
{
    size_t n = strlen(name);
    return n > 4 && strcmp(name + n - 4, ".tmp") == 0;
}

/* The .tmp files of dir, and of its sub-folders down to `depth` more levels. */
static int sweep(const char *dir, const char *shown, int depth, mf_log *log, int *removed)
{
    DIR *d = opendir(dir);
    if (!d)
        return errno == ENOENT || errno == ENOTDIR
                   ? 0
                   : MF_ERROR(MF_ERR_IO, "cannot list %s (%s)", dir, strerror(errno));
    int rc = 0;
    struct dirent *e;
    while (rc == 0 && (e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        char path[4400], label[4400];
        if (snprintf(path, sizeof path, "%s/%s", dir, e->d_name) >= (int)sizeof path ||
            snprintf(label, sizeof label, "%s/%s", shown, e->d_name) >= (int)sizeof label)
            continue;
        struct stat st;
        if (lstat(path, &st) != 0)
            continue;
        if (S_ISDIR(st.st_mode) && depth > 0) {
            rc = sweep(path, label, depth - 1, log, removed);
        } else if (S_ISREG(st.st_mode) && is_tmp_name(e->d_name)) {
            if (unlink(path) != 0) {
                rc = MF_ERROR(MF_ERR_IO, "cannot remove the stale temporary file %s (%s)", path,
                              strerror(errno));
                break;
            }
            (*removed)++;
            mf_log_printf(log, MF_LOG_QUIET,
                          "Removed %s: a temporary file left by a run stopped while writing it\n",
                          label);
        }
    }
    closedir(d);
    return rc;
}

int mf_app_remove_stale_tmp(const char *case_dir, mf_log *log, int *removed)
{
    static const char *const folders[] = {"output", "postProcessing"};
    *removed = 0;
    for (int k = 0; k < 2; k++) {
        char dir[4300];
        if (snprintf(dir, sizeof dir, "%s/%s", case_dir, folders[k]) >= (int)sizeof dir)
            return MF_ERROR(MF_ERR_INPUT, "case path too long: %s", case_dir);
        MF_CALL(sweep(dir, folders[k], 2, log, removed));
    }
    return 0;
}
