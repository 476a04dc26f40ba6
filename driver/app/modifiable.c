/* modifiable.c: runTimeModifiable, as OpenFOAM does it: between steps, if
 * system/controlDict changed on disk (its modification time or size), read
 * it again and apply what changed of the keys a running loop can take:
 * endTime, stopAt, writeInterval, deltaT, maxCo, maxDi, maxDeltaT,
 * minDeltaT, maxRetries, purgeWrite, runTimeModifiable. A key whose value in
 * the file did not change keeps what the run uses (so -endTime stays until
 * the file's endTime is edited). Other changes are reported and not
 * applied. A file that does not read (an editor's half-saved state, a typo)
 * is reported, and the run goes on with the values it has. */
#include <string.h>
#include <sys/stat.h>

#include "mf_app.h"
#include "mf_error.h"

static bool same_stamp(const struct stat *a, const mf_control_watch *w)
{
    return a->st_mtim.tv_sec == w->mtime.tv_sec && a->st_mtim.tv_nsec == w->mtime.tv_nsec &&
           a->st_size == w->size;
}

static int stamp(mf_app *app, struct stat *st)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/system/controlDict", app->cs.dir);
    if (stat(path, st) != 0)
        return -1;
    return 0;
}

int mf_app_watch_control(mf_app *app)
{
    mf_control_watch *w = &app->control_watch;
    w->file = app->cs.control;
    struct stat st;
    if (stamp(app, &st) == 0) {
        w->mtime = st.st_mtim;
        w->size = st.st_size;
    }
    app->run.modified = mf_app_control_modified;
    app->run.modified_ctx = app;
    return 0;
}

void mf_app_unwatch_control(mf_app *app)
{
    mf_dict_free(app->control_watch.tree);
    app->control_watch.tree = NULL;
}

static void say(mf_app *app, const char *key, double from, double to)
{
    mf_log_printf(&app->log, MF_LOG_QUIET, "--> controlDict changed: %s %g -> %g (at time %g)\n",
                  key, from, to, app->sim.time);
}

/* A key whose value in the file changed: the run takes it (and `also`, a
 * copy kept elsewhere, may be NULL). */
static void take(mf_app *app, const char *key, double fresh, double before, double *dst)
{
    if (fresh == before)
        return;
    say(app, key, *dst, fresh);
    *dst = fresh;
}

static void take_long(mf_app *app, const char *key, long fresh, long before, long *dst)
{
    if (fresh == before)
        return;
    say(app, key, (double)*dst, (double)fresh);
    *dst = fresh;
}

int mf_app_control_modified(void *ctx, mf_run *run)
{
    mf_app *app = ctx;
    mf_control_watch *w = &app->control_watch;
    struct stat st;
    if (stamp(app, &st) != 0 || same_stamp(&st, w))
        return 0;
    w->mtime = st.st_mtim;
    w->size = st.st_size;
    mf_control fresh;
    mf_dict *tree = NULL;
    if (mf_case_reread_control(app->cs.dir, &fresh, &tree) != 0) {
        mf_log_printf(&app->log, MF_LOG_QUIET,
                      "--> mpsflow Warning: %s; the run goes on with the values it has\n",
                      mf_error_message());
        mf_error_clear();
        return 0;
    }
    mf_run_control *c = &run->ctl;
    mf_sim *sim = run->sim;
    const mf_control *was = &w->file;
    take(app, "endTime", fresh.end_time, was->end_time, &sim->end_time);
    if (strcmp(fresh.stop_at, was->stop_at) != 0) {
        mf_stop_at s = MF_STOP_END_TIME;
        MF_CALL(mf_stop_at_parse(fresh.stop_at, &s));
        mf_log_printf(&app->log, MF_LOG_QUIET, "--> controlDict changed: stopAt %s -> %s (at time %g)\n",
                      mf_stop_at_name(c->stop_at), fresh.stop_at, sim->time);
        c->stop_at = s;
    }
    take(app, "writeInterval", fresh.write_interval, was->write_interval, &c->write_interval);
    take(app, "deltaT", fresh.delta_t, was->delta_t, &c->delta_t);
    take(app, "maxCo", fresh.max_co, was->max_co, &c->max_co);
    take(app, "maxDi", fresh.max_di, was->max_di, &c->max_di);
    take(app, "maxDeltaT", fresh.max_delta_t, was->max_delta_t, &c->max_delta_t);
    take(app, "minDeltaT", fresh.min_delta_t, was->min_delta_t, &c->min_delta_t);
    take_long(app, "maxRetries", fresh.max_retries, was->max_retries, &c->max_retries);
    take_long(app, "purgeWrite", fresh.purge_write, was->purge_write, &c->purge_write);
    if (!fresh.run_time_modifiable) {
        mf_log_printf(&app->log, MF_LOG_QUIET,
                      "--> controlDict changed: runTimeModifiable no: no more re-reading\n");
        run->modified = NULL;
    }
    const bool others = fresh.start_time != was->start_time ||
                        fresh.adjust_time_step != was->adjust_time_step ||
                        strcmp(fresh.write_control, was->write_control) != 0 ||
                        strcmp(fresh.writer, was->writer) != 0 ||
                        strcmp(fresh.start_from, was->start_from) != 0;
    if (others)
        mf_log_printf(&app->log, MF_LOG_QUIET,
                      "--> mpsflow Warning: controlDict: startTime, adjustTimeStep, writeControl, "
                      "writer and startFrom are not changed during a run (nor libs, functions, "
                      "watch)\n");
    /* The strings of fresh point into tree: keep it as long as they are compared. */
    mf_dict_free(w->tree);
    w->tree = tree;
    w->file = fresh;
    return 0;
}
