/* case_util.h: helpers for the physics tests, which run the mpsflow
 * executable on small cases and read back its snapshots.
 *
 *   tc_case c;
 *   tc_case_create(&c, argv[1], "hydrostatic");     // a fresh /tmp folder
 *   tc_case_write(&c, TC_CONTROL, "endTime 1; ...");
 *   ...
 *   int status = tc_case_run(&c, "run", (const char *[]){"-quiet", NULL});
 *   tc_snapshots s; tc_snapshots_list(c.dir, &s);
 *   mf_sim sim; tc_snapshot_load(c.dir, s.index[k], &sim, &header);
 *   ...
 *   tc_case_destroy(&c);   // removes the folder unless MF_TEST_KEEP=1
 *
 * The child runs with OMP_NUM_THREADS=1 unless MF_TEST_THREADS says
 * otherwise: the machine is shared, and an oversubscribed OpenMP team spins
 * an order of magnitude slower than one thread on these small cases. */
#ifndef TC_CASE_UTIL_H
#define TC_CASE_UTIL_H

#include <stdbool.h>
#include <stddef.h>

#include "mf_hdf5.h"
#include "mf_sim.h"

/* The four files of a case, relative to its folder. */
#define TC_CONTROL "system/controlDict"
#define TC_SOLVER "system/solverDict"
#define TC_FLUIDS "constant/fluids"
#define TC_GEOMETRY "constant/geometry"
#define TC_METRIC "validation/metric"

typedef struct tc_case {
    char dir[512];      /* the case folder */
    char exe[512];      /* the mpsflow executable */
    double last_wall;   /* wall seconds of the last tc_case_run */
} tc_case;

/* Make a unique empty folder /tmp/mpsflow-test-<tag>-XXXXXX with system/,
 * constant/ and validation/. Returns 0, or -1 with a message on stderr. */
int tc_case_create(tc_case *c, const char *exe, const char *tag);

/* Make a case and fill it from four strings (any may be NULL: not written). */
int tc_case_from_strings(tc_case *c, const char *exe, const char *tag, const char *control,
                         const char *solver, const char *fluids, const char *geometry);

/* Make a case as a copy of an existing case folder's system/, constant/ and
 * validation/ (never its output, postProcessing or logs). */
int tc_case_from_dir(tc_case *c, const char *exe, const char *tag, const char *src_dir);

/* Write (replace) a file of the case, `rel` relative to its folder. */
int tc_case_write(const tc_case *c, const char *rel, const char *text);

/* A whole file as a string (malloc'd; NULL if it cannot be read). */
char *tc_read_text(const char *path);

/* A solverDict's text with its forces block (from the line starting
 * "forces" to the end) replaced by `forces` (malloc'd; NULL when the text
 * has no such line). */
char *tc_with_forces(const char *text, const char *forces);

/* Run `mpsflow [command] -case DIR args...` (command NULL or "run": a plain
 * run; "validate": the validate command). args is NULL-terminated, may be
 * NULL. stdout and stderr are appended to DIR/log, each run headed by its
 * command line. Returns the exit status (128 + signal if killed, -1 if it
 * could not start). */
int tc_case_run(tc_case *c, const char *command, const char *const *args);
/* The same on np MPI ranks: `mpirun --oversubscribe --allow-run-as-root -np
 * np mpsflow [command] -parallel -case DIR args...` (np 0: tc_case_run). */
int tc_case_run_np(tc_case *c, int np, const char *command, const char *const *args);

/* Print the last `lines` lines of DIR/log to stderr (after a failure). */
void tc_case_log_tail(const tc_case *c, int lines);
/* True if DIR/log contains `text`. */
bool tc_case_log_contains(const tc_case *c, const char *text);

/* Remove the folder, unless MF_TEST_KEEP=1 (then say where it is). */
void tc_case_destroy(tc_case *c);

/* The snapshot indices of a case's output/, ascending. */
typedef struct tc_snapshots {
    int *index;
    size_t n;
} tc_snapshots;
int tc_snapshots_list(const char *case_dir, tc_snapshots *s);
void tc_snapshots_free(tc_snapshots *s);
void tc_snapshot_path(const char *case_dir, int index, char *path, size_t len);

/* Read snapshot `index` of a case into a zeroed *sim (particles created,
 * every stored field) and its header into *h (may be NULL). Free with
 * tc_sim_free. Returns 0, or non-zero with the error printed. */
int tc_snapshot_load(const char *case_dir, int index, mf_sim *sim, mf_hdf5_header *h);
void tc_sim_free(mf_sim *sim);

/* A stored field by name (NULL and a message if absent or of another type). */
const double *tc_field_d(const mf_particles *p, const char *name);
const int32_t *tc_field_i(const mf_particles *p, const char *name);

/* A number of the run's resolved parameters (DIR/output/resolvedParameters),
 * by a path of keys such as "solverDict/MPSCoeffs/reNumberDensity". */
int tc_resolved_number(const char *case_dir, const char *key_path, double *out);

/* Fluid particles in a snapshot. */
size_t tc_count_kind(const mf_particles *p, int kind);

#endif
