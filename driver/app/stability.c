/* stability.c: `mpsflow stability -case DIR -solvers '(A B)' [-sweeps '(name ...)']`
 *
 * Sweeps parameters of a case for each scheme and classifies every run
 * stable (it reached its end time) or unstable (the run's watch stopped it:
 * nonFinite, throughWall, densityCollapse, energy, or a failing pressure
 * solve), from the run's output/runSummary. The sweeps are in
 * DIR/system/stabilityDict:
 *
 *     endTime 0.3;                     // each run's end (optional)
 *     overrides                        // entries set in every run (optional)
 *     {
 *         system/controlDict { maxDeltaT 1; }
 *     }
 *     sweeps
 *     {
 *         courant { file "system/controlDict"; key maxCo; values (0.05 0.2 1 2); }
 *         viscosity { file "constant/fluids"; key "water/nu"; values (1e-6 1e-3); }
 *     }
 *
 * `key` is a path of sub-dictionaries and an entry. Writes
 * DIR/stability/stability.csv and one map per sweep,
 * DIR/stability/<sweep>.png (schemes by parameter value, stable in green,
 * unstable in red, labelled with the criterion).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_fs.h"
#include "mf_app.h"
#include "mf_post.h"
#include "mf_report.h"
#include "mf_runs.h"

typedef struct sweep_settings {
    const char *file, *key;
} sweep_settings;

static const mf_param sweep_params[] = {
    {"file", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(sweep_settings, file),
     "the case file that holds the parameter, e.g. \"system/controlDict\""},
    {"key", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(sweep_settings, key),
     "the entry, a path through sub-dictionaries such as \"water/nu\""},
};
static const char *const sweep_extra[] = {"values", NULL};

typedef struct stability_settings {
    double end_time;
    const mf_dict *overrides, *sweeps;
} stability_settings;

static const mf_param stability_params[] = {
    {"endTime", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(stability_settings, end_time),
     "end time of every run, s (0: the case's own; range as controlDict's endTime)"},
    {"overrides", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(stability_settings, overrides),
     "entries set in every run: { system/controlDict { maxDi 0; } ... }"},
    {"sweeps", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(stability_settings, sweeps),
     "one sub-dictionary per sweep: file, key and values (a b ...), the numbers tried"},
};
static const char *const stability_extra[] = {"FoamFile", NULL};

const mf_param_section mf_stability_sections[] = {
    {"stabilityDict", "system/stabilityDict: what `mpsflow stability` sweeps", stability_params,
     sizeof stability_params / sizeof stability_params[0]},
    {"stabilityDict: sweeps/<name>", "one parameter swept; `values (a b ...);` lists the numbers",
     sweep_params, sizeof sweep_params / sizeof sweep_params[0]},
};
const size_t mf_stability_nsections = 2;

/* Set FILE's entry at PATH (a/b/c) to the number x, in the run's copy. */
static int set_parameter(const char *run_dir, const char *file, const char *key_path, double x)
{
    char path[8800], buf[512];
    if (snprintf(path, sizeof path, "%s/%s", run_dir, file) >= (int)sizeof path)
        return MF_ERROR(MF_ERR_INPUT, "path too long: %s/%s", run_dir, file);
    mf_dict *root = NULL;
    MF_CALL(mf_dict_parse_file(path, &root));
    mf_dict *d = root;
    snprintf(buf, sizeof buf, "%s", key_path);
    int rc = 0;
    char *save = NULL, *part = strtok_r(buf, "/", &save);
    for (char *next; part && (next = strtok_r(NULL, "/", &save)); part = next) {
        d = mf_dict_subdict(d, part);
        if (!d) {
            rc = MF_ERROR(MF_ERR_INPUT,
                          "stabilityDict: %s has no sub-dictionary '%s' on the path '%s'", file,
                          part, key_path);
            break;
        }
    }
    if (rc == 0 && part)
        rc = mf_dict_set_number(d, part, x);
    if (rc == 0)
        rc = mf_dict_write_file(root, path, "written by mpsflow stability");
    mf_dict_free(root);
    return rc;
}

/* Merge `overrides { file { entries } }` into the run's files. */
static int apply_overrides(const char *run_dir, const mf_dict *overrides)
{
    char path[8800];
    for (size_t k = 0; overrides && k < overrides->n; k++) {
        const mf_entry *e = overrides->entries[k];
        if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT) {
            char where[512];
            return MF_ERROR(MF_ERR_INPUT, "%s: overrides: '%s' must be a dictionary of entries",
                            mf_loc_str(e->loc, where, sizeof where), e->key);
        }
        if (snprintf(path, sizeof path, "%s/%s", run_dir, e->key) >= (int)sizeof path)
            return MF_ERROR(MF_ERR_INPUT, "path too long: %s", e->key);
        mf_dict *d = NULL;
        MF_CALL(mf_dict_parse_file(path, &d));
        int rc = mf_dict_merge(d, e->items[0]->dict);
        if (rc == 0)
            rc = mf_dict_write_file(d, path, "written by mpsflow stability");
        mf_dict_free(d);
        MF_CALL(rc);
    }
    return 0;
}

typedef struct stability_cell {
    double value;
    size_t scheme;
    bool stable;
    char criterion[64];
} stability_cell;

static void draw_map(const char *case_dir, const char *sweep, const mf_value *schemes,
                     const stability_cell *cells, size_t n)
{
    double xs[2][512], ys[2][512];
    char text[2][512][64];
    const char *labels[2][512];
    size_t count[2] = {0, 0};
    bool positive = true;
    double lo = INFINITY, hi = 0;
    for (size_t i = 0; i < n && i < 512; i++) {
        int k = cells[i].stable ? 0 : 1;
        xs[k][count[k]] = cells[i].value;
        ys[k][count[k]] = (double)cells[i].scheme;
        snprintf(text[k][count[k]], sizeof text[k][0], "%s",
                 cells[i].stable ? "" : cells[i].criterion);
        labels[k][count[k]] = text[k][count[k]];
        count[k]++;
        positive = positive && cells[i].value > 0;
        lo = fmin(lo, cells[i].value);
        hi = fmax(hi, cells[i].value);
    }
    char extra[4096] = "set ytics (";
    for (size_t s = 0; s < schemes->n; s++) {
        size_t len = strlen(extra);
        snprintf(extra + len, sizeof extra - len, "%s\"%s\" %zu", s ? ", " : "",
                 schemes->items[s]->text, s);
    }
    size_t len = strlen(extra);
    snprintf(extra + len, sizeof extra - len,
             ")\nset yrange [-0.5:%zu.5]\nset offsets graph 0.05, graph 0.05, 0, 0\nset key outside",
             schemes->n - 1);
    char path[4400], title[512];
    snprintf(path, sizeof path, "%s/stability/%s.png", case_dir, sweep);
    char full[4096];
    const char *name = realpath(case_dir, full) ? full : case_dir;
    const char *slash = strrchr(name, '/');
    snprintf(title, sizeof title, "Stability map of %.200s: sweep '%.100s' (unstable: the watch's criterion)",
             slash && slash[1] ? slash + 1 : name, sweep);
    mf_plot plot = {title, sweep, "scheme", positive && hi > 10 * lo, false, extra};
    mf_series series[2] = {
        {"stable", xs[0], ys[0], count[0], "points pt 7 ps 2.5 lc rgb '#2a9d2a'", NULL},
        {"unstable", xs[1], ys[1], count[1], "points pt 5 ps 2.5 lc rgb '#d62728'", labels[1]},
    };
    /* Only the classes present: gnuplot warns about an empty data block. */
    size_t ns = 0;
    for (int k = 0; k < 2; k++)
        if (series[k].n > 0)
            series[ns++] = series[k];
    if (mf_report_plot(path, &plot, series, ns) != 0) {
        fprintf(stderr, "%s\n", mf_error_message());
        mf_error_clear();
    }
}

int mf_cmd_stability(const mf_options *o)
{
    const char *case_dir = o->case_dir, *solvers = o->solvers, *only = o->sweeps;
    if (!solvers)
        return MF_ERROR(MF_ERR_INPUT, "stability needs -solvers '(A B ...)', e.g. mpsflow "
                        "stability -case tutorials/damBreak2D -solvers '(MPS MPS_plain)'");
    char path[4400];
    snprintf(path, sizeof path, "%s/system/stabilityDict", case_dir);
    mf_dict *sd = NULL, *stree = NULL, *otree = NULL;
    const mf_value *schemes = NULL, *only_list = NULL;
    MF_CALL(mf_dict_parse_file(path, &sd));
    stability_settings st;
    int rc = mf_params_apply(stability_params, 3, sd, stability_extra, &st, NULL);
    if (rc == 0)
        rc = mf_parse_option_list("-solvers", solvers, &stree, &schemes);
    if (rc == 0 && only)
        rc = mf_parse_option_list("-sweeps", only, &otree, &only_list);
    const mf_dict *sweeps = mf_dict_subdict(sd, "sweeps");
    double end_time = 0;
    if (rc == 0)
        rc = mf_dict_get_number_or(sd, "endTime", 0, &end_time);
    if (o->end_time > 0) /* -endTime overrides stabilityDict's */
        end_time = o->end_time;
    char l0_text[64];
    snprintf(l0_text, sizeof l0_text, "%.10g", o->l0);
    if (rc == 0 && !sweeps)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no 'sweeps { ... }' dictionary", path);
    FILE *csv = NULL;
    if (rc == 0) {
        snprintf(path, sizeof path, "%s/stability", case_dir);
        rc = mf_mkdir_p(path);
        snprintf(path, sizeof path, "%s/stability/stability.csv", case_dir);
        csv = rc == 0 ? fopen(path, "w") : NULL;
        if (rc == 0 && !csv)
            rc = MF_ERROR(MF_ERR_IO, "%s: cannot write", path);
    }
    if (csv)
        fprintf(csv, "sweep,value,scheme,status,criterion,steps,wall_seconds\n");
    for (size_t w = 0; rc == 0 && w < sweeps->n; w++) {
        const mf_entry *e = sweeps->entries[w];
        bool wanted = !only_list;
        for (size_t k = 0; only_list && k < only_list->n; k++)
            wanted = wanted || (only_list->items[k]->text && !strcmp(only_list->items[k]->text, e->key));
        if (!wanted)
            continue;
        const mf_dict *sw = mf_dict_subdict(sweeps, e->key);
        sweep_settings ss;
        mf_entry *values = sw ? mf_dict_find(sw, "values") : NULL;
        rc = sw ? mf_params_apply(sweep_params, 2, sw, sweep_extra, &ss, NULL)
                : MF_ERROR(MF_ERR_INPUT, "stabilityDict: sweep '%s' must be a dictionary", e->key);
        if (rc == 0 && (!values || values->n != 1 || values->items[0]->kind != MF_VAL_LIST))
            rc = MF_ERROR(MF_ERR_INPUT, "stabilityDict: sweep '%s' needs values (a b ...);", e->key);
        if (rc != 0)
            break;
        values->used = true;
        const mf_value *vl = values->items[0];
        size_t ncells = vl->n * schemes->n, nc = 0;
        stability_cell *cells = calloc(ncells ? ncells : 1, sizeof *cells);
        if (!cells) {
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
            break;
        }
        for (size_t s = 0; rc == 0 && s < schemes->n; s++)
            for (size_t v = 0; rc == 0 && v < vl->n; v++) {
                stability_cell *c = &cells[nc++];
                c->scheme = s;
                rc = mf_value_number(vl->items[v], "stabilityDict values", &c->value);
                const char *scheme = schemes->items[s]->text;
                char run_dir[4400], log_path[4500], end_text[64];
                snprintf(run_dir, sizeof run_dir, "%s/stability/%s_%s_%g", case_dir, e->key,
                         scheme, c->value);
                if (rc == 0)
                    rc = mf_case_copy(case_dir, run_dir);
                if (rc == 0)
                    rc = mf_case_apply_scheme(run_dir, case_dir, scheme);
                if (rc == 0)
                    rc = apply_overrides(run_dir, mf_dict_subdict(sd, "overrides"));
                if (rc == 0)
                    rc = set_parameter(run_dir, ss.file, ss.key, c->value);
                if (rc != 0)
                    break;
                snprintf(log_path, sizeof log_path, "%s/log.mpsflow", run_dir);
                snprintf(end_text, sizeof end_text, "%.10g", end_time);
                char *argv[8] = {NULL, "-case", run_dir, "-quiet"};
                int na = 4;
                if (end_time > 0) {
                    argv[na++] = "-endTime";
                    argv[na++] = end_text;
                }
                if (o->l0 > 0) {
                    argv[na++] = "-l0";
                    argv[na++] = l0_text;
                }
                argv[na] = NULL;
                mf_child_result child;
                printf("stability: %s = %g, %s ... ", e->key, c->value, scheme);
                rc = mf_run_child(argv, log_path, &child);
                if (rc != 0)
                    break;
                mf_run_summary sum;
                mf_read_run_summary(run_dir, &sum);
                c->stable = child.exit_status == 0 && !strcmp(sum.status, "completed");
                snprintf(c->criterion, sizeof c->criterion, "%s",
                         c->stable ? "" : (sum.criterion[0] ? sum.criterion : sum.status));
                printf("%s%s%s (%.3g s)\n", c->stable ? "stable" : "unstable",
                       c->stable ? "" : ": ", c->criterion, child.wall_seconds);
                fprintf(csv, "%s,%g,%s,%s,%s,%ld,%.4g\n", e->key, c->value, scheme,
                        c->stable ? "stable" : "unstable", c->criterion, sum.steps,
                        child.wall_seconds);
            }
        if (rc == 0)
            draw_map(case_dir, e->key, schemes, cells, nc);
        free(cells);
    }
    if (csv)
        fclose(csv);
    if (rc == 0)
        printf("Table: %s/stability/stability.csv; maps: %s/stability/<sweep>.png\n", case_dir,
               case_dir);
    mf_dict_free(sd);
    mf_dict_free(stree);
    mf_dict_free(otree);
    return rc;
}
