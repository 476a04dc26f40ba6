/* compare.c: `mpsflow compare -case DIR -solvers '(A B)' -resolutions '(l0 ...)'`
 *
 * Runs one case with several schemes at several particle spacings and, for
 * each run, records the error of the case's validation metric, the wall
 * time, the CPU (user + system) time, steps, pressure iterations and peak
 * memory. Writes
 * DIR/compare/compare.csv and compare.png (error against run time, log-log,
 * one line per scheme, points labelled by resolution) and prints which runs
 * are on the Pareto front (no other run is both faster and more accurate),
 * on wall time and on CPU time.
 *
 * -l0 VALUE is one resolution for every scheme; -endTime VALUE is every
 * run's end time.
 *
 * Schemes: see mf_case_apply_scheme (a variant of system/compareDict or a
 * solver module). Each run is a copy of the case in DIR/compare/<scheme>_l0_<l0>/, run by a
 * child mpsflow process so that its peak memory is its own.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_fs.h"
#include "mf_app.h"
#include "mf_post.h"
#include "mf_report.h"
#include "mf_runs.h"

typedef struct compare_row {
    char scheme[128];
    double l0, error;
    mf_child_result child;
    mf_run_summary summary;
} compare_row;

/* The run's time: wall seconds, or CPU (user + system) seconds. */
static double run_seconds(const compare_row *r, bool cpu)
{
    return cpu ? r->child.cpu_seconds : r->child.wall_seconds;
}

/* Row i is on the Pareto front when it has an error and no other run is at
 * least as accurate and as fast, and strictly better in one of the two. */
static bool on_pareto_front(const compare_row *rows, size_t n, size_t i, bool cpu)
{
    if (!isfinite(rows[i].error))
        return false;
    double ti = run_seconds(&rows[i], cpu);
    for (size_t j = 0; j < n; j++) {
        double tj = run_seconds(&rows[j], cpu);
        if (j != i && isfinite(rows[j].error) && rows[j].error <= rows[i].error && tj <= ti &&
            (rows[j].error < rows[i].error || tj < ti))
            return false;
    }
    return true;
}

/* compare.csv (whole or not at all: a failed write is an error, not a
 * table that silently ends early) and compare.png (a missing gnuplot is
 * said and skipped: the table is the result). */
static int write_report(const char *case_dir, compare_row *rows, size_t n)
{
    char path[4400];
    snprintf(path, sizeof path, "%s/compare/compare.csv", case_dir);
    mf_replace out;
    MF_CALL(mf_replace_open(&out, path, "w"));
    FILE *f = out.f;
    fprintf(f, "# mpsflow compare of %s: error from validation/metric; pareto: on wall "
               "time, pareto_cpu: on CPU (user + system) time\n", case_dir);
    /* New columns go at the end: scripts read the old ones by position. */
    fprintf(f, "scheme,l0,particles,error,wall_seconds,steps,pressure_iterations,peak_MB,"
               "status,criterion,pareto,cpu_seconds,pareto_cpu\n");
    for (size_t i = 0; i < n; i++) {
        bool pareto = on_pareto_front(rows, n, i, false);
        bool pareto_cpu = on_pareto_front(rows, n, i, true);
        fprintf(f, "%s,%g,%ld,%.6g,%.4g,%ld,%ld,%.1f,%s,%s,%s,%.4g,%s\n", rows[i].scheme,
                rows[i].l0, rows[i].summary.particles, rows[i].error,
                rows[i].child.wall_seconds, rows[i].summary.steps, rows[i].summary.iterations,
                rows[i].child.peak_mb, rows[i].summary.status, rows[i].summary.criterion,
                pareto ? "yes" : "no", rows[i].child.cpu_seconds, pareto_cpu ? "yes" : "no");
        if (pareto)
            printf("Pareto front: %s at l0 = %g (error %.4g, %.3g s)\n", rows[i].scheme,
                   rows[i].l0, rows[i].error, rows[i].child.wall_seconds);
        if (pareto_cpu)
            printf("Pareto front (CPU time): %s at l0 = %g (error %.4g, %.3g CPU s)\n",
                   rows[i].scheme, rows[i].l0, rows[i].error, rows[i].child.cpu_seconds);
    }
    MF_CALL(mf_replace_commit(&out, 0));
    /* One line per scheme, points labelled by l0. */
    mf_series series[64];
    double xs[64][32], ys[64][32];
    char labels_text[64][32][24];
    const char *labels[64][32];
    size_t ns = 0;
    for (size_t i = 0; i < n && ns < 64; i++) {
        size_t s = 0;
        while (s < ns && strcmp(series[s].title, rows[i].scheme) != 0)
            s++;
        if (s == ns) {
            series[ns] = (mf_series){rows[i].scheme, xs[ns], ys[ns], 0, "linespoints lw 2 pt 7",
                                     labels[ns]};
            ns++;
        }
        if (!isfinite(rows[i].error) || rows[i].error <= 0 || series[s].n == 32)
            continue;
        size_t k = series[s].n++;
        xs[s][k] = rows[i].child.wall_seconds;
        ys[s][k] = rows[i].error;
        snprintf(labels_text[s][k], sizeof labels_text[s][k], "%g", rows[i].l0);
        labels[s][k] = labels_text[s][k];
    }
    snprintf(path, sizeof path, "%s/compare/compare.png", case_dir);
    char title[512];
    char full[4096];
    const char *name = realpath(case_dir, full) ? full : case_dir;
    const char *slash = strrchr(name, '/');
    snprintf(title, sizeof title, "Error against run time: %.200s (labels: l0)",
             slash && slash[1] ? slash + 1 : name);
    mf_plot plot = {title, "wall time, s", "error (validation/metric)", true, true, NULL};
    if (mf_report_plot(path, &plot, series, ns) != 0) {
        fprintf(stderr, "%s\n", mf_error_message());
        mf_error_clear();
    }
    return 0;
}

int mf_cmd_compare(mf_registry *reg, const mf_options *o)
{
    const char *case_dir = o->case_dir, *solvers = o->solvers, *resolutions = o->resolutions;
    char end_text[64], one_l0[80];
    snprintf(end_text, sizeof end_text, "%.10g", o->end_time);
    if (o->l0 > 0 && resolutions)
        return MF_ERROR(MF_ERR_INPUT, "compare: give -resolutions '(l0 ...)' or -l0, not both");
    if (o->l0 > 0) { /* one spacing for every scheme */
        snprintf(one_l0, sizeof one_l0, "(%.10g)", o->l0);
        resolutions = one_l0;
    }
    if (!solvers || !resolutions)
        return MF_ERROR(MF_ERR_INPUT, "compare needs -solvers '(A B ...)' and -resolutions "
                        "'(l0 ...)', e.g. mpsflow compare -case tutorials/hydrostatic2D "
                        "-solvers '(MPS)' -resolutions '(0.02 0.01)'");
    mf_dict *stree = NULL, *rtree = NULL;
    const mf_value *slist = NULL, *rlist = NULL;
    int rc = mf_parse_option_list("-solvers", solvers, &stree, &slist);
    if (rc == 0)
        rc = mf_parse_option_list("-resolutions", resolutions, &rtree, &rlist);
    size_t nrows = rc == 0 ? slist->n * rlist->n : 0, n = 0;
    compare_row *rows = calloc(nrows ? nrows : 1, sizeof *rows);
    if (rc == 0 && !rows)
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    for (size_t s = 0; rc == 0 && s < slist->n; s++)
        for (size_t r = 0; rc == 0 && r < rlist->n; r++) {
            compare_row *row = &rows[n++];
            const char *scheme = slist->items[s]->text;
            if (!scheme) {
                rc = MF_ERROR(MF_ERR_INPUT, "-solvers: item %zu is not a name", s + 1);
                break;
            }
            rc = mf_value_number(rlist->items[r], "-resolutions", &row->l0);
            if (rc != 0)
                break;
            snprintf(row->scheme, sizeof row->scheme, "%s", scheme);
            char run_dir[4400], l0_text[64], log_path[4500];
            snprintf(l0_text, sizeof l0_text, "%g", row->l0);
            snprintf(run_dir, sizeof run_dir, "%s/compare/%s_l0_%s", case_dir, scheme, l0_text);
            rc = mf_case_copy(case_dir, run_dir);
            if (rc == 0)
                rc = mf_case_apply_scheme(run_dir, case_dir, scheme);
            if (rc != 0)
                break;
            snprintf(log_path, sizeof log_path, "%s/log.mpsflow", run_dir);
            char *argv[] = {NULL, "-case", run_dir, "-l0", l0_text, "-quiet",
                            o->end_time > 0 ? "-endTime" : NULL, end_text, NULL};
            printf("compare: %s at l0 = %s ... ", scheme, l0_text);
            rc = mf_run_child(argv, log_path, &row->child);
            if (rc != 0)
                break;
            mf_read_run_summary(run_dir, &row->summary);
            row->error = NAN;
            if (row->child.exit_status == 0) {
                if (mf_cmd_validate(reg, run_dir, &row->error) != 0) {
                    fprintf(stderr, "  validate failed: %s\n", mf_error_message());
                    mf_error_clear();
                }
            } else {
                printf("%s (%s); see %s\n", row->summary.status, row->summary.criterion,
                       log_path);
            }
            printf("  %.3g s (CPU %.3g s), %ld steps, %ld pressure iterations, %.0f MB\n",
                   row->child.wall_seconds, row->child.cpu_seconds, row->summary.steps,
                   row->summary.iterations, row->child.peak_mb);
        }
    if (rc == 0)
        rc = write_report(case_dir, rows, n);
    if (rc == 0)
        printf("Table: %s/compare/compare.csv, plot: %s/compare/compare.png\n", case_dir,
               case_dir);
    free(rows);
    mf_dict_free(stree);
    mf_dict_free(rtree);
    return rc;
}
