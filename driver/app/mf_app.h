/* mf_app.h: the driver, the one place that knows every layer. */
#ifndef MF_APP_H
#define MF_APP_H

#include <stdbool.h>

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
    double l0;              /* -l0 overrides particleSpacing (0: no) */
    double end_time;        /* -endTime overrides controlDict (0: no) */
    bool dry_run, latest_time;
    int log_level;
} mf_options;

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
    mf_scene_budget budget; /* the memory estimate the scene was checked against */
} mf_app;

/* Register every built-in module (the one explicit call). */
int mf_register_builtins(mf_registry *reg);

/* Load plugins named in a list text such as "(libfoo.so bar)". */
int mf_app_load_libs_text(mf_registry *reg, const char *text);
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

/* output/runSummary: how the run ended (status is its return code). */
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
/* Print the tables of the case dictionary `name` (false: no such one). */
bool mf_dict_tables_print(const char *name, FILE *f);
/* The names mf_dict_tables_print knows, NULL-terminated. */
extern const char *const mf_dict_table_names[];
/* docs/reference.md: every dictionary's and every module's keys. */
int mf_cmd_reference(mf_registry *reg, const char *path);

/* Commands. */
int mf_cmd_run(mf_app *app);
int mf_cmd_modules(mf_registry *reg, const char *name);
/* `mpsflow validate -case DIR`: prints "error <metric> = <value>". */
int mf_cmd_validate(const char *case_dir, double *error);

/* `mpsflow compare`: see compare.c. */
int mf_cmd_compare(const char *case_dir, const char *solvers, const char *resolutions);

/* `mpsflow stability`: see stability.c. */
int mf_cmd_stability(const char *case_dir, const char *solvers, const char *sweeps);

#endif
