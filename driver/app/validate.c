/* validate.c: `mpsflow validate -case DIR` runs the metric named in the
 * case's validation/metric on its snapshots, and says whether the run it
 * scores reached its endTime: the error of a run that stopped early is over
 * the part it ran, never to be read as a finished run's. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mf_app.h"
#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_post.h"
#include "mf_runs.h"

/* The keys of validation/metric the host reads besides the metric's own:
 * FoamFile, libs (plugins to load first), and the metric's extra_keys. */
static int metric_extra_keys(const mf_metric_ops *m, const char **keys, size_t cap)
{
    size_t n = 0;
    keys[n++] = "FoamFile";
    keys[n++] = "libs";
    for (size_t k = 0; m->extra_keys && m->extra_keys[k]; k++) {
        if (n + 1 >= cap)
            return MF_ERROR(MF_ERR_INPUT, "metric '%s' has more than %zu extra keys",
                            m->info.name, cap - 3);
        keys[n++] = m->extra_keys[k];
    }
    keys[n] = NULL;
    return 0;
}

int mf_app_load_metric_libs(mf_registry *reg, const char *case_dir)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/validation/metric", case_dir);
    if (access(path, F_OK) != 0)
        return 0;
    mf_dict *d = NULL;
    MF_CALL(mf_dict_parse_file(path, &d));
    int rc = mf_app_load_function_libs(reg, d);
    mf_dict_free(d);
    return rc;
}

int mf_metric_evaluate(mf_registry *reg, const char *case_dir, const char *name,
                       const int *selected, size_t nselected, const char *out_dir,
                       double *error, const mf_metric_ops **used)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/validation/metric", case_dir);
    mf_dict *d = NULL;
    MF_CALL(mf_dict_parse_file(path, &d));
    const char *in_file = NULL;
    int rc = mf_app_load_function_libs(reg, d); /* a plugin's metric: libs ("libfoo.so"); */
    if (rc == 0)
        rc = mf_dict_get_word(d, "metric", &in_file);
    const char *want = name ? name : in_file;
    const mf_module_info *info = NULL;
    char where[4400];
    if (rc == 0 && mf_registry_find(reg, MF_KIND_METRIC, want, &info) != 0) {
        const mf_entry *e = mf_dict_find(d, "metric");
        rc = MF_ERROR(MF_ERR_INPUT, "%s: %s",
                      name ? "-func" : mf_loc_str(e->loc, where, sizeof where),
                      mf_error_message());
    } else if (rc == 0 && strcmp(want, in_file) != 0) {
        rc = MF_ERROR(MF_ERR_INPUT,
                      "%s names the metric '%s'; '%s' needs its own settings there "
                      "(metric %s; ...)",
                      path, in_file, want, want);
    }
    const mf_metric_ops *m = (const mf_metric_ops *)info;
    if (rc == 0 && !m->evaluate)
        rc = MF_ERROR(MF_ERR_INPUT, "metric '%s' has no evaluate", want);
    const char *extra[20];
    if (rc == 0)
        rc = metric_extra_keys(m, extra, sizeof extra / sizeof extra[0]);
    mf_module mod = {0};
    if (rc == 0)
        rc = mf_module_prepare(reg, MF_KIND_METRIC, want, d, extra, NULL, &mod);
    mf_metric_ctx ctx = {case_dir, selected, nselected, out_dir, d, mf_metric_snapshots,
                         mf_metric_read_snapshot};
    if (rc == 0)
        rc = m->evaluate(mod.settings, &ctx, error);
    if (rc == 0 && used)
        *used = m;
    mf_module_release(&mod);
    mf_dict_free(d);
    return rc;
}

/* "" when output/runSummary says the run reached its endTime, else why not
 * ("unstable (timeStep) at time 0.4 of endTime 0.6"). Returns whether there
 * is a runSummary. Clears the error trace (call it before anything that
 * may fail). */
bool mf_run_status_note(const char *case_dir, char *note, size_t len)
{
    mf_run_summary s;
    mf_read_run_summary(case_dir, &s);
    note[0] = '\0';
    if (!strcmp(s.status, "completed"))
        return true;
    if (!strcmp(s.status, "no summary")) {
        snprintf(note, len, "no output/runSummary: the run did not finish (killed?)");
        return false;
    }
    snprintf(note, len, "%s%s%s%s at time %.6g of endTime %.6g", s.status,
             s.criterion[0] && strcmp(s.criterion, "none") ? " (" : "",
             s.criterion[0] && strcmp(s.criterion, "none") ? s.criterion : "",
             s.criterion[0] && strcmp(s.criterion, "none") ? ")" : "", s.time, s.end_time);
    return true;
}

int mf_cmd_validate(mf_registry *reg, const char *case_dir, double *error)
{
    char out_dir[4200], note[256];
    snprintf(out_dir, sizeof out_dir, "%s/validation", case_dir);
    const mf_metric_ops *m = NULL;
    const bool summary = mf_run_status_note(case_dir, note, sizeof note);
    int rc = mf_metric_evaluate(reg, case_dir, NULL, NULL, 0, out_dir, error, &m);
    if (rc != 0 && summary && note[0] && rc != MF_ERR_MEMORY)
        return MF_ERROR(rc, "%s (the run: %s)", mf_error_message(), note);
    MF_CALL(rc);
    if (note[0]) {
        printf("error %s = %.6g (not a finished run's: %s)\n", m->info.name, *error, note);
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: the run did not reach its endTime (%s); the error above is over "
                        "the part it ran",
                        case_dir, note);
    }
    printf("error %s = %.6g\n", m->info.name, *error);
    return 0;
}
