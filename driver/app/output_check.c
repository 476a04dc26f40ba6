/* output_check.c: a new run never mixes with an earlier one.
 *
 * A run that is not a restart (-latestTime, startFrom latestTime) refuses
 * to start when the case's output/ holds an earlier run (a snapshot, a
 * runSummary or resolvedParameters), as OpenFOAM's runApplication refuses
 * when its log exists; -overwrite removes output/ and postProcessing/
 * (what that run made) first. Nothing is deleted without being asked. */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mf_app.h"
#include "mf_error.h"

bool mf_app_is_restart(const mf_app *app)
{
    return app->opt.latest_time || !strcmp(app->cs.control.start_from, "latestTime");
}

/* What of an earlier run output/ holds: the number of snapshots, and
 * whether it has a runSummary or resolvedParameters. */
static int earlier_run(const char *dir, int *nsnap, bool *other)
{
    *nsnap = 0;
    *other = false;
    DIR *d = opendir(dir);
    if (!d) {
        if (errno == ENOENT)
            return 0;
        return MF_ERROR(MF_ERR_IO, "%s: cannot list (%s)", dir, strerror(errno));
    }
    struct dirent *e;
    while ((e = readdir(d))) {
        int index;
        char tail[8];
        if (sscanf(e->d_name, "snapshot_%d.h%7s", &index, tail) == 2 && !strcmp(tail, "5"))
            (*nsnap)++;
        else if (!strcmp(e->d_name, "runSummary") || !strcmp(e->d_name, "resolvedParameters"))
            *other = true;
    }
    closedir(d);
    return 0;
}

/* rm -r, not following symbolic links. */
static int remove_tree(const char *path)
{
    struct stat st;
    if (lstat(path, &st) != 0)
        return errno == ENOENT ? 0 : MF_ERROR(MF_ERR_IO, "%s: %s", path, strerror(errno));
    if (S_ISDIR(st.st_mode)) {
        DIR *d = opendir(path);
        if (!d)
            return MF_ERROR(MF_ERR_IO, "-overwrite: cannot list %s (%s)", path, strerror(errno));
        struct dirent *e;
        int rc = 0;
        char child[4400];
        while (rc == 0 && (e = readdir(d))) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
                continue;
            if (snprintf(child, sizeof child, "%s/%s", path, e->d_name) >= (int)sizeof child)
                rc = MF_ERROR(MF_ERR_IO, "-overwrite: path too long in %s", path);
            else
                rc = remove_tree(child);
        }
        closedir(d);
        MF_CALL(rc);
    }
    if (remove(path) != 0 && errno != ENOENT)
        return MF_ERROR(MF_ERR_IO, "-overwrite: cannot remove %s (%s)", path, strerror(errno));
    return 0;
}

int mf_app_check_output(mf_app *app)
{
    if (app->opt.dry_run || mf_app_is_restart(app))
        return 0;
    char out[4200], post[4200];
    snprintf(out, sizeof out, "%s/output", app->cs.dir);
    snprintf(post, sizeof post, "%s/postProcessing", app->cs.dir);
    int nsnap = 0;
    bool other = false;
    MF_CALL(earlier_run(out, &nsnap, &other));
    if (nsnap == 0 && !other)
        return 0;
    if (app->opt.overwrite) {
        MF_CALL(remove_tree(out));
        MF_CALL(remove_tree(post));
        mf_log_printf(&app->log, MF_LOG_QUIET,
                      "-overwrite: removed the earlier run's %s and %s\n", out, post);
        return 0;
    }
    return MF_ERROR(MF_ERR_INPUT,
                    "%s holds an earlier run (%d snapshot(s)%s): a new run would mix with it. "
                    "Continue it with -latestTime, replace it with -overwrite (removes output/ "
                    "and postProcessing/), or clean the case first (./Allclean)",
                    out, nsnap, other ? ", a run summary" : "");
}
