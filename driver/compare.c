/* compare.c: `mpsflow compare -case DIR -solvers '(A B)' -resolutions '(l0 ...)'`
 *
 * Runs one case with several schemes at several particle spacings and, for
 * each run, records the error of the case's validation metric, the wall
 * time, steps, pressure iterations and peak memory. Writes
 * DIR/compare/compare.csv and compare.png (error against run time, log-log,
 * one line per scheme, points labelled by resolution) and prints which runs
 * are on the Pareto front (no other run is both faster and more accurate).
 *
 * A scheme is a variant named in DIR/system/compareDict,
 *     variants { QUICK { solver MAFL; MAFLCoeffs { convection QUICK; } } }
 * whose entries replace those of system/solverDict (sub-dictionaries merge),
 * or, when no variant has that name, a solver module with its defaults.
 * Each run is a copy of the case in DIR/compare/<scheme>_l0_<l0>/, run by a
 * child mpsflow process so that its peak memory is its own.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_post.h"
#include "mf_report.h"
#include "mf_run.h"

typedef struct compare_row {
    char scheme[128];
    double l0, error, wall, peak_mb;
    long steps, iterations, particles;
    char status[32], criterion[64];
} compare_row;

static int run_command(char *const argv[], const char *log_path, double *wall, double *peak_mb,
                       int *exit_status)
{
    double t0 = mf_wall_seconds();
    pid_t pid = fork();
    if (pid < 0)
        return MF_ERROR(MF_ERR_IO, "cannot start a run (%s)", strerror(errno));
    if (pid == 0) {
        FILE *log = freopen(log_path, "w", stdout);
        if (log)
            dup2(fileno(stdout), 2);
        execv(argv[0], argv);
        _exit(127);
    }
    int status = 0;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) < 0)
        return MF_ERROR(MF_ERR_IO, "waiting for a run failed (%s)", strerror(errno));
    *wall = mf_wall_seconds() - t0;
    *peak_mb = ru.ru_maxrss / 1024.0;
    *exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return 0;
}

static int copy_tree(const char *from, const char *to)
{
    char cmd[9000];
    if (snprintf(cmd, sizeof cmd, "mkdir -p '%s' && cp -r '%s/system' '%s/constant' '%s' && "
                 "{ [ ! -d '%s/validation' ] || cp -r '%s/validation' '%s'; }",
                 to, from, from, to, from, from, to) >= (int)sizeof cmd)
        return MF_ERROR(MF_ERR_INPUT, "case path too long: %s", from);
    if (strchr(from, '\'') || strchr(to, '\''))
        return MF_ERROR(MF_ERR_INPUT, "case paths with quotes are not supported: %s", from);
    if (system(cmd) != 0)
        return MF_ERROR(MF_ERR_IO, "cannot copy case %s to %s", from, to);
    return 0;
}

/* Entries of src replace those of dst; sub-dictionaries merge. */
static int merge_into(mf_dict *dst, const mf_dict *src)
{
    for (size_t k = 0; k < src->n; k++) {
        const mf_entry *e = src->entries[k];
        mf_dict *sub_dst = mf_dict_subdict(dst, e->key);
        if (e->n == 1 && e->items[0]->kind == MF_VAL_DICT && sub_dst) {
            MF_CALL(merge_into(sub_dst, e->items[0]->dict));
            continue;
        }
        mf_value **items = calloc(e->n ? e->n : 1, sizeof *items);
        if (!items)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory");
        for (size_t i = 0; i < e->n; i++)
            items[i] = mf_value_copy(e->items[i], dst);
        if (!mf_dict_set(dst, e->key, e->loc, e->n, items))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    }
    return 0;
}

static int write_solver_dict(const char *run_dir, const char *case_dir, const char *scheme,
                             const mf_dict *variants)
{
    char path[4400];
    snprintf(path, sizeof path, "%s/system/solverDict", case_dir);
    mf_dict *sd = NULL;
    MF_CALL(mf_dict_parse_file(path, &sd));
    const mf_dict *v = variants ? mf_dict_subdict(variants, scheme) : NULL;
    int rc = v ? merge_into(sd, v) : mf_dict_set_word(sd, "solver", scheme);
    if (snprintf(path, sizeof path, "%s/system/solverDict", run_dir) >= (int)sizeof path)
        rc = MF_ERROR(MF_ERR_INPUT, "path too long: %s", run_dir);
    FILE *f = rc == 0 ? fopen(path, "w") : NULL;
    if (rc == 0 && !f)
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot write (%s)", path, strerror(errno));
    if (f) {
        fprintf(f, "// solverDict of %s with scheme '%s' (written by mpsflow compare)\n",
                case_dir, scheme);
        rc = mf_dict_write(sd, f, 0);
        fclose(f);
    }
    mf_dict_free(sd);
    return rc;
}

static void read_summary(const char *run_dir, compare_row *row)
{
    char path[4400];
    mf_dict *d = NULL;
    snprintf(row->status, sizeof row->status, "no summary");
    if (snprintf(path, sizeof path, "%s/output/runSummary", run_dir) >= (int)sizeof path ||
        mf_dict_parse_file(path, &d) != 0) {
        mf_error_clear();
        return;
    }
    const char *w = NULL;
    double x;
    if (mf_dict_get_word(d, "status", &w) == 0)
        snprintf(row->status, sizeof row->status, "%s", w);
    if (mf_dict_get_word(d, "criterion", &w) == 0)
        snprintf(row->criterion, sizeof row->criterion, "%s", w);
    if (mf_dict_get_number(d, "steps", &x) == 0) row->steps = (long)x;
    if (mf_dict_get_number(d, "pressureIterations", &x) == 0) row->iterations = (long)x;
    if (mf_dict_get_number(d, "particles", &x) == 0) row->particles = (long)x;
    mf_error_clear();
    mf_dict_free(d);
}

static int parse_list(const char *what, const char *text, mf_dict **tree, const mf_value **list)
{
    char buf[8192];
    snprintf(buf, sizeof buf, "x %s;", text);
    MF_CALL(mf_dict_parse_string(buf, strlen(buf), what, tree));
    mf_entry *e = mf_dict_find(*tree, "x");
    if (!e || e->n != 1 || e->items[0]->kind != MF_VAL_LIST || e->items[0]->n == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s takes a non-empty list, e.g. %s '(a b)'", what, what);
    *list = e->items[0];
    return 0;
}

static void write_report(const char *case_dir, compare_row *rows, size_t n)
{
    char path[4400];
    snprintf(path, sizeof path, "%s/compare/compare.csv", case_dir);
    FILE *f = fopen(path, "w");
    if (f) {
        fprintf(f, "# mpsflow compare of %s: error from validation/metric\n", case_dir);
        fprintf(f, "scheme,l0,particles,error,wall_seconds,steps,pressure_iterations,peak_MB,"
                   "status,criterion,pareto\n");
    }
    for (size_t i = 0; i < n; i++) {
        bool pareto = isfinite(rows[i].error);
        for (size_t j = 0; j < n && pareto; j++)
            if (j != i && isfinite(rows[j].error) && rows[j].error <= rows[i].error &&
                rows[j].wall <= rows[i].wall &&
                (rows[j].error < rows[i].error || rows[j].wall < rows[i].wall))
                pareto = false;
        if (f)
            fprintf(f, "%s,%g,%ld,%.6g,%.4g,%ld,%ld,%.1f,%s,%s,%s\n", rows[i].scheme, rows[i].l0,
                    rows[i].particles, rows[i].error, rows[i].wall, rows[i].steps,
                    rows[i].iterations, rows[i].peak_mb, rows[i].status, rows[i].criterion,
                    pareto ? "yes" : "no");
        if (pareto)
            printf("Pareto front: %s at l0 = %g (error %.4g, %.3g s)\n", rows[i].scheme,
                   rows[i].l0, rows[i].error, rows[i].wall);
    }
    if (f)
        fclose(f);
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
        xs[s][k] = rows[i].wall;
        ys[s][k] = rows[i].error;
        snprintf(labels_text[s][k], sizeof labels_text[s][k], "%g", rows[i].l0);
        labels[s][k] = labels_text[s][k];
    }
    snprintf(path, sizeof path, "%s/compare/compare.png", case_dir);
    char title[512];
    snprintf(title, sizeof title, "Error against run time: %s (labels: l0)", case_dir);
    mf_plot plot = {title, "wall time, s", "error (validation/metric)", true, true};
    if (mf_report_plot(path, &plot, series, ns) != 0) {
        fprintf(stderr, "%s\n", mf_error_message());
        mf_error_clear();
    }
}

int mf_cmd_compare(const char *case_dir, const char *solvers, const char *resolutions)
{
    if (!solvers || !resolutions)
        return MF_ERROR(MF_ERR_INPUT, "compare needs -solvers '(A B ...)' and -resolutions "
                        "'(l0 ...)', e.g. mpsflow compare -case tutorials/hydrostatic2D "
                        "-solvers '(MPS)' -resolutions '(0.02 0.01)'");
    mf_dict *stree = NULL, *rtree = NULL, *cdict = NULL;
    const mf_value *slist = NULL, *rlist = NULL;
    int rc = parse_list("-solvers", solvers, &stree, &slist);
    if (rc == 0)
        rc = parse_list("-resolutions", resolutions, &rtree, &rlist);
    char path[4400], exe[4096];
    snprintf(path, sizeof path, "%s/system/compareDict", case_dir);
    if (rc == 0 && access(path, R_OK) == 0)
        rc = mf_dict_parse_file(path, &cdict);
    const mf_dict *variants = cdict ? mf_dict_subdict(cdict, "variants") : NULL;
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (rc == 0 && len <= 0)
        rc = MF_ERROR(MF_ERR_IO, "cannot find the mpsflow executable (/proc/self/exe)");
    if (len > 0)
        exe[len] = '\0';
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
            rc = copy_tree(case_dir, run_dir);
            if (rc == 0)
                rc = write_solver_dict(run_dir, case_dir, scheme, variants);
            if (rc != 0)
                break;
            snprintf(log_path, sizeof log_path, "%s/log.mpsflow", run_dir);
            char *argv[] = {exe, "-case", run_dir, "-l0", l0_text, "-quiet", NULL};
            int status = 0;
            printf("compare: %s at l0 = %s ... ", scheme, l0_text);
            fflush(stdout);
            rc = run_command(argv, log_path, &row->wall, &row->peak_mb, &status);
            if (rc != 0)
                break;
            read_summary(run_dir, row);
            row->error = NAN;
            if (status == 0) {
                fflush(stdout);
                if (mf_cmd_validate(run_dir, &row->error) != 0) {
                    fprintf(stderr, "  validate failed: %s\n", mf_error_message());
                    mf_error_clear();
                }
            } else {
                printf("%s (%s); see %s\n", row->status, row->criterion, log_path);
            }
            printf("  %.3g s, %ld steps, %ld pressure iterations, %.0f MB\n", row->wall,
                   row->steps, row->iterations, row->peak_mb);
        }
    if (rc == 0)
        write_report(case_dir, rows, n);
    if (rc == 0)
        printf("Table: %s/compare/compare.csv, plot: %s/compare/compare.png\n", case_dir,
               case_dir);
    free(rows);
    mf_dict_free(stree);
    mf_dict_free(rtree);
    mf_dict_free(cdict);
    return rc;
}
