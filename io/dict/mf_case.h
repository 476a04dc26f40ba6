/* mf_case.h: read a case directory (OpenFOAM layout).
 *
 *   system/controlDict   time, writing, time-step limits, libs, functions
 *   system/solverDict    solver NAME; <NAME>Coeffs {...}; pressure {...};
 *                        forces { gravity { g (0 -9.81 0); } }
 *   constant/fluids      one sub-dictionary per fluid
 *   constant/geometry    particle spacing, fluid blocks, walls
 */
#ifndef MF_CASE_H
#define MF_CASE_H

#include <stdbool.h>

#include "mf_dict.h"
#include "mf_params.h"

typedef struct mf_control {
    const char *application; /* informational, as in OpenFOAM */
    double start_time;   /* informational; a restart takes the snapshot's time */
    double end_time;
    double delta_t;      /* first step, or every step when !adjust_time_step */
    bool adjust_time_step;
    double max_co;
    double max_di;       /* viscous number nu dt / l0^2 */
    double max_delta_t;
    double min_delta_t;
    const char *write_control; /* adjustableRunTime | timeStep */
    double write_interval;
    const char *writer;  /* writer module name */
    const char *start_from; /* startTime | latestTime */
    long max_retries;    /* retries of a failed step with a smaller dt */
    double max_memory;   /* GB a scene may need (0: 80% of the machine's memory) */
    /* Run control (issue 15). */
    const char *stop_at; /* endTime | writeNow | noWriteNow | nextWrite */
    bool run_time_modifiable;
    long purge_write;
} mf_control;

typedef struct mf_case {
    char dir[4096];
    mf_dict *control_dict, *solver_dict, *fluids, *geometry;
    mf_control control;
    mf_dict *resolved;   /* everything as used, defaults included */
} mf_case;

/* Read and validate the four files. On error *c is left freeable. */
int mf_case_read(const char *dir, mf_case *c);
void mf_case_free(mf_case *c);
/* The words of a `libs ( ... );` entry of controlDict (NULL-terminated,
 * pointing into the tree). */
int mf_case_libs(const mf_case *c, const char ***libs, size_t *n);
/* Read DIR/system/controlDict again (runTimeModifiable): *control and
 * *tree (which its strings point into; free it with mf_dict_free) on
 * success; on a bad file an error naming file, line and key, and nothing
 * changed. */
int mf_case_reread_control(const char *dir, mf_control *control, mf_dict **tree);
/* Write c->resolved to DIR/output/resolvedParameters (temp + rename). */
int mf_case_write_resolved(const mf_case *c);

extern const mf_param mf_control_params[];
extern const size_t mf_control_nparams;
/* The controlDict table's entry of a key (NULL if none). */
const mf_param *mf_case_control_param(const char *name);
/* An endTime from elsewhere (-endTime, compare, stability): in endTime's
 * range and after startTime; source names it in the message. */
int mf_case_check_end_time(const mf_control *c, double end_time, const char *source);

#endif
