/* runs.c: child runs of a case (mf_runs.h). */
#include "mf_runs.h"

#include <errno.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_fs.h"
#include "mf_run.h"

int mf_run_child(char *argv[], const char *log_path, mf_child_result *r)
{
    static char exe[4096];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (len <= 0)
        return MF_ERROR(MF_ERR_IO, "cannot find the mpsflow executable (/proc/self/exe)");
    exe[len] = '\0';
    argv[0] = exe;
    fflush(stdout);
    double t0 = mf_wall_seconds();
    pid_t pid = fork();
    if (pid < 0)
        return MF_ERROR(MF_ERR_IO, "cannot start a run (%s)", strerror(errno));
    if (pid == 0) {
        if (freopen(log_path, "w", stdout))
            dup2(fileno(stdout), 2);
        execv(argv[0], argv);
        _exit(127);
    }
    int status = 0;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) < 0)
        return MF_ERROR(MF_ERR_IO, "waiting for a run failed (%s)", strerror(errno));
    r->wall_seconds = mf_wall_seconds() - t0;
    r->peak_mb = ru.ru_maxrss / 1024.0;
    r->cpu_seconds = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
                     (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    r->exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return 0;
}

int mf_case_copy(const char *from, const char *to)
{
    char cmd[9000];
    if (strchr(from, '\'') || strchr(to, '\''))
        return MF_ERROR(MF_ERR_INPUT, "case paths with quotes are not supported: %s", from);
    if (snprintf(cmd, sizeof cmd,
                 "rm -rf '%s' && mkdir -p '%s' && cp -r '%s/system' '%s/constant' '%s' && "
                 "{ [ ! -d '%s/validation' ] || cp -r '%s/validation' '%s'; }",
                 to, to, from, from, to, from, from, to) >= (int)sizeof cmd)
        return MF_ERROR(MF_ERR_INPUT, "case path too long: %s", from);
    if (system(cmd) != 0)
        return MF_ERROR(MF_ERR_IO, "cannot copy case %s to %s", from, to);
    return 0;
}

int mf_dict_merge(mf_dict *dst, const mf_dict *src)
{
    for (size_t k = 0; k < src->n; k++) {
        const mf_entry *e = src->entries[k];
        mf_dict *sub_dst = mf_dict_subdict(dst, e->key);
        if (e->n == 1 && e->items[0]->kind == MF_VAL_DICT && sub_dst) {
            MF_CALL(mf_dict_merge(sub_dst, e->items[0]->dict));
            continue;
        }
        mf_value **items = calloc(e->n ? e->n : 1, sizeof *items);
        if (!items)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory");
        for (size_t i = 0; i < e->n; i++)
            items[i] = mf_value_copy(e->items[i], dst);
        if (!mf_dict_set(dst, e->key, e->loc, e->n, items))
            return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    }
    return 0;
}

int mf_dict_write_file(const mf_dict *d, const char *path, const char *comment)
{
    mf_replace out;
    MF_CALL(mf_replace_open(&out, path, "w"));
    fprintf(out.f, "// %s\n", comment);
    MF_CALL(mf_replace_commit(&out, mf_dict_write(d, out.f, 0)));
    return 0;
}

void mf_read_run_summary(const char *run_dir, mf_run_summary *s)
{
    char path[4400];
    mf_dict *d = NULL;
    memset(s, 0, sizeof *s);
    snprintf(s->status, sizeof s->status, "no summary");
    if (snprintf(path, sizeof path, "%s/output/runSummary", run_dir) >= (int)sizeof path ||
        mf_dict_parse_file(path, &d) != 0) {
        mf_error_clear();
        return;
    }
    const char *w = NULL;
    double x;
    if (mf_dict_get_word(d, "status", &w) == 0)
        snprintf(s->status, sizeof s->status, "%s", w);
    if (mf_dict_get_word(d, "criterion", &w) == 0)
        snprintf(s->criterion, sizeof s->criterion, "%s", w);
    if (mf_dict_get_number(d, "steps", &x) == 0) s->steps = (long)x;
    if (mf_dict_get_number(d, "pressureIterations", &x) == 0) s->iterations = (long)x;
    if (mf_dict_get_number(d, "particles", &x) == 0) s->particles = (long)x;
    if (mf_dict_get_number(d, "time", &x) == 0) s->time = x;
    if (mf_dict_get_number(d, "endTime", &x) == 0) s->end_time = x;
    mf_error_clear();
    mf_dict_free(d);
}

int mf_parse_option_list(const char *option, const char *text, mf_dict **tree,
                         const mf_value **list)
{
    char buf[8192];
    if (snprintf(buf, sizeof buf, "x %s;", text) >= (int)sizeof buf)
        return MF_ERROR(MF_ERR_INPUT, "%s: list too long", option);
    MF_CALL(mf_dict_parse_string(buf, strlen(buf), option, tree));
    mf_entry *e = mf_dict_find(*tree, "x");
    if (!e || e->n != 1 || e->items[0]->kind != MF_VAL_LIST || e->items[0]->n == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s takes a non-empty list, e.g. %s '(a b)'", option,
                        option);
    *list = e->items[0];
    return 0;
}

typedef struct compare_settings {
    const mf_dict *variants;
} compare_settings;

const mf_param mf_compare_params[] = {
    {"variants", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(compare_settings, variants),
     "one sub-dictionary per scheme: entries that replace those of solverDict (sub-dictionaries "
     "merge), e.g. MPS_plain { MPSCoeffs { relaxation 1; } }"},
};
const mf_param_section mf_compare_sections[] = {
    {"compareDict", "system/compareDict: the schemes `mpsflow compare` can name", mf_compare_params,
     1},
};
const size_t mf_compare_nsections = 1;

int mf_case_apply_scheme(const char *run_dir, const char *case_dir, const char *scheme)
{
    char path[4400], comment[4600];
    mf_dict *cd = NULL, *sd = NULL;
    int rc = 0;
    snprintf(path, sizeof path, "%s/system/compareDict", case_dir);
    if (access(path, R_OK) == 0)
        MF_CALL(mf_dict_parse_file(path, &cd));
    snprintf(path, sizeof path, "%s/system/solverDict", case_dir);
    rc = mf_dict_parse_file(path, &sd);
    if (cd) {
        compare_settings cs;
        static const char *const extra[] = {"FoamFile", NULL};
        int crc = mf_params_apply(mf_compare_params, 1, cd, extra, &cs, NULL);
        if (crc != 0) {
            mf_dict_free(cd);
            return mf_error_trace(crc, __FILE__, __LINE__, __func__);
        }
    }
    const mf_dict *variants = cd ? mf_dict_subdict(cd, "variants") : NULL;
    const mf_dict *v = variants ? mf_dict_subdict(variants, scheme) : NULL;
    if (rc == 0)
        rc = v ? mf_dict_merge(sd, v) : mf_dict_set_word(sd, "solver", scheme);
    snprintf(comment, sizeof comment, "solverDict of %s with scheme '%s' (written by mpsflow)",
             case_dir, scheme);
    if (rc == 0 && snprintf(path, sizeof path, "%s/system/solverDict", run_dir) >= (int)sizeof path)
        rc = MF_ERROR(MF_ERR_INPUT, "path too long: %s", run_dir);
    if (rc == 0)
        rc = mf_dict_write_file(sd, path, comment);
    mf_dict_free(sd);
    mf_dict_free(cd);
    return rc;
}
