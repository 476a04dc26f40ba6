/* hdf5_files.c: the snapshot files of a case's output folder: their names,
 * finding them, committing a finished file under its real name, and
 * choosing the newest complete one for a restart. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mf_alloc.h"
#include "hdf5_internal.h"
#include "mf_error.h"
#include "mf_hdf5.h"

int mf_h5_output_dir(const char *case_dir, char *buf, size_t len)
{
    int w = snprintf(buf, len, "%s/output", case_dir);
    if (w < 0 || (size_t)w >= len)
        return MF_ERROR(MF_ERR_INPUT, "case path too long: %s", case_dir);
    return 0;
}

int mf_h5_snapshot_path(const char *output_dir, int index, char *buf, size_t len)
{
    int w = snprintf(buf, len, "%s/snapshot_%06d.h5", output_dir, index);
    if (w < 0 || (size_t)w >= len)
        return MF_ERROR(MF_ERR_INPUT, "output path too long: %s", output_dir);
    return 0;
}

/* snapshot_<digits>.h5 exactly: "snapshot_000001.h5.tmp" and other files
 * are not snapshots. */
static bool parse_snapshot_name(const char *name, int *index)
{
    static const char prefix[] = "snapshot_";
    if (strncmp(name, prefix, sizeof prefix - 1) != 0)
        return false;
    const char *s = name + sizeof prefix - 1;
    long value = 0;
    int ndigits = 0;
    while (*s >= '0' && *s <= '9') {
        if (++ndigits > 9)
            return false; /* beyond int range: not written by us */
        value = value * 10 + (*s - '0');
        s++;
    }
    if (ndigits == 0 || strcmp(s, ".h5") != 0)
        return false;
    *index = (int)value;
    return true;
}

static int compare_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

int mf_h5_scan_snapshots(const char *output_dir, int **indices, size_t *n)
{
    *indices = NULL;
    *n = 0;
    DIR *dir = opendir(output_dir);
    if (!dir) {
        if (errno == ENOENT)
            return 0;
        return MF_ERROR(MF_ERR_IO, "cannot list %s: %s", output_dir, strerror(errno));
    }
    int *list = NULL;
    size_t count = 0, cap = 0;
    int rc = 0;
    struct dirent *e;
    while ((e = readdir(dir)) != NULL) {
        int index;
        if (!parse_snapshot_name(e->d_name, &index))
            continue;
        if (count == cap) {
            size_t new_cap = cap ? 2 * cap : 64;
            if (mf_resize(&list, new_cap, sizeof *list)) {
                rc = MF_ERROR(MF_ERR_MEMORY, "out of memory listing %s", output_dir);
                break;
            }
            cap = new_cap;
        }
        list[count++] = index;
    }
    closedir(dir);
    if (rc != 0) {
        free(list);
        return rc;
    }
    if (count > 0)
        qsort(list, count, sizeof *list, compare_int);
    *indices = list;
    *n = count;
    return 0;
}

int mf_hdf5_latest_snapshot(const char *case_dir, char *path, size_t len, int *index)
{
    char output_dir[MF_H5_PATH_MAX], candidate[MF_H5_PATH_MAX];
    MF_CALL(mf_h5_output_dir(case_dir, output_dir, sizeof output_dir));
    int *indices;
    size_t n;
    MF_CALL(mf_h5_scan_snapshots(output_dir, &indices, &n));

    /* Newest first; a file that does not open or has no valid header is
     * skipped (and reported if nothing readable is found). */
    char first_failure[1024] = "";
    size_t nskipped = 0;
    for (size_t k = n; k-- > 0;) {
        int rc = mf_h5_snapshot_path(output_dir, indices[k], candidate, sizeof candidate);
        mf_hdf5_header h;
        if (rc == 0)
            rc = mf_hdf5_read_header(candidate, &h);
        if (rc != 0) {
            if (nskipped++ == 0)
                snprintf(first_failure, sizeof first_failure, "%s", mf_error_message());
            mf_error_clear();
            continue;
        }
        if (path && len > 0) {
            if (strlen(candidate) >= len) {
                free(indices);
                return MF_ERROR(MF_ERR_INPUT, "snapshot path too long: %s", candidate);
            }
            memcpy(path, candidate, strlen(candidate) + 1);
        }
        if (index)
            *index = indices[k];
        free(indices);
        return 0;
    }
    free(indices);
    if (nskipped > 0)
        return MF_ERROR(MF_ERR_INPUT,
                        "no readable snapshot in %s (%zu snapshot file(s) could not be read; "
                        "newest: %s)",
                        output_dir, nskipped, first_failure);
    return MF_ERROR(MF_ERR_INPUT, "no snapshot in %s", output_dir);
}
