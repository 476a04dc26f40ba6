/* validate.c: `mpsflow validate -case DIR` runs the metric named in the
 * case's validation/metric on its snapshots, and says whether the run it
 * scores reached its endTime: the error of a run that stopped early is over
 * the part it ran, never to be read as a finished run's. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_app.h"
#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_post.h"
#include "mf_runs.h"

int mf_metric_evaluate(const char *case_dir, const char *name, const int *selected,
                       size_t nselected, const char *out_dir, double *error,
                       const mf_metric **used)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/validation/metric", case_dir);
    mf_dict *d = NULL;
    MF_CALL(mf_dict_parse_file(path, &d));
    const char *in_file = NULL;
    int rc = mf_dict_get_word(d, "metric", &in_file);
    const char *want = name ? name : in_file;
    const mf_metric *m = rc == 0 ? mf_metric_find(want) : NULL;
    if (rc == 0 && !m) {
        const char *names[32];
        char known[1024] = "";
        for (size_t k = 0; k < mf_nmetrics && k < 32; k++) {
            names[k] = mf_metrics[k]->name;
            snprintf(known + strlen(known), sizeof known - strlen(known), "%s%s", k ? ", " : "",
                     names[k]);
        }
        const char *hint = mf_did_you_mean(want, names, mf_nmetrics < 32 ? mf_nmetrics : 32);
        rc = MF_ERROR(MF_ERR_INPUT, "%s: unknown metric '%s'%s%s%s; known: %s",
                      name ? "-func" : path, want, hint ? " (did you mean '" : "",
                      hint ? hint : "", hint ? "'?)" : "", known);
    } else if (rc == 0 && strcmp(want, in_file) != 0) {
        rc = MF_ERROR(MF_ERR_INPUT,
                      "%s names the metric '%s'; '%s' needs its own settings there "
                      "(metric %s; ...)",
                      path, in_file, want, want);
    }
    mf_metric_ctx ctx = {case_dir, selected, nselected, out_dir};
    if (rc == 0)
        rc = m->evaluate(&ctx, d, error);
    if (rc == 0 && used)
        *used = m;
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

int mf_cmd_validate(const char *case_dir, double *error)
{
    char out_dir[4200], note[256];
    snprintf(out_dir, sizeof out_dir, "%s/validation", case_dir);
    const mf_metric *m = NULL;
    const bool summary = mf_run_status_note(case_dir, note, sizeof note);
    int rc = mf_metric_evaluate(case_dir, NULL, NULL, 0, out_dir, error, &m);
    if (rc != 0 && summary && note[0] && rc != MF_ERR_MEMORY)
        return MF_ERROR(rc, "%s (the run: %s)", mf_error_message(), note);
    MF_CALL(rc);
    if (note[0]) {
        printf("error %s = %.6g (not a finished run's: %s)\n", m->name, *error, note);
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: the run did not reach its endTime (%s); the error above is over "
                        "the part it ran",
                        case_dir, note);
    }
    printf("error %s = %.6g\n", m->name, *error);
    return 0;
}
