/* snapshots.c: the snapshots of a case, in order, for post-processing. */
#include <dirent.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_post.h"

static int by_index(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

int mf_list_snapshots(const char *case_dir, int **indices, size_t *n)
{
    char dir[4200];
    snprintf(dir, sizeof dir, "%s/output", case_dir);
    *indices = NULL;
    *n = 0;
    DIR *d = opendir(dir);
    if (!d)
        return MF_ERROR(MF_ERR_INPUT, "%s: no output folder: run the case first (mpsflow -case %s)",
                        dir, case_dir);
    size_t cap = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        int idx;
        char tail[8];
        if (sscanf(e->d_name, "snapshot_%d.h%7s", &idx, tail) != 2 || strcmp(tail, "5") != 0)
            continue;
        if (*n == cap) {
            cap = cap ? 2 * cap : 64;
            int *grown = realloc(*indices, cap * sizeof *grown);
            if (!grown) {
                closedir(d);
                return MF_ERROR(MF_ERR_MEMORY, "out of memory");
            }
            *indices = grown;
        }
        (*indices)[(*n)++] = idx;
    }
    closedir(d);
    if (*n == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: no snapshot_*.h5: run the case first", dir);
    qsort(*indices, *n, sizeof **indices, by_index);
    return 0;
}

void mf_snapshot_path(const char *case_dir, int index, char *path, size_t len)
{
    snprintf(path, len, "%s/output/snapshot_%06d.h5", case_dir, index);
}
