/* snapshots.c: the snapshots of a case, in order, for post-processing. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_hdf5.h"
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
            if (mf_resize(indices, cap, sizeof **indices)) {
                closedir(d);
                return MF_ERROR(MF_ERR_MEMORY, "out of memory");
            }
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

int mf_snapshot_times(const char *case_dir, int **indices, double **times, size_t *n)
{
    *times = NULL;
    MF_CALL(mf_list_snapshots(case_dir, indices, n));
    *times = calloc(*n, sizeof **times);
    int rc = *times ? 0 : MF_ERROR(MF_ERR_MEMORY, "out of memory");
    char path[4400];
    for (size_t k = 0; k < *n && rc == 0; k++) {
        mf_hdf5_header h;
        mf_snapshot_path(case_dir, (*indices)[k], path, sizeof path);
        rc = mf_hdf5_read_header(path, &h);
        (*times)[k] = h.time;
    }
    if (rc != 0) {
        free(*indices);
        free(*times);
        *indices = NULL;
        *times = NULL;
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    return 0;
}

/* ---- -time selections (OpenFOAM's forms) ----------------------------------- */
static int parse_time(const char *text, double *out)
{
    char *end;
    errno = 0;
    *out = strtod(text, &end);
    if (end == text || errno || !isfinite(*out))
        return MF_ERROR(MF_ERR_INPUT, "-time: '%s' is not a time", text);
    return 0;
}

int mf_select_times(const char *spec, const double *t, size_t n, bool *sel)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", spec);
    for (char *save = NULL, *item = strtok_r(buf, ",", &save); item;
         item = strtok_r(NULL, ",", &save)) {
        char *colon = strchr(item, ':');
        if (colon) {
            double lo = -INFINITY, hi = INFINITY;
            *colon = '\0';
            if (*item)
                MF_CALL(parse_time(item, &lo));
            if (colon[1])
                MF_CALL(parse_time(colon + 1, &hi));
            double tol = 1e-9 * fmax(1.0, fmax(fabs(isfinite(lo) ? lo : 0), fabs(isfinite(hi) ? hi : 0)));
            bool any = false;
            for (size_t k = 0; k < n; k++)
                if (t[k] >= lo - tol && t[k] <= hi + tol)
                    sel[k] = any = true;
            if (!any)
                return MF_ERROR(MF_ERR_INPUT, "-time %s:%s: no snapshot in that range", item,
                                colon + 1);
        } else {
            double v;
            MF_CALL(parse_time(item, &v));
            size_t best = 0;
            for (size_t k = 1; k < n; k++)
                if (fabs(t[k] - v) < fabs(t[best] - v))
                    best = k;
            sel[best] = true;
        }
    }
    return 0;
}

