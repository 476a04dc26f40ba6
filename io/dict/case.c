/* case.c: the case reader. */
#include "mf_case.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_fs.h"
#include "mf_params.h"

static const char *const write_controls[] = {"adjustableRunTime", "timeStep", NULL};
static const char *const start_froms[] = {"startTime", "latestTime", NULL};
static const char *const stop_ats[] = {"endTime", "writeNow", "noWriteNow", "nextWrite", NULL};

/* Ranges: what the numerics allow, each said in its doc line (the key
 * reference, docs/reference.md, is generated from these). */
const mf_param mf_control_params[] = {
    {"application", MF_PARAM_WORD, "mpsflow", MF_NO_RANGE, NULL, offsetof(mf_control, application),
     "informational, as in OpenFOAM"},
    {"startTime", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(mf_control, start_time),
     "time of the initial state, s (as endTime)"},
    {"endTime", MF_PARAM_SCALAR, NULL, 0, 1e9, NULL, offsetof(mf_control, end_time),
     "time to stop, s; a double time holds 16 digits, so at 1e9 s it still resolves steps of "
     "1e-6 s: beyond that, steps would be lost in rounding"},
    {"deltaT", MF_PARAM_SCALAR, "1e-4", 1e-12, 1e6, NULL, offsetof(mf_control, delta_t),
     "first time step (every step when adjustTimeStep is off; the last one is shortened to "
     "land on endTime and on write times), s"},
    {"adjustTimeStep", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL,
     offsetof(mf_control, adjust_time_step), "choose dt from the Courant and viscous limits"},
    {"maxCo", MF_PARAM_SCALAR, "0.2", 1e-6, 2, NULL, offsetof(mf_control, max_co),
     "largest Courant number |u| dt / l0. The explicit half of the semi-implicit MPS step moves "
     "a particle Co l0 before the pressure equation sees it: at Co = 1 it reaches its "
     "neighbour's place and the pressure can no longer keep them apart (damBreak2D is unstable "
     "from 1); up to 2 is allowed so that a stability map can show that"},
    {"maxDi", MF_PARAM_SCALAR, "0.1", 0, 2, NULL, offsetof(mf_control, max_di),
     "largest viscous number nu dt / l0^2 of the explicit viscous term (0: no viscous limit). "
     "Forward Euler on the Laplacian of eq. 7 is stable to about 1 on a lattice (measured on "
     "poiseuille2D: stable at 1, unstable from 1.25): beyond 2 it never is"},
    {"maxDeltaT", MF_PARAM_SCALAR, "1", 1e-12, 1e6, NULL, offsetof(mf_control, max_delta_t),
     "largest time step, s"},
    {"minDeltaT", MF_PARAM_SCALAR, "1e-8", 0, 1, NULL, offsetof(mf_control, min_delta_t),
     "an adjustable step below this stops the run as unstable (timeStep), s; must be below "
     "maxDeltaT"},
    {"writeControl", MF_PARAM_WORD, "adjustableRunTime", MF_NO_RANGE, write_controls,
     offsetof(mf_control, write_control), "writeInterval in seconds or in steps"},
    {"writeInterval", MF_PARAM_SCALAR, NULL, 1e-12, 1e9, NULL,
     offsetof(mf_control, write_interval),
     "time (s, adjustableRunTime: steps land on each write time) or steps (timeStep: a whole "
     "number >= 1) between snapshots"},
    {"writer", MF_PARAM_WORD, "hdf5", MF_NO_RANGE, NULL, offsetof(mf_control, writer),
     "writer module for snapshots"},
    {"startFrom", MF_PARAM_WORD, "startTime", MF_NO_RANGE, start_froms,
     offsetof(mf_control, start_from), "latestTime restarts from the newest snapshot"},
    {"maxRetries", MF_PARAM_INT, "4", 0, 20, NULL, offsetof(mf_control, max_retries),
     "retries of a failed step, each with half the time step (20 halvings: a millionth)"},
    {"maxMemory", MF_PARAM_SCALAR, "0", 0, 1e6, NULL, offsetof(mf_control, max_memory),
     "GB the scene may need by the memory estimate (particles times bytes a particle), "
     "checked before any particle is made; 0: 80% of this machine's memory (or of the "
     "cgroup's limit)"},
    /* ---- run control (issue 15; core/run/run_control.c) ---------------- */
    {"stopAt", MF_PARAM_WORD, "endTime", MF_NO_RANGE, stop_ats, offsetof(mf_control, stop_at),
     "endTime; writeNow / noWriteNow: stop after the current step with / without a snapshot; "
     "nextWrite: after the next snapshot"},
    {"runTimeModifiable", MF_PARAM_BOOL, "no", MF_NO_RANGE, NULL,
     offsetof(mf_control, run_time_modifiable),
     "re-read this file between steps when it changes (endTime, stopAt, writeInterval, "
     "time-step limits, purgeWrite)"},
    {"purgeWrite", MF_PARAM_INT, "0", 0, 1000000000, NULL, offsetof(mf_control, purge_write),
     "keep only the newest N snapshots of this run, besides the initial one (0: keep all)"},
};
const size_t mf_control_nparams = sizeof mf_control_params / sizeof mf_control_params[0];

static int read_one(const char *dir, const char *rel, mf_dict **out)
{
    char path[4400];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    struct stat st;
    if (stat(path, &st) != 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: cannot open (%s); is '%s' a case directory?", path,
                        strerror(errno), dir);
    MF_CALL(mf_dict_parse_file(path, out));
    return 0;
}

/* Keys that are sound alone but not together. */
static int check_control(const mf_dict *d, const mf_control *c)
{
    char where[512];
    const mf_entry *e = mf_dict_find(d, "endTime");
    if (c->end_time <= c->start_time)
        return MF_ERROR(MF_ERR_INPUT, "%s: endTime (%g) must be after startTime (%g)",
                        mf_loc_str(e->loc, where, sizeof where), c->end_time, c->start_time);
    if (c->adjust_time_step && !(c->min_delta_t < c->max_delta_t)) {
        e = mf_dict_find(d, "minDeltaT") ? mf_dict_find(d, "minDeltaT")
                                         : mf_dict_find(d, "maxDeltaT");
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: minDeltaT (%g s) must be below maxDeltaT (%g s): every adjustable "
                        "step would stop the run as unstable",
                        e ? mf_loc_str(e->loc, where, sizeof where) : "system/controlDict",
                        c->min_delta_t, c->max_delta_t);
    }
    if (strcmp(c->write_control, "timeStep") == 0 &&
        (c->write_interval < 1 || c->write_interval != floor(c->write_interval))) {
        e = mf_dict_find(d, "writeInterval");
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: writeInterval %g: with writeControl timeStep it counts steps, a "
                        "whole number >= 1",
                        mf_loc_str(e->loc, where, sizeof where), c->write_interval);
    }
    return 0;
}

/* controlDict's keys into *c (resolved may be NULL). */
static int apply_control(const mf_dict *d, mf_control *c, mf_dict *resolved)
{
    static const char *const extra[] = {"FoamFile", "libs", "functions", "watch", "writerCoeffs",
                                        NULL};
    MF_CALL(mf_params_apply(mf_control_params, mf_control_nparams, d, extra, c, resolved));
    MF_CALL(check_control(d, c));
    return 0;
}

int mf_case_read(const char *dir, mf_case *c)
{
    memset(c, 0, sizeof *c);
    if (strlen(dir) >= sizeof c->dir)
        return MF_ERROR(MF_ERR_INPUT, "case path too long");
    snprintf(c->dir, sizeof c->dir, "%s", dir);
    MF_CALL(read_one(dir, "system/controlDict", &c->control_dict));
    MF_CALL(read_one(dir, "system/solverDict", &c->solver_dict));
    MF_CALL(read_one(dir, "constant/fluids", &c->fluids));
    MF_CALL(read_one(dir, "constant/geometry", &c->geometry));
    c->resolved = mf_dict_new("", NULL);
    if (!c->resolved)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    MF_CALL(apply_control(c->control_dict, &c->control,
                          mf_dict_set_subdict(c->resolved, "controlDict")));
    return 0;
}

int mf_case_reread_control(const char *dir, mf_control *control, mf_dict **tree)
{
    mf_dict *d = NULL;
    MF_CALL(read_one(dir, "system/controlDict", &d));
    mf_control c;
    int rc = apply_control(d, &c, NULL);
    if (rc != 0) {
        mf_dict_free(d);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    *control = c;
    *tree = d;
    return 0;
}

const mf_param *mf_case_control_param(const char *name)
{
    for (size_t k = 0; k < mf_control_nparams; k++)
        if (strcmp(mf_control_params[k].name, name) == 0)
            return &mf_control_params[k];
    return NULL;
}

int mf_case_check_end_time(const mf_control *c, double end_time, const char *source)
{
    const mf_param *p = mf_case_control_param("endTime");
    if (!isfinite(end_time) || end_time < p->min || end_time > p->max)
        return MF_ERROR(MF_ERR_INPUT, "%s: endTime %g is out of range [%g, %g] (%s)", source,
                        end_time, p->min, p->max, p->doc);
    if (end_time <= c->start_time)
        return MF_ERROR(MF_ERR_INPUT, "%s: endTime (%g) must be after startTime (%g)", source,
                        end_time, c->start_time);
    return 0;
}

void mf_case_free(mf_case *c)
{
    mf_dict_free(c->control_dict);
    mf_dict_free(c->solver_dict);
    mf_dict_free(c->fluids);
    mf_dict_free(c->geometry);
    mf_dict_free(c->resolved);
    memset(c, 0, sizeof *c);
}

int mf_case_libs(const mf_case *c, const char ***libs, size_t *n)
{
    *libs = NULL;
    *n = 0;
    mf_entry *e = mf_dict_find(c->control_dict, "libs");
    if (!e)
        return 0;
    e->used = true;
    char where[512];
    if (e->n != 1 || e->items[0]->kind != MF_VAL_LIST)
        return MF_ERROR(MF_ERR_INPUT, "%s: 'libs' takes a list, e.g. libs (\"libprobes.so\");",
                        mf_loc_str(e->loc, where, sizeof where));
    const mf_value *list = e->items[0];
    *libs = calloc(list->n + 1, sizeof **libs);
    if (!*libs)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    for (size_t k = 0; k < list->n; k++) {
        const mf_value *v = list->items[k];
        if (v->kind != MF_VAL_WORD && v->kind != MF_VAL_STRING) {
            free(*libs);
            *libs = NULL;
            return MF_ERROR(MF_ERR_INPUT, "%s: 'libs' entries are library names",
                            mf_loc_str(v->loc, where, sizeof where));
        }
        (*libs)[k] = v->text;
    }
    *n = list->n;
    return 0;
}

int mf_case_write_resolved(const mf_case *c)
{
    char dir[4200], path[4300];
    snprintf(dir, sizeof dir, "%s/output", c->dir);
    MF_CALL(mf_mkdir(dir));
    snprintf(path, sizeof path, "%s/resolvedParameters", dir);
    mf_replace out;
    MF_CALL(mf_replace_open(&out, path, "w"));
    fprintf(out.f, "// Parameters of this run as used, defaults included (written by mpsflow "
                   "%s).\n\n",
            MPSFLOW_VERSION);
    MF_CALL(mf_replace_commit(&out, mf_dict_write(c->resolved, out.f, 0)));
    return 0;
}
