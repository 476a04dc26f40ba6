/* mf_runs.h: running copies of a case as child processes, for the commands
 * that sweep a case (compare, stability). */
#ifndef MF_RUNS_H
#define MF_RUNS_H

#include <stddef.h>

#include "mf_dict.h"

/* How a run ended, from its output/runSummary. */
typedef struct mf_run_summary {
    char status[32];     /* completed | unstable | failed | "no summary" */
    char criterion[64];  /* the watch criterion, "none" or "other" */
    long steps, iterations, particles;
    double time, end_time;   /* reached, and asked for */
} mf_run_summary;

typedef struct mf_child_result {
    double wall_seconds, peak_mb;
    double cpu_seconds;  /* the child's user + system time (wait4's rusage):
                            less sensitive than wall time to a loaded machine */
    int exit_status;     /* 128 + signal when killed */
} mf_child_result;

/* Write run_dir/system/solverDict for a scheme: a variant of the case's
 * system/compareDict (`variants { NAME { ...entries... } }`, whose entries
 * replace those of solverDict, sub-dictionaries merging), or, when no
 * variant has that name, the solver module NAME with the case's solverDict. */
int mf_case_apply_scheme(const char *run_dir, const char *case_dir, const char *scheme);

/* Copy system/, constant/ and validation/ of a case to a new folder. */
int mf_case_copy(const char *from, const char *to);
/* Run the mpsflow executable with argv (argv[0] is replaced by its path),
 * stdout and stderr to log_path; its own wall time, CPU time and peak memory. */
int mf_run_child(char *argv[], const char *log_path, mf_child_result *r);
void mf_read_run_summary(const char *run_dir, mf_run_summary *s);
/* Entries of src replace those of dst; sub-dictionaries merge. */
int mf_dict_merge(mf_dict *dst, const mf_dict *src);
/* Write a dictionary file (temp + rename) with a comment line on top. */
int mf_dict_write_file(const mf_dict *d, const char *path, const char *comment);
/* "(a b c)" given for an option into a list; *tree owns it. */
int mf_parse_option_list(const char *option, const char *text, mf_dict **tree,
                         const mf_value **list);

#endif
