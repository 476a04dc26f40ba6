/* parallel_setup.c: `-parallel`, OpenFOAM's way of running one case on the
 * ranks mpirun starts (`mpirun -np N mpsflow -parallel -case DIR`).
 *
 * The decomposition's settings come from system/decomposeParDict when the
 * case has one (OpenFOAM's file name; every key optional):
 *
 *   method              RCB;   // or HSFC (Zoltan's Hilbert space-filling curve)
 *   firstPartition      zoltan; // none: keep the scene's build order until the first
 *                              // step (a deliberately unbalanced start)
 *   imbalanceThreshold  1.1;   // a new partition when the heaviest rank carries
 *                              // more than this times the mean load
 *   multiCriteria       yes;   // balance the pressure rows as well as the load
 *   weights { fluid 1; wall 0.35; dummy 0.2; inlet 1; outlet 1; }
 *
 * Every rank reads the case and builds the whole scene (or reads the whole
 * restart snapshot); mf_app_distribute then keeps each rank's share and the
 * first partition sends every particle to its subdomain. */
#include <stdbool.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mf_app.h"
#include "mf_dictio.h"
#include "mf_error.h"

typedef struct decompose_settings {
    const char *method;
    const char *first_partition;
    double imbalance_threshold;
    bool multi_criteria;
    const mf_dict *weights;
} decompose_settings;

typedef struct weight_settings {
    double w[MF_NKINDS];
} weight_settings;

static const char *const methods[] = {"RCB", "HSFC", NULL};
static const char *const first_partitions[] = {"zoltan", "none", NULL};

static const mf_param decompose_params[] = {
    {"method", MF_PARAM_WORD, "RCB", MF_NO_RANGE, methods, offsetof(decompose_settings, method),
     "Zoltan partitioner: RCB (recursive coordinate bisection) or HSFC (Hilbert curve)"},
    {"firstPartition", MF_PARAM_WORD, "zoltan", MF_NO_RANGE, first_partitions,
     offsetof(decompose_settings, first_partition),
     "zoltan: partition at the start; none: each rank keeps its share of the scene in build "
     "order until the first step (a deliberately unbalanced start)"},
    {"imbalanceThreshold", MF_PARAM_SCALAR, "1.1", 1.0, 100, NULL,
     offsetof(decompose_settings, imbalance_threshold),
     "a new partition when the heaviest rank's load exceeds this times the mean"},
    {"multiCriteria", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL,
     offsetof(decompose_settings, multi_criteria),
     "balance the pressure equation's rows as well as the load (Zoltan's multi-criteria RCB "
     "picks the cut axis); no: the load alone, cut across the longest axis"},
    {"weights", MF_PARAM_DICT, "{}", MF_NO_RANGE, NULL, offsetof(decompose_settings, weights),
     "load of a particle of each kind relative to a fluid particle"},
};

static const mf_param weight_params[] = {
    {"fluid", MF_PARAM_SCALAR, "1", 0, 1e6, NULL, offsetof(weight_settings, w[MF_FLUID]),
     "load of a fluid particle"},
    {"wall", MF_PARAM_SCALAR, "0.35", 0, 1e6, NULL, offsetof(weight_settings, w[MF_WALL]),
     "load of a wall particle (in the pressure equation)"},
    {"dummy", MF_PARAM_SCALAR, "0.2", 0, 1e6, NULL, offsetof(weight_settings, w[MF_DUMMY]),
     "load of a dummy particle (number density only)"},
    {"inlet", MF_PARAM_SCALAR, "1", 0, 1e6, NULL, offsetof(weight_settings, w[MF_INLET]),
     "load of an inlet particle"},
    {"outlet", MF_PARAM_SCALAR, "1", 0, 1e6, NULL, offsetof(weight_settings, w[MF_OUTLET]),
     "load of an outlet particle"},
};

const mf_param_section mf_decompose_sections[] = {
    {"decomposeParDict",
     "system/decomposeParDict (optional, read by -parallel runs on more than one rank): how "
     "Zoltan splits the particles over the ranks",
     decompose_params, sizeof decompose_params / sizeof decompose_params[0]},
    {"decomposeParDict: weights",
     "its weights {} block: the load of a particle of each kind, relative to a fluid particle "
     "(measured: instructions a step per particle of the 3-D dam break)",
     weight_params, sizeof weight_params / sizeof weight_params[0]},
};
const size_t mf_decompose_nsections = 2;

int mf_app_check_parallel(const mf_options *opt, int argc, char **argv)
{
    const int nprocs = mf_parallel_world_size();
    if (nprocs == 1 || opt->parallel)
        return 0;
    /* Each rank would run the whole case and write the same output/. */
    char cmd[2048];
    size_t len = (size_t)snprintf(cmd, sizeof cmd, "mpsflow");
    int i = 1;
    if (argc > 1 && argv[1][0] != '-')
        len += (size_t)snprintf(cmd + len, sizeof cmd - len, " %s", argv[i++]);
    len += (size_t)snprintf(cmd + len, sizeof cmd - len, " -parallel");
    for (; i < argc && len < sizeof cmd; i++)
        len += (size_t)snprintf(cmd + len, sizeof cmd - len, " %s", argv[i]);
    return MF_ERROR(MF_ERR_INPUT,
                    "started on %d MPI ranks without -parallel: every rank would run the whole "
                    "case and write the same output. For one case on %d ranks type\n"
                    "    mpirun -np %d %s\nor run mpsflow without mpirun for a serial run",
                    nprocs, nprocs, nprocs, cmd);
}

int mf_app_create_parallel(mf_app *app, mf_dict *resolved)
{
    if (mf_parallel_world_size() == 1)
        return 0; /* -parallel on one rank is the serial run */
    char path[4400];
    snprintf(path, sizeof path, "%s/system/decomposeParDict", app->opt.case_dir);
    mf_dict *dict = NULL;
    struct stat st;
    if (stat(path, &st) == 0)
        MF_CALL(mf_dict_parse_file(path, &dict));
    decompose_settings ds;
    weight_settings ws;
    static const char *const extra[] = {"FoamFile", "numberOfSubdomains", NULL};
    mf_dict *rd = mf_dict_set_subdict(resolved, "decomposeParDict");
    int rc = mf_params_apply(decompose_params, sizeof decompose_params / sizeof decompose_params[0],
                             dict, extra, &ds, rd);
    if (rc == 0)
        rc = mf_params_apply(weight_params, sizeof weight_params / sizeof weight_params[0],
                             ds.weights, NULL, &ws, mf_dict_set_subdict(rd, "weights"));
    mf_parallel_settings s;
    mf_parallel_default_settings(&s);
    if (rc == 0) {
        s.method = strcmp(ds.method, "HSFC") == 0 ? MF_DECOMPOSE_HSFC : MF_DECOMPOSE_RCB;
        s.imbalance_threshold = ds.imbalance_threshold;
        s.first_partition = strcmp(ds.first_partition, "none") != 0;
        s.multi_criteria = ds.multi_criteria;
        memcpy(s.weight, ws.w, sizeof s.weight);
        rc = mf_parallel_create(&s, &app->sim.par);
    }
    if (rc == 0)
        mf_log_printf(&app->log, MF_LOG_NORMAL,
                      "Parallel: %d ranks, %s decomposition (Zoltan), new partition above "
                      "imbalance %g\n",
                      mf_parallel_size(app->sim.par), ds.method, s.imbalance_threshold);
    mf_dict_free(dict);
    return rc;
}

int mf_app_distribute(mf_app *app)
{
    mf_sim *sim = &app->sim;
    if (!sim->par)
        return 0;
    /* A quarter spacing of hysteresis: lattice rows on a cut stay put. */
    mf_parallel_set_margin(sim->par, 0.25 * sim->l0);
    MF_CALL(mf_parallel_distribute(sim->par, sim->p, sim->p->next_id));
    double c[2] = {(double)sim->p->n_owned, (double)sim->p->n_owned};
    mf_parallel_min(sim->par, &c[0], 1);
    mf_parallel_max(sim->par, &c[1], 1);
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "Decomposed: %.0f to %.0f particles a rank, load imbalance %.3f (pressure rows "
                  "%.3f)\n",
                  c[0], c[1], mf_parallel_statistics(sim->par)->imbalance,
                  mf_parallel_statistics(sim->par)->imbalance_rows);
    return 0;
}

/* One line a rank (at most 16 ranks; beyond that the smallest, mean and
 * largest): owned particles, the halo's share of the particles and the
 * bytes it sent a step, migration and rebalancing; then the linear solves
 * (every system the pressure modules solved: the PPE and the implicit
 * viscosity's): solves and preconditioner set-ups a step, set-up and
 * iteration time a step. */
void mf_app_report_parallel(const mf_app *app)
{
    mf_parallel *par = app->sim.par;
    if (!par)
        return;
    const mf_parallel_stats *st = mf_parallel_statistics(par);
    const double steps = app->run.steps > 0 ? (double)app->run.steps : 1.0;
    enum { NV = 13 };
    const double mine[NV] = {
        (double)app->sim.p->n_owned,
        st->owned_at_builds ? (double)st->halo_particles / (double)st->owned_at_builds : 0.0,
        st->halo_sent_bytes / steps,
        (double)st->migrated / steps,
        st->t_halo / steps,
        st->t_migrate / steps,
        st->t_rebalance,
        (double)st->rebalances,
        st->t_halo_wait / steps,
        (double)st->solves / steps,
        (double)st->solve_setups / steps,
        st->t_solve_setup / steps,
        st->t_solve_iterate / steps,
    };
    const int size = mf_parallel_size(par);
    double *all = malloc((size_t)size * NV * sizeof *all);
    if (!all)
        return; /* a report only: nothing is lost without it */
    mf_parallel_allgather(par, mine, sizeof mine, all);
    if (mf_parallel_is_root(par)) {
        mf_log *log = (mf_log *)&app->log;
        mf_log_printf(log, MF_LOG_QUIET,
                      "\nParallel: %d ranks, %ld new partitions, load imbalance %.3f at the end "
                      "(pressure rows %.3f)\n"
                      "    rank   owned  halo/owned  halo kB/step  migrated/step  halo ms/step "
                      "(waiting)  migrate ms/step  rebalance s\n",
                      size, st->rebalances, st->imbalance, st->imbalance_rows);
        for (int r = 0; r < size && size <= 16; r++) {
            const double *v = all + (size_t)r * NV;
            mf_log_printf(log, MF_LOG_QUIET,
                          "    %4d %7.0f %11.3f %13.1f %14.1f %13.2f (%7.2f) %16.2f %12.2f\n",
                          r, v[0], v[1], v[2] / 1024, v[3], 1e3 * v[4], 1e3 * v[8],
                          1e3 * v[5], v[6]);
        }
        mf_log_printf(log, MF_LOG_QUIET,
                      "    rank  solves/step  set-ups/step  set-up ms/step  iterations "
                      "ms/step\n");
        for (int r = 0; r < size && size <= 16; r++) {
            const double *v = all + (size_t)r * NV;
            mf_log_printf(log, MF_LOG_QUIET, "    %4d %12.2f %13.2f %15.2f %19.2f\n", r, v[9],
                          v[10], 1e3 * v[11], 1e3 * v[12]);
        }
        if (size > 16)
            for (int k = 0; k < NV; k++) {
                double lo = all[k], hi = all[k], sum = 0;
                for (int r = 0; r < size; r++) {
                    const double v = all[(size_t)r * NV + k];
                    lo = v < lo ? v : lo;
                    hi = v > hi ? v : hi;
                    sum += v;
                }
                mf_log_printf(log, MF_LOG_QUIET, "    column %d: min %g mean %g max %g\n", k + 2,
                              lo, sum / size, hi);
            }
    }
    free(all);
}
