/* mf_app.h: the driver, the one place that knows every layer. */
#ifndef MF_APP_H
#define MF_APP_H

#include <stdbool.h>
#include <stdio.h>
#include <sys/types.h>
#include <time.h>

#include "mf_case.h"
#include "mf_modules.h"
#include "mf_run.h"
#include "mf_scene.h"
#include "mf_sim.h"

typedef struct mf_options {
    const char *case_dir;
    const char *solver;     /* -solver overrides solverDict */
    const char *libs;       /* -libs '(a b)' */
    const char *solvers, *resolutions, *sweeps; /* compare, stability */
    const char *func, *funcs;   /* -postProcess -func NAME, -funcs '(A B)' */
    const char *time;       /* -time: snapshots for listTimes and -postProcess */
    bool post_process, version;
    double l0;              /* -l0 overrides particleSpacing (0: no) */
    double end_time;        /* -endTime overrides controlDict (0: no) */
    bool dry_run, latest_time;
    bool parallel;          /* -parallel: one case on the ranks mpirun started */
    bool overwrite;         /* -overwrite: a fresh run may replace an earlier output/ */
    int log_level;
    int argc;               /* the command line, for the log's banner */
    char **argv;
} mf_options;

/* runTimeModifiable (modifiable.c): the controlDict values last read. */
typedef struct mf_control_watch {
    mf_control file;        /* as the file said (strings into tree or the case) */
    mf_dict *tree;          /* the last re-read file, NULL before one */
    struct timespec mtime;
    off_t size;
} mf_control_watch;

typedef struct mf_app {
    mf_options opt;
    mf_registry *reg;
    mf_case cs;
    mf_log log;
    mf_sim sim;
    mf_module solver, writer;
    size_t nfunctions;
    mf_module *functions;
    mf_run run;
    bool error_agreed;      /* a -parallel run's failure is known to every rank */
    mf_scene_budget budget; /* the memory estimate the scene was checked against */
    mf_control_watch control_watch;
} mf_app;

/* Register every built-in module (the one explicit call). */
int mf_register_builtins(mf_registry *reg);

/* Load plugins named in a list text such as "(libfoo.so bar)". */
int mf_app_load_libs_text(mf_registry *reg, const char *text);
/* The `libs` of one function's dictionary (functions { NAME { libs (...); } }). */
int mf_app_load_function_libs(mf_registry *reg, const mf_dict *fd);
/* Load the plugins of controlDict's `libs` (after the case is read). */
int mf_app_load_case_libs(mf_app *app);
/* Read the case, build the scene and create the modules it names. */
int mf_app_setup(mf_app *app);
void mf_app_teardown(mf_app *app);
/* The memory budget of the case's scene (memory_budget.c): maxMemory, or
 * 80% of the machine's memory, and the bytes a particle costs at the
 * solver's largest neighbour radius. */
int mf_app_memory_budget(mf_app *app, mf_scene_budget *b);
/* Remove the *.tmp files a killed run left in output/ and postProcessing/
 * (stale_tmp.c), logging each; *removed counts them. */
int mf_app_remove_stale_tmp(const char *case_dir, mf_log *log, int *removed);
/* Print counts, kernel constants and memory (-dryRun). */
void mf_app_summary(const mf_app *app);

/* parallel_setup.c: -parallel. Started on several ranks without it: an
 * error saying what to type. */
int mf_app_check_parallel(const mf_options *opt, int argc, char **argv);
/* sim.par from system/decomposeParDict (NULL on one rank: the serial run). */
int mf_app_create_parallel(mf_app *app, mf_dict *resolved);
/* Each rank keeps its subdomain of the particles every rank holds. */
int mf_app_distribute(mf_app *app);
/* The decomposition's figures at the end of a -parallel run (the log). */
void mf_app_report_parallel(const mf_app *app);

/* output/runSummary: how the run ended (status is its return code; a run
 * stopped early, by stopAt or a signal, says so from app->run.stop_reason). */
int mf_write_run_summary(const mf_app *app, int status);

/* The tables of compareDict and stabilityDict (runs.c, stability.c), and
 * every table of every case dictionary and module (dict_tables.c): what
 * `mpsflow modules controlDict|geometry|fluids|watch|validation|compareDict|
 * stabilityDict` and `mpsflow reference` print. */
extern const mf_param mf_compare_params[];
extern const mf_param_section mf_compare_sections[];
extern const size_t mf_compare_nsections;
extern const mf_param_section mf_stability_sections[];
extern const size_t mf_stability_nsections;
extern const mf_param_section mf_decompose_sections[]; /* parallel_setup.c */
extern const size_t mf_decompose_nsections;
/* Print the tables of the case dictionary `name` (false: no such one);
 * validation's are those of the metrics registered in reg. */
bool mf_dict_tables_print(const mf_registry *reg, const char *name, FILE *f);
/* The names mf_dict_tables_print knows, NULL-terminated. */
extern const char *const mf_dict_table_names[];
/* docs/reference.md: every dictionary's and every module's keys. */
int mf_cmd_reference(mf_registry *reg, const char *path);
/* -latestTime or startFrom latestTime. */
bool mf_app_is_restart(const mf_app *app);
/* A fresh run refuses an output/ that holds an earlier run, or removes it
 * with -overwrite (output_check.c). */
int mf_app_check_output(mf_app *app);

/* runTimeModifiable (modifiable.c): remember controlDict as read and let
 * the loop re-read it between steps (run->modified). */
int mf_app_watch_control(mf_app *app);
void mf_app_unwatch_control(mf_app *app);
int mf_app_control_modified(void *ctx, mf_run *run);

/* The log's first lines (banner.c): version, build, command line, date,
 * host, PID, case, nProcs; as OpenFOAM's. */
void mf_app_banner(FILE *f, int argc, char **argv, const char *case_dir);
/* "mpsflow 0.1.0 (git ...)" for -version and file headers. */
const char *mf_app_version(void);

/* Commands. */
int mf_cmd_run(mf_app *app);
int mf_cmd_modules(mf_registry *reg, const char *name);
/* `mpsflow validate -case DIR`: prints "error <metric> = <value>"; fails
 * (after printing it, marked) when the run did not reach its endTime. */
int mf_cmd_validate(mf_registry *reg, const char *case_dir, double *error);
/* The metric `name` (NULL: the one validation/metric names; its settings
 * come from there) over the selected snapshots (NULL: all), its report in
 * out_dir. The metric is found in reg (after loading the plugins the
 * file's `libs` names). *used: the metric (may be NULL). */
int mf_metric_evaluate(mf_registry *reg, const char *case_dir, const char *name,
                       const int *selected, size_t nselected, const char *out_dir,
                       double *error, const mf_metric_ops **used);
/* Load the plugins that DIR/validation/metric names in its `libs` (none
 * when there is no such file), so that its metric is registered. */
int mf_app_load_metric_libs(mf_registry *reg, const char *case_dir);
/* Why output/runSummary says the run did not reach endTime ("" if it did);
 * false when there is no runSummary. Clears the error trace. */
bool mf_run_status_note(const char *case_dir, char *note, size_t len);

/* `mpsflow compare`: see compare.c (-endTime is passed to each run). */
int mf_cmd_compare(mf_registry *reg, const mf_options *o);

/* `mpsflow stability`: see stability.c (-l0 and -endTime passed to each run). */
int mf_cmd_stability(const mf_options *o);

/* `mpsflow listTimes` and `mpsflow -postProcess` (post_process.c). */
int mf_cmd_list_times(const mf_options *o);
int mf_cmd_post_process(mf_app *app);

#endif
