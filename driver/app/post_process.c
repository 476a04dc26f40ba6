/* post_process.c: `mpsflow listTimes` and `mpsflow -postProcess`, after
 * OpenFOAM's foamListTimes and `<solver> -postProcess -func NAME`.
 *
 *   mpsflow listTimes [-case DIR] [-time T | -latestTime] [-verbose]
 *   mpsflow -postProcess -func NAME | -funcs '(A B)' [-time T | -latestTime]
 *
 * -postProcess replays over the snapshots already written, each NAME being
 *   - a function object of controlDict's `functions` (by its entry name),
 *     created as in a run (its libs loaded) and given every selected
 *     snapshot in time order: execute, then write, as at a write time;
 *   - or a function object type (a registered module, e.g. kineticEnergy
 *     with -libs, or surface), with its defaults, under that name;
 *   - or a validation metric (the one validation/metric names, with its
 *     settings there), evaluated over the selected snapshots.
 * Output goes to postProcessing/NAME/ (a metric's result.csv and .png too,
 * so that validate's validation/result.* are not overwritten). */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mf_app.h"
#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_fs.h"
#include "mf_hdf5.h"
#include "mf_post.h"
#include "mf_runs.h"
#include "mf_scene.h"
#include "mf_timetext.h"

/* The snapshots the -time / -latestTime options select: indices and times
 * (malloc'ed) of the selected ones, ascending. */
static int selected_snapshots(const mf_options *o, int **idx, double **times, size_t *n)
{
    size_t all = 0;
    MF_CALL(mf_snapshot_times(o->case_dir, idx, times, &all));
    bool *sel = calloc(all, sizeof *sel);
    int rc = sel ? 0 : MF_ERROR(MF_ERR_MEMORY, "out of memory");
    if (rc == 0 && o->latest_time)
        sel[all - 1] = true;
    else if (rc == 0 && o->time)
        rc = mf_select_times(o->time, *times, all, sel);
    else if (rc == 0)
        for (size_t k = 0; k < all; k++)
            sel[k] = true;
    size_t m = 0;
    for (size_t k = 0; rc == 0 && k < all; k++)
        if (sel[k]) {
            (*idx)[m] = (*idx)[k];
            (*times)[m] = (*times)[k];
            m++;
        }
    free(sel);
    *n = m;
    if (rc != 0) {
        free(*idx);
        free(*times);
        *idx = NULL;
        *times = NULL;
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    return 0;
}

int mf_cmd_list_times(const mf_options *o)
{
    int *idx = NULL;
    double *times = NULL;
    size_t n = 0;
    MF_CALL(selected_snapshots(o, &idx, &times, &n));
    char text[40], path[4400];
    int rc = 0;
    for (size_t k = 0; k < n && rc == 0; k++) {
        mf_time_text(times[k], text, sizeof text);
        if (o->log_level < MF_LOG_VERBOSE) {
            printf("%s\n", text);
            continue;
        }
        mf_hdf5_header h;
        mf_snapshot_path(o->case_dir, idx[k], path, sizeof path);
        rc = mf_hdf5_read_header(path, &h);
        if (rc == 0) {
            printf("%-12s step %-8ld %s ", text, h.step, path);
            for (int kind = 0; kind < MF_NKINDS; kind++)
                if (h.npart[kind])
                    printf(" %s %lld", mf_particle_kind_name(kind), (long long)h.npart[kind]);
            printf("\n");
        }
    }
    free(idx);
    free(times);
    return rc;
}

/* ---- -postProcess ------------------------------------------------------------ */

typedef struct replay {
    mf_app *app;
    const int *idx;
    const double *times;
    size_t n;
} replay;

/* Read snapshot k into app->sim (particles replaced). */
static int load(replay *r, size_t k)
{
    char path[4400];
    mf_snapshot_path(r->app->cs.dir, r->idx[k], path, sizeof path);
    mf_sim *sim = &r->app->sim;
    mf_particles_destroy(sim->p);
    sim->p = NULL;
    sim->dim = 0;
    sim->l0 = 0;
    MF_CALL(mf_hdf5_read_snapshot(path, sim));
    return 0;
}

static int replay_function(replay *r, const char *name, const mf_dict *fd, const char *type)
{
    mf_app *app = r->app;
    static const char *const extra[] = {"type", "libs", NULL};
    mf_module m = {0};
    char out_dir[4400];
    snprintf(out_dir, sizeof out_dir, "%s/postProcessing/%s", app->cs.dir, name);
    MF_CALL(load(r, 0));
    MF_CALL(mf_module_prepare(app->reg, MF_KIND_FUNCTION_OBJECT, type, fd, extra, NULL, &m));
    const mf_function_object_ops *ops = (const mf_function_object_ops *)m.info;
    int rc = ops->create(m.settings, &app->sim, out_dir, &m.data);
    for (size_t k = 0; rc == 0 && k < r->n; k++) {
        if (k > 0)
            rc = load(r, k);
        mf_log_printf(&app->log, MF_LOG_NORMAL, "Time = %g\n", app->sim.time);
        if (rc == 0)
            rc = ops->execute(m.data, &app->sim);
        if (rc == 0 && ops->write)
            rc = ops->write(m.data, &app->sim);
    }
    if (m.data)
        ops->destroy(m.data);
    mf_module_release(&m);
    MF_CALL(rc);
    mf_log_printf(&app->log, MF_LOG_QUIET, "-postProcess: %s (%s) over %zu snapshot(s) -> %s\n",
                  name, type, r->n, out_dir);
    return 0;
}

static int replay_metric(replay *r, const char *name)
{
    mf_app *app = r->app;
    char out_dir[4400], note[256];
    snprintf(out_dir, sizeof out_dir, "%s/postProcessing", app->cs.dir);
    MF_CALL(mf_mkdir(out_dir));
    snprintf(out_dir, sizeof out_dir, "%s/postProcessing/%s", app->cs.dir, name);
    MF_CALL(mf_mkdir(out_dir));
    double error = 0;
    mf_run_status_note(app->cs.dir, note, sizeof note);
    MF_CALL(mf_metric_evaluate(app->reg, app->cs.dir, name, r->idx, r->n, out_dir, &error, NULL));
    printf("error %s = %.6g%s%s%s\n", name, error, note[0] ? " (not a finished run's: " : "",
           note, note[0] ? ")" : "");
    mf_log_printf(&app->log, MF_LOG_QUIET, "-postProcess: %s over %zu snapshot(s) -> %s\n", name,
                  r->n, out_dir);
    return 0;
}

static int replay_one(replay *r, const char *name)
{
    mf_app *app = r->app;
    const mf_dict *fns = mf_dict_subdict(app->cs.control_dict, "functions");
    const mf_dict *fd = fns ? mf_dict_subdict(fns, name) : NULL;
    if (fd) {
        MF_CALL(mf_app_load_function_libs(app->reg, fd));
        const char *type;
        MF_CALL(mf_dict_get_word(fd, "type", &type));
        return replay_function(r, name, fd, type);
    }
    const mf_module_info *found = NULL;
    if (mf_registry_find(app->reg, MF_KIND_FUNCTION_OBJECT, name, &found) == 0)
        return replay_function(r, name, NULL, name);
    char fo_names[2048];
    snprintf(fo_names, sizeof fo_names, "%s", mf_error_message());
    mf_error_clear();
    MF_CALL(mf_app_load_metric_libs(app->reg, app->cs.dir)); /* a plugin's metric */
    if (mf_registry_find(app->reg, MF_KIND_METRIC, name, &found) == 0)
        return replay_metric(r, name);
    char metric_names[2048];
    snprintf(metric_names, sizeof metric_names, "%s", mf_error_message());
    mf_error_clear();
    char functions[1024] = "";
    for (size_t k = 0; fns && k < fns->n; k++)
        snprintf(functions + strlen(functions), sizeof functions - strlen(functions), "%s%s",
                 k ? " " : "", fns->entries[k]->key);
    return MF_ERROR(MF_ERR_INPUT,
                    "-func %s: not a function of %s/system/controlDict (%s), a function object "
                    "type, nor a metric. %s. %s",
                    name, app->cs.dir, functions[0] ? functions : "none", metric_names, fo_names);
}

int mf_cmd_post_process(mf_app *app)
{
    const mf_options *o = &app->opt;
    if (!o->func && !o->funcs)
        return MF_ERROR(MF_ERR_INPUT, "-postProcess needs -func NAME or -funcs '(A B)'");
    mf_log_init(&app->log, stdout, o->log_level);
    app->log.progress = false;
    app->sim.log = &app->log;
    app->sim.reg = app->reg;
    MF_CALL(mf_case_read(o->case_dir, &app->cs));
    MF_CALL(mf_app_load_case_libs(app));
    MF_CALL(mf_scene_read_fluids(app->cs.fluids, &app->sim));
    int *idx = NULL;
    double *times = NULL;
    size_t n = 0;
    MF_CALL(selected_snapshots(o, &idx, &times, &n));
    replay r = {app, idx, times, n};
    mf_dict *tree = NULL;
    const mf_value *list = NULL;
    int rc = 0;
    if (o->funcs)
        rc = mf_parse_option_list("-funcs", o->funcs, &tree, &list);
    if (rc == 0 && o->func)
        rc = replay_one(&r, o->func);
    for (size_t k = 0; rc == 0 && list && k < list->n; k++) {
        if (!list->items[k]->text)
            rc = MF_ERROR(MF_ERR_INPUT, "-funcs: item %zu is not a name", k + 1);
        else
            rc = replay_one(&r, list->items[k]->text);
    }
    mf_dict_free(tree);
    free(idx);
    free(times);
    MF_CALL(rc);
    mf_log_printf(&app->log, MF_LOG_QUIET, "End\n");
    return 0;
}
