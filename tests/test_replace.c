/* test_replace.c: a file written whole or not at all (mf_replace, mf_fs.h).
 *
 * The failures a user meets are made here on purpose: the file-size limit
 * (RLIMIT_FSIZE, with SIGXFSZ ignored, writes then fail with EFBIG, as a
 * full disk fails them with ENOSPC) stops a write half-way, and a caller
 * that fails while writing abandons its file. In every case the old file
 * must be left exactly as it was, no .tmp beside it, and the error must
 * name the path. */
#include <errno.h>
#include <signal.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mf_fs.h"
#include "mf_test.h"

static char dir[256];

static void slurp(const char *path, char *buf, size_t len)
{
    buf[0] = '\0';
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    size_t n = fread(buf, 1, len - 1, f);
    buf[n] = '\0';
    fclose(f);
}

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Write `bytes` bytes of 'x' through mf_replace; status is the caller's. */
static int write_x(const char *path, size_t bytes, int status)
{
    mf_replace r;
    MF_CALL(mf_replace_open(&r, path, "w"));
    for (size_t k = 0; k < bytes; k++)
        fputc('x', r.f);
    return mf_replace_commit(&r, status);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/mf_test_replace_%d", (int)getpid());
    CHECK(mf_mkdir(dir) == 0);
    char path[400], tmp[420], buf[8192];
    snprintf(path, sizeof path, "%s/summary", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);

    /* 1. A write that succeeds replaces the file. */
    mf_replace r;
    CHECK(mf_replace_open(&r, path, "w") == 0);
    fprintf(r.f, "old contents\n");
    CHECK(mf_replace_commit(&r, 0) == 0);
    slurp(path, buf, sizeof buf);
    CHECK(strcmp(buf, "old contents\n") == 0);
    CHECK(!exists(tmp));

    /* 2. The caller's own failure abandons the write, and its code is what
     * comes back. */
    CHECK(write_x(path, 100, MF_ERR_NUMERIC) == MF_ERR_NUMERIC);
    slurp(path, buf, sizeof buf);
    CHECK(strcmp(buf, "old contents\n") == 0);
    CHECK(!exists(tmp));

    /* 3. The disk fills half-way (the size limit): MF_ERR_IO naming the
     * path, the old file intact, no .tmp. */
    signal(SIGXFSZ, SIG_IGN);
    struct rlimit old, lim;
    CHECK(getrlimit(RLIMIT_FSIZE, &old) == 0);
    lim = old;
    lim.rlim_cur = 4096;
    CHECK(setrlimit(RLIMIT_FSIZE, &lim) == 0);
    int rc = write_x(path, 100000, 0);
    CHECK_MSG(rc == MF_ERR_IO, "rc %d", rc);
    CHECK_MSG(strstr(mf_error_message(), path) != NULL, "message: %s", mf_error_message());
    slurp(path, buf, sizeof buf);
    CHECK(strcmp(buf, "old contents\n") == 0);
    CHECK(!exists(tmp));
    /* ... and a write that fits still goes through under the limit. */
    CHECK(write_x(path, 1000, 0) == 0);
    slurp(path, buf, sizeof buf);
    CHECK(strlen(buf) == 1000);
    CHECK(setrlimit(RLIMIT_FSIZE, &old) == 0);

    /* 4. A folder that does not exist: an error naming the .tmp, nothing made. */
    char missing[400];
    snprintf(missing, sizeof missing, "%s/no/such/file", dir);
    rc = mf_replace_open(&r, missing, "w");
    CHECK(rc == MF_ERR_IO);
    CHECK(strstr(mf_error_message(), "no/such/file.tmp") != NULL);

    /* 5. mf_rename_synced of a file that is not there fails cleanly. */
    char absent[420];
    snprintf(absent, sizeof absent, "%s/absent.tmp", dir);
    CHECK(mf_rename_synced(absent, path) == MF_ERR_IO);
    slurp(path, buf, sizeof buf);
    CHECK(strlen(buf) == 1000);

    remove(path);
    rmdir(dir);
    return mf_test_summary("replace");
}
