/* fs.c: the file-system helpers of mf_fs.h. */
#include "mf_fs.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

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

/* fsync of a file or a folder by name. */
static int fsync_path(const char *path, int flags)
{
    int fd = open(path, flags);
    if (fd < 0)
        return MF_ERROR(MF_ERR_IO, "cannot open %s: %s", path, strerror(errno));
    int rc = 0;
    /* EINVAL: the file system does not sync this kind of file (some do not
     * sync folders); nothing more we can do for durability there. */
    if (fsync(fd) != 0 && errno != EINVAL)
        rc = MF_ERROR(MF_ERR_IO, "cannot sync %s: %s", path, strerror(errno));
    close(fd);
    return rc;
}

int mf_rename_synced(const char *tmp, const char *final)
{
    MF_CALL(fsync_path(tmp, O_RDONLY));
    if (rename(tmp, final) != 0)
        return MF_ERROR(MF_ERR_IO, "cannot rename %s to %s: %s", tmp, final, strerror(errno));
    char dir[4608];
    const char *slash = strrchr(final, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if ((size_t)(slash - final) < sizeof dir)
        snprintf(dir, sizeof dir, "%.*s", slash == final ? 1 : (int)(slash - final), final);
    else
        return 0;
    MF_CALL(fsync_path(dir, O_RDONLY | O_DIRECTORY));
    return 0;
}

int mf_replace_open(mf_replace *r, const char *path, const char *mode)
{
    r->f = NULL;
    r->path = path;
    if (snprintf(r->tmp, sizeof r->tmp, "%s.tmp", path) >= (int)sizeof r->tmp)
        return MF_ERROR(MF_ERR_INPUT, "path too long: %s", path);
    r->f = fopen(r->tmp, mode);
    if (!r->f)
        return MF_ERROR(MF_ERR_IO, "%s: cannot open for writing (%s)", r->tmp, strerror(errno));
    return 0;
}

int mf_replace_commit(mf_replace *r, int status)
{
    if (!r->f)
        return status ? status : MF_ERROR(MF_ERR_INTERNAL, "%s: not open", r->tmp);
    /* fflush first: a write that fails only when the buffer goes out (a full
     * disk) shows in errno here, where fclose would lose which it was. */
    int failed = fflush(r->f) != 0 || ferror(r->f);
    int err = failed ? errno : 0;
    if (fclose(r->f) != 0 && !failed) {
        failed = 1;
        err = errno;
    }
    r->f = NULL;
    if (status == 0 && failed)
        status = MF_ERROR(MF_ERR_IO, "%s: write failed (%s)", r->path,
                          err ? strerror(err) : "stream error");
    if (status == 0)
        status = mf_rename_synced(r->tmp, r->path);
    if (status != 0)
        remove(r->tmp); /* nothing half-written is left behind */
    return status;
}
