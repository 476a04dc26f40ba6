/* run_summary.c: output/runSummary, the machine-readable end of a run
 * (status, criterion, counts, times), read by `mpsflow compare` and the
 * stability sweep. Written even when the run fails. */
#include <errno.h>
#include <string.h>
#include <sys/stat.h>

#include "mf_app.h"
#include "mf_error.h"
#include "mf_fs.h"

/* "unstable (energy) at time ..." -> "energy"; other failures -> "" */
static void criterion_of(const char *message, char *out, size_t len)
{
    out[0] = '\0';
    const char *s = strstr(message, "unstable (");
    if (!s)
        return;
    s += strlen("unstable (");
    size_t n = strcspn(s, ")");
    if (n < len) {
        memcpy(out, s, n);
        out[n] = '\0';
    }
}

int mf_write_run_summary(const mf_app *app, int status)
{
    const mf_sim *sim0 = &app->sim;
    /* Collective: the particles of every rank; rank 0 writes the file. */
    int64_t particles = sim0->p ? (int64_t)sim0->p->n_owned : 0;
    mf_parallel_sum_i64(sim0->par, &particles, 1);
    if (!mf_parallel_is_root(sim0->par))
        return 0;
    char dir[4200], path[4300], criterion[64];
    snprintf(dir, sizeof dir, "%s/output", app->cs.dir);
    MF_CALL(mf_mkdir(dir));
    snprintf(path, sizeof path, "%s/runSummary", dir);
    const char *message = status ? mf_error_message() : "";
    criterion_of(message, criterion, sizeof criterion);
    mf_replace out;
    MF_CALL(mf_replace_open(&out, path, "w"));
    FILE *f = out.f;
    const mf_sim *sim = &app->sim;
    /* Stopped before endTime on purpose: stopAt, or a signal. */
    const bool stopped = status == 0 && app->run.stop_reason[0] &&
                         sim->time < sim->end_time * (1 - 1e-12);
    char stop_message[256];
    if (stopped) {
        snprintf(stop_message, sizeof stop_message, "%s at time %.10g", app->run.stop_reason,
                 sim->time);
        message = stop_message;
    }
    fprintf(f, "// How this run ended (written by %s).\n", mf_app_version());
    fprintf(f, "status              %s;\n",
            stopped       ? "stopped"
            : status == 0 ? "completed"
                          : (criterion[0] || status == MF_ERR_NUMERIC ? "unstable" : "failed"));
    fprintf(f, "criterion           %s;\n",
            stopped ? (app->run.stop_signal ? "signal" : "stopAt")
                    : criterion[0] ? criterion : (status ? "other" : "none"));
    fprintf(f, "message             \"");
    for (const char *c = message; *c; c++) /* a dictionary string: escape quotes */
        fprintf(f, "%s%c", (*c == '"' || *c == '\\') ? "\\" : "", *c == '\n' ? ' ' : *c);
    fprintf(f, "\";\n");
    fprintf(f, "solver              %s;\n", app->solver.info ? app->solver.info->name : "none");
    fprintf(f, "particleSpacing     %.10g;\n", sim->l0);
    fprintf(f, "particles           %lld;\n", (long long)particles);
    fprintf(f, "nProcs              %d;\n", mf_parallel_size(sim->par));
    fprintf(f, "time                %.10g;\n", sim->time);
    fprintf(f, "endTime             %.10g;\n", sim->end_time);
    fprintf(f, "steps               %ld;\n", app->run.steps);
    fprintf(f, "retries             %ld;\n", app->run.retries);
    fprintf(f, "pressureIterations  %ld;\n", sim->pressure_iterations);
    fprintf(f, "wallSeconds         %.6g;\n", app->run.wall_seconds);
    fprintf(f, "peakMemoryMB        %.6g;\n", mf_peak_memory() / 1048576.0);
    MF_CALL(mf_replace_commit(&out, 0));
    return 0;
}
