/* mf_app.h: the driver, the one place that knows every layer. */
#ifndef MF_APP_H
#define MF_APP_H

#include <stdbool.h>

#include "mf_case.h"
#include "mf_modules.h"
#include "mf_run.h"
#include "mf_sim.h"

typedef struct mf_options {
    const char *case_dir;
    const char *solver;     /* -solver overrides solverDict */
    const char *libs;       /* -libs '(a b)' */
    const char *solvers, *resolutions, *sweeps; /* compare, stability */
    double l0;              /* -l0 overrides particleSpacing (0: no) */
    double end_time;        /* -endTime overrides controlDict (0: no) */
    bool dry_run, latest_time;
    bool parallel;          /* -parallel: one case on the ranks mpirun started */
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
    bool error_agreed;      /* a -parallel run's failure is known to every rank */
} mf_app;

/* Register every built-in module (the one explicit call). */
int mf_register_builtins(mf_registry *reg);

/* Load plugins named in a list text such as "(libfoo.so bar)". */
int mf_app_load_libs_text(mf_registry *reg, const char *text);
/* Read the case, build the scene and create the modules it names. */
int mf_app_setup(mf_app *app);
void mf_app_teardown(mf_app *app);
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

/* output/runSummary: how the run ended (status is its return code). */
int mf_write_run_summary(const mf_app *app, int status);

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
