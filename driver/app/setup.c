/* setup.c: wire a case to the modules it names. */
#include <stdlib.h>
#include <string.h>

#include "mf_app.h"
#include "mf_dictio.h"
#include "mf_emitter.h"
#include "mf_error.h"
#include "mf_mesh_import.h"
#include "mf_scene.h"
#include "mf_walls.h"

int mf_app_load_libs_text(mf_registry *reg, const char *text)
{
    char buf[8192];
    snprintf(buf, sizeof buf, "libs %s;", text);
    mf_dict *d = NULL;
    MF_CALL(mf_dict_parse_string(buf, strlen(buf), "-libs", &d));
    mf_entry *e = mf_dict_find(d, "libs");
    int rc = 0;
    if (!e || e->n != 1 || e->items[0]->kind != MF_VAL_LIST) {
        rc = MF_ERROR(MF_ERR_INPUT, "-libs takes a list, e.g. -libs '(libkineticEnergy.so)'");
    } else {
        for (size_t k = 0; k < e->items[0]->n && rc == 0; k++)
            rc = mf_registry_load_plugin(reg, e->items[0]->items[k]->text);
    }
    mf_dict_free(d);
    return rc;
}

int mf_app_load_case_libs(mf_app *app)
{
    const char **libs = NULL;
    size_t n = 0;
    MF_CALL(mf_case_libs(&app->cs, &libs, &n));
    int rc = 0;
    for (size_t k = 0; k < n && rc == 0; k++)
        rc = mf_registry_load_plugin(app->reg, libs[k]);
    free(libs);
    return rc;
}

int mf_app_load_function_libs(mf_registry *reg, const mf_dict *fd)
{
    mf_entry *libs = mf_dict_find(fd, "libs");
    if (!libs)
        return 0;
    libs->used = true;
    for (size_t i = 0; libs->n == 1 && libs->items[0]->kind == MF_VAL_LIST &&
                       i < libs->items[0]->n;
         i++)
        MF_CALL(mf_registry_load_plugin(reg, libs->items[0]->items[i]->text));
    return 0;
}

/* forces { gravity { g (0 -9.81 0); } myDrag { type drag; ... } } */
static int create_forces(mf_app *app, mf_dict *resolved)
{
    const mf_dict *forces = mf_dict_subdict(app->cs.solver_dict, "forces");
    if (!forces)
        return 0;
    mf_sim *sim = &app->sim;
    sim->forces = calloc(forces->n ? forces->n : 1, sizeof *sim->forces);
    if (!sim->forces)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    mf_dict *rforces = mf_dict_set_subdict(resolved, "forces");
    static const char *const extra[] = {"type", NULL};
    char where[512];
    for (size_t k = 0; k < forces->n; k++) {
        mf_entry *e = forces->entries[k];
        if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT)
            return MF_ERROR(MF_ERR_INPUT, "%s: force '%s' must be a sub-dictionary { ... }",
                            mf_loc_str(e->loc, where, sizeof where), e->key);
        const mf_dict *fd = e->items[0]->dict;
        const char *type = e->key;
        MF_CALL(mf_dict_get_word_or(fd, "type", e->key, &type));
        mf_dict *rf = mf_dict_set_subdict(rforces, e->key);
        MF_CALL(mf_dict_set_word(rf, "type", type));
        mf_module *m = &sim->forces[sim->nforces];
        int rc = mf_module_prepare(app->reg, MF_KIND_FORCE, type, fd, extra, rf, m);
        if (rc != 0)
            return MF_ERROR(rc, "%s: force '%s': %s", mf_loc_str(e->loc, where, sizeof where),
                            e->key, mf_error_message());
        sim->nforces++;
        const mf_force_ops *ops = (const mf_force_ops *)m->info;
        MF_CALL(ops->create(m->settings, sim, &m->data));
    }
    return 0;
}

/* Does the solver's Coeffs set `wall wallWeight;`? Read before the scene is
 * built: the walls then have no particles (sim->wall_weight); the solver
 * checks the key with the rest of its parameters and refuses it where it
 * has no wall terms. */
static bool solver_wants_wall_weight(const mf_app *app)
{
    const mf_dict *sd = app->cs.solver_dict;
    const char *name = app->opt.solver;
    if (!name && mf_dict_get_word_or(sd, "solver", NULL, &name) != 0)
        return false;
    if (!name)
        return false;
    char coeffs[256];
    snprintf(coeffs, sizeof coeffs, "%sCoeffs", name);
    const mf_dict *cd = mf_dict_subdict(sd, coeffs);
    const char *wall = NULL;
    if (!cd || mf_dict_get_word_or(cd, "wall", NULL, &wall) != 0 || !wall)
        return false;
    return strcmp(wall, "wallWeight") == 0;
}

static int create_solver(mf_app *app, mf_dict *resolved)
{
    const mf_dict *sd = app->cs.solver_dict;
    const char *name = app->opt.solver;
    if (!name)
        MF_CALL(mf_dict_get_word(sd, "solver", &name));
    else if (mf_dict_find(sd, "solver"))
        mf_dict_find(sd, "solver")->used = true;
    /* Allowed top-level keys: solver, <name>Coeffs of any solver, pressure, forces. */
    char coeffs[256];
    snprintf(coeffs, sizeof coeffs, "%sCoeffs", name);
    const mf_module_info *info = NULL;
    MF_CALL(mf_registry_find(app->reg, MF_KIND_SOLVER, name, &info));
    size_t ns = mf_registry_count(app->reg, MF_KIND_SOLVER);
    char(*names)[256] = calloc(ns + 1, sizeof *names);
    const char **extra = calloc(ns + 7, sizeof *extra);
    if (!names || !extra) {
        free(names);
        free(extra);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    }
    size_t ne = 0;
    extra[ne++] = "solver";
    extra[ne++] = "pressure";
    extra[ne++] = "viscosity";
    extra[ne++] = "forces";
    extra[ne++] = "FoamFile";
    for (size_t k = 0; k < ns; k++) {
        snprintf(names[k], sizeof names[k], "%sCoeffs", mf_registry_at(app->reg, MF_KIND_SOLVER, k)->name);
        extra[ne++] = names[k];
    }
    extra[ne] = NULL;
    int rc = mf_params_apply(NULL, 0, sd, extra, NULL, NULL);
    free(names);
    free(extra);
    MF_CALL(rc);
    mf_dict *rs = mf_dict_set_subdict(resolved, "solverDict");
    MF_CALL(mf_dict_set_word(rs, "solver", name));
    MF_CALL(mf_module_prepare(app->reg, MF_KIND_SOLVER, name, mf_dict_subdict(sd, coeffs), NULL,
                              mf_dict_set_subdict(rs, coeffs), &app->solver));
    MF_CALL(create_forces(app, rs));
    const mf_solver_ops *ops = (const mf_solver_ops *)app->solver.info;
    /* The solver reads `pressure` itself; it records what it used in rs. */
    MF_CALL(ops->create(app->solver.settings, &app->sim, sd, &app->solver.data));
    /* The linear solvers' dictionaries as the case gave them. */
    static const char *const solves[] = {"pressure", "viscosity"};
    for (size_t s = 0; s < sizeof solves / sizeof *solves; s++) {
        const mf_dict *pd = mf_dict_subdict(sd, solves[s]);
        if (!pd)
            continue;
        mf_dict *rp = mf_dict_set_subdict(rs, solves[s]);
        for (size_t k = 0; k < pd->n; k++) {
            mf_entry *e = pd->entries[k];
            mf_value **items = calloc(e->n ? e->n : 1, sizeof *items);
            if (!items)
                return MF_ERROR(MF_ERR_MEMORY, "out of memory");
            for (size_t i = 0; i < e->n; i++)
                items[i] = mf_value_copy(e->items[i], rp);
            mf_dict_set(rp, e->key, e->loc, e->n, items);
        }
    }
    return 0;
}

/* functions { ke { type kineticEnergy; libs ("libkineticEnergy.so"); ... } } */
static int create_functions(mf_app *app, mf_dict *resolved)
{
    const mf_dict *fns = mf_dict_subdict(app->cs.control_dict, "functions");
    if (!fns)
        return 0;
    mf_dict_find(app->cs.control_dict, "functions")->used = true;
    app->functions = calloc(fns->n ? fns->n : 1, sizeof *app->functions);
    if (!app->functions)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    mf_dict *rfns = mf_dict_set_subdict(resolved, "functions");
    static const char *const extra[] = {"type", "libs", NULL};
    char where[512], out_dir[4400];
    for (size_t k = 0; k < fns->n; k++) {
        mf_entry *e = fns->entries[k];
        if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT)
            return MF_ERROR(MF_ERR_INPUT, "%s: function '%s' must be a sub-dictionary { type ...; }",
                            mf_loc_str(e->loc, where, sizeof where), e->key);
        const mf_dict *fd = e->items[0]->dict;
        MF_CALL(mf_app_load_function_libs(app->reg, fd));
        const char *type;
        MF_CALL(mf_dict_get_word(fd, "type", &type));
        mf_dict *rf = mf_dict_set_subdict(rfns, e->key);
        MF_CALL(mf_dict_set_word(rf, "type", type));
        mf_module *m = &app->functions[app->nfunctions];
        int rc = mf_module_prepare(app->reg, MF_KIND_FUNCTION_OBJECT, type, fd, extra, rf, m);
        if (rc != 0)
            return MF_ERROR(rc, "%s: function '%s': %s", mf_loc_str(e->loc, where, sizeof where),
                            e->key, mf_error_message());
        app->nfunctions++;
        snprintf(out_dir, sizeof out_dir, "%s/postProcessing/%s", app->cs.dir, e->key);
        const mf_function_object_ops *ops = (const mf_function_object_ops *)m->info;
        MF_CALL(ops->create(m->settings, &app->sim, out_dir, &m->data));
    }
    return 0;
}

static int create_writer(mf_app *app, mf_dict *resolved)
{
    const mf_dict *wd = mf_dict_subdict(app->cs.control_dict, "writerCoeffs");
    MF_CALL(mf_module_prepare(app->reg, MF_KIND_WRITER, app->cs.control.writer, wd, NULL,
                              mf_dict_set_subdict(resolved, "writerCoeffs"), &app->writer));
    const mf_writer_ops *ops = (const mf_writer_ops *)app->writer.info;
    MF_CALL(ops->create(app->writer.settings, app->cs.dir, &app->writer.data));
    return 0;
}

int mf_app_setup(mf_app *app)
{
    mf_sim *sim = &app->sim;
    mf_log_init(&app->log, stdout, app->opt.log_level);
    if (mf_parallel_world_rank() != 0)
        app->log.out = NULL; /* rank 0 writes the log */
    if (mf_parallel_world_size() > 1)
        app->log.progress = false; /* mpirun hands rank 0 a terminal even into a file */
    sim->log = &app->log;
    sim->reg = app->reg;
    MF_CALL(mf_neighbours_create(&sim->neighbours));
    MF_CALL(mf_case_read(app->opt.case_dir, &app->cs));
    MF_CALL(mf_app_create_parallel(app, app->cs.resolved));
    /* One rank looks at (and with -overwrite clears) output/: the others
     * would race it. */
    MF_CALL(mf_parallel_agree(app->sim.par,
                              mf_parallel_is_root(app->sim.par) ? mf_app_check_output(app) : 0));
    MF_CALL(mf_app_load_case_libs(app));
    const mf_control *c = &app->cs.control;
    sim->time = c->start_time;
    if (app->opt.end_time > 0)
        MF_CALL(mf_case_check_end_time(c, app->opt.end_time, "-endTime"));
    sim->end_time = app->opt.end_time > 0 ? app->opt.end_time : c->end_time;
    MF_CALL(mf_scene_read_fluids(app->cs.fluids, sim));
    mf_dict *resolved = app->cs.resolved;
    static mf_trimesh_reader mesh_reader; /* polygon files, for the scene and the modules */
    mesh_reader = mf_mesh_import_reader();
    sim->mesh_reader = &mesh_reader;
    sim->mesh_relative_to = app->cs.geometry->loc.file; /* constant/geometry */
    sim->wall_weight = solver_wants_wall_weight(app);
    MF_CALL(mf_app_memory_budget(app, &app->budget));
    MF_CALL(mf_scene_build_budgeted(app->cs.geometry, app->opt.l0, sim,
                                    mf_dict_set_subdict(resolved, "geometry"), &mesh_reader,
                                    &app->budget));
    MF_CALL(mf_scene_check_start(app->cs.geometry, sim));
    mf_dict *rf = mf_dict_set_subdict(resolved, "fluids");
    for (int k = 0; k < sim->nfluids; k++) {
        mf_dict *f = mf_dict_set_subdict(rf, sim->fluid[k].name);
        MF_CALL(mf_dict_set_number(f, "rho", sim->fluid[k].rho));
        MF_CALL(mf_dict_set_number(f, "nu", sim->fluid[k].nu));
        MF_CALL(mf_dict_set_number(f, "sigma", sim->fluid[k].sigma));
    }
    MF_CALL(create_solver(app, resolved));
    MF_CALL(create_functions(app, resolved));
    MF_CALL(create_writer(app, resolved));

    mf_run *run = &app->run;
    run->sim = sim;
    run->ctl.delta_t = c->delta_t;
    run->ctl.adjust = c->adjust_time_step;
    run->ctl.max_co = c->max_co;
    run->ctl.max_di = c->max_di;
    run->ctl.max_delta_t = c->max_delta_t;
    run->ctl.min_delta_t = c->min_delta_t;
    run->ctl.write_by_steps = strcmp(c->write_control, "timeStep") == 0;
    run->ctl.write_interval = c->write_interval;
    run->ctl.max_retries = c->max_retries;
    MF_CALL(mf_stop_at_parse(c->stop_at, &run->ctl.stop_at));
    run->ctl.purge_write = c->purge_write;
    if (c->run_time_modifiable)
        MF_CALL(mf_app_watch_control(app));
    run->solver_ops = (const mf_solver_ops *)app->solver.info;
    run->solver = &app->solver;
    run->writer_ops = (const mf_writer_ops *)app->writer.info;
    run->writer = &app->writer;
    run->nfunctions = app->nfunctions;
    run->functions = app->functions;
    run->params = resolved;
    const mf_dict *wd = mf_dict_subdict(app->cs.control_dict, "watch");
    if (wd)
        mf_dict_find(app->cs.control_dict, "watch")->used = true;
    MF_CALL(mf_watch_init(&run->watch, wd,
                          mf_dict_set_subdict(mf_dict_subdict(resolved, "controlDict"), "watch")));
    return 0;
}

void mf_app_teardown(mf_app *app)
{
    for (size_t k = 0; k < app->nfunctions; k++) {
        const mf_function_object_ops *ops = (const mf_function_object_ops *)app->functions[k].info;
        if (app->functions[k].data)
            ops->destroy(app->functions[k].data);
        mf_module_release(&app->functions[k]);
    }
    free(app->functions);
    if (app->writer.info && app->writer.data)
        ((const mf_writer_ops *)app->writer.info)->destroy(app->writer.data);
    mf_module_release(&app->writer);
    if (app->solver.info && app->solver.data)
        ((const mf_solver_ops *)app->solver.info)->destroy(app->solver.data);
    mf_module_release(&app->solver);
    app->sim.fault = (mf_fault_hook){0}; /* its context belongs to a force */
    for (size_t k = 0; k < app->sim.nforces; k++) {
        const mf_force_ops *ops = (const mf_force_ops *)app->sim.forces[k].info;
        if (app->sim.forces[k].data)
            ops->destroy(app->sim.forces[k].data);
        mf_module_release(&app->sim.forces[k]);
    }
    free(app->sim.forces);
    mf_walls_destroy(app->sim.walls);
    app->sim.walls = NULL;
    mf_app_unwatch_control(app);
    mf_emitters_destroy(app->sim.emitters);
    app->sim.emitters = NULL;
    mf_particles_destroy(app->sim.p);
    mf_neighbours_destroy(app->sim.neighbours);
    app->sim.neighbours = NULL;
    mf_parallel_destroy(app->sim.par);
    app->sim.par = NULL;
    mf_case_free(&app->cs);
}

void mf_app_summary(const mf_app *app)
{
    const mf_sim *sim = &app->sim;
    size_t counts[MF_NKINDS];
    mf_particles_count_kinds(sim->p, counts);
    int64_t total[MF_NKINDS + 1] = {0};
    for (int k = 0; k < MF_NKINDS; k++)
        total[MF_NKINDS] += total[k] = (int64_t)counts[k];
    mf_parallel_sum_i64(sim->par, total, MF_NKINDS + 1); /* over the ranks */
    double memory[2] = {mf_particles_memory(sim->p) / 1048576.0, mf_peak_memory() / 1048576.0};
    mf_parallel_max(sim->par, memory, 2);
    if (!mf_parallel_is_root(sim->par))
        return;
    printf("\nCase %s: %d-D, particle spacing l0 = %g m\n", app->cs.dir, sim->dim, sim->l0);
    printf("Particles: %lld in all\n", (long long)total[MF_NKINDS]);
    for (int k = 0; k < MF_NKINDS; k++)
        if (total[k])
            printf("    %-8s %lld\n", mf_particle_kind_name(k), (long long)total[k]);
    printf("Fluids:\n");
    for (int k = 0; k < sim->nfluids; k++)
        printf("    %-12s rho = %g kg/m^3, nu = %g m^2/s, sigma = %g N/m\n", sim->fluid[k].name,
               sim->fluid[k].rho, sim->fluid[k].nu, sim->fluid[k].sigma);
    const mf_emitters *em = sim->emitters;
    if (em)
        printf("Emitters: %zu inlet(s), %zu outlet(s), %zu nozzle(s)\n", em->ninlets,
               em->noutlets, em->nnozzles);
    for (int k = 0; k < sim->nscalars; k++)
        printf("Transported scalar: %s\n", sim->scalar_name[k]);
    printf("Solver %s; time %g to %g s\n", app->solver.info->name, sim->time, sim->end_time);
    printf("Memory: particles %.2f MB; peak resident %.1f MB%s\n", memory[0], memory[1],
           sim->par ? " (the largest rank)" : "");
    const mf_scene_budget *b = &app->budget;
    if (b->bytes_per_particle > 0)
        printf("Memory estimate: %.3g particles x %.0f bytes = %.3g GB of maxMemory %.3g GB (%s)\n",
               b->particles, b->bytes_per_particle, b->particles * b->bytes_per_particle / 1e9,
               b->max_bytes / 1e9, b->limit_source);
}
