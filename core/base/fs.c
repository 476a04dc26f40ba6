/* fs.c: the file-system helpers of mf_fs.h. */
#include "mf_fs.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mf_error.h"

int mf_mkdir(const char *dir)
{
    if (mkdir(dir, 0777) == 0)
        return 0;
    if (errno != EEXIST)
        return MF_ERROR(MF_ERR_IO, "%s: cannot create (%s)", dir, strerror(errno));
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return MF_ERROR(MF_ERR_IO, "%s exists but is not a folder", dir);
    return 0;
}

int mf_mkdir_p(const char *path)
{
    size_t n = strlen(path);
    if (n == 0)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_mkdir_p: empty path");
    char *buf = malloc(n + 1);
    if (!buf)
        return MF_ERROR(MF_ERR_MEMORY, "mf_mkdir_p: out of memory");
    memcpy(buf, path, n + 1);
    int rc = 0;
    for (char *s = buf + 1; *s && rc == 0; s++)
        if (*s == '/' && s[-1] != '/') {
            *s = '\0';
            rc = mf_mkdir(buf);
            *s = '/';
        }
    if (rc == 0)
        rc = mf_mkdir(buf);
    free(buf);
    return rc;
}
