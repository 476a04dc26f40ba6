/* main.c: `mpsflow`, with OpenFOAM's habits.
 *
 *   mpsflow [-case DIR] [-solver NAME] [-libs '(...)'] [-dryRun] [-latestTime] [-overwrite]
 *   mpsflow -postProcess -func NAME | -funcs '(A B)' [-time T | -latestTime]
 *   mpsflow listTimes | modules [NAME] | validate | compare | stability | surface
 *   mpsflow -version
 *   mpirun -np N mpsflow -parallel -case DIR     (one case on N ranks)
 */
#include <limits.h>
#include <math.h>
#include <mpi.h>
#include <HYPRE_utilities.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mf_app.h"
#include "mf_bodies.h"
#include "mf_error.h"
#include "mf_malloc_defaults.h"
#include "mf_post.h"
#include "mf_walls.h"

static void usage(FILE *f)
{
    fprintf(f,
            "Usage: mpsflow [COMMAND] [OPTIONS]\n"
            "\n"
            "Commands:\n"
            "  (none)            run the case\n"
            "  modules [NAME]    list the registered modules by kind, or the parameters of one\n"
            "                    (also of a case dictionary: controlDict, watch, geometry,\n"
            "                    fluids, validation, compareDict, stabilityDict)\n"
            "  reference [FILE]  every key of every dictionary and module, as markdown\n"
            "  validate          score the case's output against its reference (validation/)\n"
            "  compare           run the case with several schemes and resolutions: error\n"
            "                    against run time (-solvers '(A B)' -resolutions '(l0 ...)')\n"
            "  stability         sweep system/stabilityDict's parameters for each scheme and\n"
            "                    map stable and unstable runs (-solvers '(A B)' [-sweeps '(...)'])\n"
            "  surface           reconstruct the free surface of the snapshots as meshes\n"
            "                    (-time T | -latestTime, -method levelSet|blobby; surface -help)\n"
            "  listTimes         the times of the snapshots in DIR/output (-time, -latestTime;\n"
            "                    -verbose: step, file and particle counts too)\n"
            "\n"
            "Options:\n"
            "  -case DIR         case directory (default: the current folder)\n"
            "  -solver NAME      solver module, overriding system/solverDict\n"
            "  -libs '(...)'     plugin libraries to load, e.g. -libs '(libkineticEnergy.so)'\n"
            "  -dryRun           read the case, build the scene, print a summary, stop\n"
            "  -latestTime       restart from the newest snapshot in DIR/output\n"
            "                    (listTimes, -postProcess: only the newest snapshot)\n"
            "  -overwrite        a new run replaces an earlier one's output/ and postProcessing/\n"
            "                    (without it a new run over an earlier output/ is refused)\n"
            "  -postProcess      replay function objects or metrics over the existing snapshots:\n"
            "                    -func NAME or -funcs '(A B)' (controlDict functions, function\n"
            "                    object types, validation metrics); -time T selects snapshots\n"
            "  -time T           a time (the nearest snapshot), a list 0.1,0.2 or a range 0.1:0.5\n"
            "  -l0 VALUE         particle spacing, overriding constant/geometry (coarse/fine)\n"
            "  -endTime VALUE    end time, overriding system/controlDict\n"
            "  -solvers '(...)'  compare: schemes (variants of system/compareDict, or solvers)\n"
            "  -resolutions '(...)'  compare: particle spacings\n"
            "  -sweeps '(...)'   stability: only these sweeps\n"
            "  -quiet, -verbose  less or more log\n"
            "  -version          the version and build of this mpsflow\n"
            "  -help             this text\n"
            "\n"
            "Plugins are searched as named, then in MPSFLOW_PLUGIN_PATH, then in the\n"
            "plugins folder beside the executable's build or install tree.\n");
}

int mf_main_surface(int argc, char **argv, int first); /* surface.c: its own options */

static int parse_number(const char *opt, const char *text, double *out)
{
    char *end;
    *out = strtod(text, &end);
    if (end == text || *end || !(*out > 0) || !isfinite(*out))
        return MF_ERROR(MF_ERR_INPUT, "%s takes a positive finite number, not '%s'", opt, text);
    return 0;
}

/* Returns 0 and fills opt, 1 for -help, <0 on a bad option. */
static int parse_options(int argc, char **argv, int first, mf_options *opt)
{
    static const char *const known[] = {"-case", "-solver", "-libs", "-dryRun", "-latestTime",
                                        "-l0", "-endTime", "-quiet", "-verbose", "-help",
                                        "-solvers", "-resolutions", "-sweeps", "-overwrite",
                                        "-postProcess", "-func", "-funcs", "-time", "-version",
                                        "-parallel"};
    for (int i = first; i < argc; i++) {
        const char *a = argv[i];
        bool has_value = i + 1 < argc;
        if (!strcmp(a, "-help") || !strcmp(a, "--help") || !strcmp(a, "-h"))
            return 1;
        else if (!strcmp(a, "-dryRun"))
            opt->dry_run = true;
        else if (!strcmp(a, "-latestTime"))
            opt->latest_time = true;
        else if (!strcmp(a, "-overwrite"))
            opt->overwrite = true;
        else if (!strcmp(a, "-parallel"))
            opt->parallel = true;
        else if (!strcmp(a, "-postProcess"))
            opt->post_process = true;
        else if (!strcmp(a, "-version"))
            opt->version = true;
        else if (!strcmp(a, "-quiet"))
            opt->log_level = MF_LOG_QUIET;
        else if (!strcmp(a, "-verbose"))
            opt->log_level = MF_LOG_VERBOSE;
        else if (!strcmp(a, "-case") || !strcmp(a, "-solver") || !strcmp(a, "-libs") ||
                 !strcmp(a, "-l0") || !strcmp(a, "-endTime") || !strcmp(a, "-solvers") ||
                 !strcmp(a, "-resolutions") || !strcmp(a, "-sweeps") || !strcmp(a, "-func") ||
                 !strcmp(a, "-funcs") || !strcmp(a, "-time")) {
            if (!has_value)
                return MF_ERROR(MF_ERR_INPUT, "option %s needs a value (see mpsflow -help)", a);
            const char *v = argv[++i];
            if (!strcmp(a, "-case"))
                opt->case_dir = v;
            else if (!strcmp(a, "-solver"))
                opt->solver = v;
            else if (!strcmp(a, "-libs"))
                opt->libs = v;
            else if (!strcmp(a, "-solvers"))
                opt->solvers = v;
            else if (!strcmp(a, "-resolutions"))
                opt->resolutions = v;
            else if (!strcmp(a, "-sweeps"))
                opt->sweeps = v;
            else if (!strcmp(a, "-func"))
                opt->func = v;
            else if (!strcmp(a, "-funcs"))
                opt->funcs = v;
            else if (!strcmp(a, "-time"))
                opt->time = v;
            else if (!strcmp(a, "-l0"))
                MF_CALL(parse_number(a, v, &opt->l0));
            else
                MF_CALL(parse_number(a, v, &opt->end_time));
        } else {
            const char *hint = mf_did_you_mean(a, known, sizeof known / sizeof known[0]);
            return MF_ERROR(MF_ERR_INPUT, "unknown option '%s'%s%s%s (see mpsflow -help)", a,
                            hint ? "; did you mean '" : "", hint ? hint : "", hint ? "'?" : "");
        }
    }
    if (opt->time && opt->latest_time)
        return MF_ERROR(MF_ERR_INPUT, "-time and -latestTime exclude each other");
    return 0;
}

/* Plugins built with mpsflow sit in ../plugins beside driver/ in the build
 * tree, or, installed, in the plugin folder at MPSFLOW_PLUGIN_RELDIR from
 * bin/ (meson's libdir/mpsflow: ../lib/x86_64-linux-gnu/mpsflow on Debian),
 * found from where the executable is, so that an installed tree works
 * wherever it is put (meson install --destdir, a moved prefix). */
#ifndef MPSFLOW_PLUGIN_RELDIR
#define MPSFLOW_PLUGIN_RELDIR "../lib/mpsflow"
#endif
static void set_plugin_dirs(mf_registry *reg)
{
    char exe[PATH_MAX], dirs[3 * PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return;
    exe[n] = '\0';
    char *slash = strrchr(exe, '/');
    if (!slash)
        return;
    *slash = '\0';
    if (MPSFLOW_PLUGIN_RELDIR[0] == '/')
        snprintf(dirs, sizeof dirs, "%s/../plugins:%s", exe, MPSFLOW_PLUGIN_RELDIR);
    else
        snprintf(dirs, sizeof dirs, "%s/../plugins:%s/%s", exe, exe, MPSFLOW_PLUGIN_RELDIR);
    mf_registry_set_plugin_dir(reg, dirs);
}

int mf_cmd_modules(mf_registry *reg, const char *name)
{
    if (!name) {
        mf_registry_print(reg, stdout);
        printf("case dictionaries (mpsflow modules NAME):\n   ");
        for (size_t k = 0; mf_dict_table_names[k]; k++)
            printf(" %s", mf_dict_table_names[k]);
        printf("\n");
        return 0;
    }
    if (mf_dict_tables_print(reg, name, stdout))
        return 0;
    const mf_module_info *m = mf_registry_lookup_any(reg, name);
    if (!m) {
        /* Suggest from every module of every kind and the case dictionaries. */
        const char *names[512];
        size_t n = 0;
        char list[4096] = "";
        for (int k = 0; k < MF_KIND_COUNT; k++)
            for (size_t i = 0; i < mf_registry_count(reg, (mf_module_kind)k) && n < 500; i++)
                names[n++] = mf_registry_at(reg, (mf_module_kind)k, i)->name;
        for (size_t k = 0; mf_dict_table_names[k] && n < 512; k++)
            names[n++] = mf_dict_table_names[k];
        for (size_t k = 0; k < n; k++) {
            strncat(list, k ? ", " : "", sizeof list - strlen(list) - 1);
            strncat(list, names[k], sizeof list - strlen(list) - 1);
        }
        const char *hint = mf_did_you_mean(name, names, n);
        return MF_ERROR(MF_ERR_INPUT, "no module or case dictionary named '%s'%s%s%s; known: %s",
                        name, hint ? " (did you mean '" : "", hint ? hint : "", hint ? "'?)" : "",
                        list);
    }
    printf("%s (%s module): %s\n", m->name, mf_module_kind_name(m->kind), m->summary);
    printf("Parameters:\n");
    mf_params_print(m->params, m->nparams, stdout);
    return 0;
}

/* The run itself; every rank of a -parallel run calls it. */
static int run_case(mf_app *app)
{
    /* Stale .tmp files of a killed run: one rank looks (and says so). */
    int stale = 0;
    MF_CALL(mf_parallel_agree(app->sim.par,
                              mf_parallel_is_root(app->sim.par)
                                  ? mf_app_remove_stale_tmp(app->cs.dir, &app->log, &stale)
                                  : 0));
    bool restart = mf_app_is_restart(app);
    const bool bodies = mf_bodies_count(app->sim.walls) > 0;
    if (bodies) {
        /* Rigid bodies (mf_bodies.h): time 0 or a restart, whose snapshot
         * holds their state (/RigidBodies); on several ranks their sums are
         * taken over all (mf_walls.par). */
        app->sim.walls->par = app->sim.par;
        if (!restart && app->sim.time != 0)
            return MF_ERROR(MF_ERR_INPUT, "rigid bodies (motion type rigid) start at time 0 or "
                            "restart from a snapshot (startFrom latestTime, -latestTime): their "
                            "state at startTime %g is not known", app->sim.time);
    }
    if (restart) {
        const mf_writer_ops *w = (const mf_writer_ops *)app->writer.info;
        if (!w->read_latest)
            return MF_ERROR(MF_ERR_INPUT, "writer '%s' cannot restart a run", w->info.name);
        MF_CALL(w->read_latest(app->writer.data, &app->sim));
        mf_log_printf(&app->log, MF_LOG_NORMAL, "Restarting from time %g (step %ld)\n",
                      app->sim.time, app->sim.step);
        mf_bodies_set_committed(app->sim.walls);
    } else if (app->sim.time != 0) { /* a fresh scene at startTime: solids where they are then */
        MF_CALL(mf_walls_advance(app->sim.walls, app->sim.p, 0, app->sim.time));
    }
    if (bodies) {
        char post[4400];
        snprintf(post, sizeof post, "%s/postProcessing", app->cs.dir);
        /* bodyState.csv: rank 0 writes it (every rank has the same state) */
        MF_CALL(mf_parallel_agree(app->sim.par,
                                  mf_parallel_is_root(app->sim.par)
                                      ? mf_bodies_open_output(app->sim.walls, post,
                                                              app->sim.time, restart)
                                      : 0));
    }
    MF_CALL(mf_parallel_agree(app->sim.par, mf_app_distribute(app)));
    if (mf_parallel_is_root(app->sim.par))
        MF_CALL(mf_case_write_resolved(&app->cs));
    mf_app_summary(app);
    int rc = mf_run_signals_install();
    if (rc == 0)
        rc = mf_run_loop(&app->run, !restart);
    mf_run_signals_restore();
    if (rc == 0 && app->run.stop_reason[0])
        mf_log_printf(&app->log, MF_LOG_QUIET, "\n--> %s at time %g (step %ld)%s\n",
                      app->run.stop_reason, app->sim.time, app->sim.step,
                      app->run.ctl.stop_at == MF_STOP_NO_WRITE_NOW && !app->run.stop_signal
                          ? ""
                          : "; the last snapshot holds this state");
    const mf_solver_ops *ops = (const mf_solver_ops *)app->solver.info;
    if (ops->report)
        ops->report(app->solver.data, &app->sim, &app->log);
    mf_app_report_parallel(app);
    /* What the calling wrappers counted (mf_modules.h). */
    mf_log_printf(&app->log, MF_LOG_QUIET, "Solver %s: %ld steps, %.3f s\n",
                  app->solver.info->name, app->solver.calls, app->solver.seconds);
    for (size_t k = 0; k < app->sim.nforces; k++)
        mf_log_printf(&app->log, MF_LOG_QUIET, "Force %s: %ld calls, %.3f s\n",
                      app->sim.forces[k].info->name, app->sim.forces[k].calls,
                      app->sim.forces[k].seconds);
    mf_watch_report(&app->run.watch, &app->log);
    mf_log_printf(&app->log, MF_LOG_QUIET,
                  "\nSteps %ld (retried %ld), snapshots %d, wall time %.2f s, peak memory %.1f "
                  "MB\n",
                  app->run.steps, app->run.retries, app->run.writes, app->run.wall_seconds,
                  mf_peak_memory() / 1048576.0);
    if (mf_write_run_summary(app, rc) != 0 && rc == 0)
        return mf_error_trace(MF_ERR_IO, __FILE__, __LINE__, __func__);
    MF_CALL(rc);
    mf_log_printf(&app->log, MF_LOG_QUIET, "End\n");
    fflush(stdout);
    return 0;
}

int mf_cmd_run(mf_app *app)
{
    int rc = mf_app_setup(app);
    /* Reading the case and building the scene is the same on every rank,
     * but a rank may still fail alone (memory): agree before the first
     * collective step. */
    rc = mf_parallel_agree(app->sim.par, rc);
    if (rc == 0 && app->opt.dry_run) {
        MF_CALL(mf_parallel_agree(app->sim.par, mf_app_distribute(app)));
        mf_app_summary(app);
        if (mf_parallel_is_root(app->sim.par))
            printf("\nDry run: stopping before the time loop.\nEnd\n");
        return 0;
    }
    if (rc == 0)
        rc = run_case(app);
    /* The time loop agrees on every step's status; this covers the rest. */
    rc = mf_parallel_agree(app->sim.par, rc);
    app->error_agreed = app->sim.par != NULL;
    return rc;
}

/* OpenMP's wait policy, before anything else. libgomp's default spins a
 * waiting thread for up to 300,000 iterations at every barrier; when
 * another process holds the second core, the team's other thread is not
 * running, every barrier waits out a time slice, and two threads made a step
 * 25 to 40 times slower than one (the neighbour search: 1 ms to 400 ms).
 * Passive waiting (sleep at once) keeps two threads at or below one thread's
 * time on a loaded machine (docs/validation-and-performance.md has the measurements).
 * libgomp reads the policy from the environment when it loads, before main:
 * so set it and start again, unless the user chose a policy. */
static void openmp_wait_policy(char **argv)
{
    if (getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT"))
        return;
    if (setenv("OMP_WAIT_POLICY", "PASSIVE", 1) != 0)
        return;
    execv("/proc/self/exe", argv); /* returns only on failure: go on as we are */
}

/* hwloc (which OpenMPI's MPI_Init and its singleton orted load) probes
 * the X displays :0, :1, ... for GPUs through its GL plugin. A run does not
 * need GPUs, and a busy X server on the machine (an Xvfb of a ParaView
 * test) made the probe fail with Xlib's "XIO: fatal IO error", which exits
 * the process. Leave the plugin out unless the user chose hwloc's
 * components. Before the re-exec below, so that every process inherits it. */
static void hwloc_without_displays(void)
{
    if (!getenv("HWLOC_COMPONENTS"))
        setenv("HWLOC_COMPONENTS", "-gl", 1);
}

int main(int argc, char **argv)
{
    /* Freed memory goes back to the system again: libsuperlu_dist's
     * constructor turned that off before main (malloc_defaults.c). */
    (void)mf_malloc_gives_back();
    hwloc_without_displays();
    openmp_wait_policy(argv);
    /* Whole lines reach a redirected log at once (tail -f, a kill). */
    setvbuf(stdout, NULL, _IOLBF, 0);
    mf_app app;
    memset(&app, 0, sizeof app);
    app.opt.case_dir = ".";
    app.opt.log_level = MF_LOG_NORMAL;
    app.opt.argc = argc;
    app.opt.argv = argv;
    const char *command = NULL;
    int first = 1;
    if (argc > 1 && argv[1][0] != '-') {
        command = argv[1];
        first = 2;
    }
    if (command && !strcmp(command, "surface"))
        return mf_main_surface(argc, argv, first);
    const char *module_name = NULL;
    if (command && (!strcmp(command, "modules") || !strcmp(command, "reference")) && argc > 2 &&
        argv[2][0] != '-') {
        module_name = argv[2];
        first = 3;
    }
    int rc = parse_options(argc, argv, first, &app.opt);
    if (rc == 1) {
        usage(stdout);
        return 0;
    }
    if (rc != 0) {
        mf_error_print(stderr);
        return 2;
    }
    if (app.opt.version) {
        printf("%s\n", mf_app_version());
        return 0;
    }
    static const char *const commands[] = {"modules", "validate", "compare", "stability",
                                           "listTimes", "reference"};
    const size_t ncommands = sizeof commands / sizeof commands[0];
    bool known = !command;
    for (size_t k = 0; k < ncommands && !known; k++)
        known = !strcmp(command, commands[k]);
    if (!known) {
        const char *hint = mf_did_you_mean(command, commands, ncommands);
        fprintf(stderr, "mpsflow: unknown command '%s'%s%s%s\n\n", command,
                hint ? " (did you mean '" : "", hint ? hint : "", hint ? "'?)" : "");
        usage(stderr);
        return 2;
    }
    MPI_Init(&argc, &argv);
    HYPRE_Init();
    const bool root = mf_parallel_world_rank() == 0;
    rc = mf_app_check_parallel(&app.opt, argc, argv);
    if (rc == 0 && command && mf_parallel_world_size() > 1 &&
        (!strcmp(command, "compare") || !strcmp(command, "stability")))
        rc = MF_ERROR(MF_ERR_INPUT,
                      "%s runs the case many times as child processes and compares their run "
                      "times: run it without mpirun (each run is serial); to time a case on N "
                      "ranks use mpirun -np N mpsflow -parallel -case DIR",
                      command);
    if (rc != 0) {
        if (root)
            mf_error_print(stderr);
        HYPRE_Finalize();
        MPI_Finalize();
        return 2;
    }
    rc = mf_registry_create(&app.reg);
    if (rc == 0) {
        set_plugin_dirs(app.reg);
        rc = mf_register_builtins(app.reg);
    }
    if (rc == 0 && app.opt.libs)
        rc = mf_app_load_libs_text(app.reg, app.opt.libs);
    double error = 0;
    if (rc == 0 && !command && (app.opt.post_process || !app.opt.dry_run) && root)
        mf_app_banner(stdout, argc, argv, app.opt.case_dir);
    if (rc == 0 && !command && app.opt.post_process) {
        if (root) /* replays snapshots serially: one rank is enough */
            rc = mf_cmd_post_process(&app);
    } else if (rc == 0 && !command)
        rc = mf_cmd_run(&app);
    /* Commands that read a case's files: one rank is enough. */
    else if (rc == 0 && !strcmp(command, "listTimes") && root)
        rc = mf_cmd_list_times(&app.opt);
    else if (rc == 0 && !strcmp(command, "modules") && root)
        rc = mf_cmd_modules(app.reg, module_name);
    else if (rc == 0 && !strcmp(command, "reference") && root)
        rc = mf_cmd_reference(app.reg, module_name);
    else if (rc == 0 && !strcmp(command, "validate") && root)
        rc = mf_cmd_validate(app.reg, app.opt.case_dir, &error);
    else if (rc == 0 && !strcmp(command, "compare"))
        rc = mf_cmd_compare(app.reg, &app.opt);
    else if (rc == 0 && !strcmp(command, "stability"))
        rc = mf_cmd_stability(&app.opt);
    /* A failure every rank agreed on is printed once; one that a rank met
     * alone is printed by that rank. */
    if (rc != 0 && (root || !app.error_agreed))
        mf_error_print(stderr);
    fflush(stdout);
    const int stop_signal = app.run.stop_signal;
    mf_app_teardown(&app);
    mf_registry_destroy(app.reg);
    HYPRE_Finalize();
    MPI_Finalize();
    /* Stopped by SIGINT/SIGTERM: the shell's convention, 128 + signal. */
    if (rc == 0 && stop_signal)
        return 128 + stop_signal;
    return rc == 0 ? 0 : 1;
}
