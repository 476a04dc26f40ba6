/* case_util.c: temporary cases, runs of the mpsflow executable, snapshots. */
#include "case_util.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "mf_dictio.h"
#include "mf_error.h"

static double wall_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int make_dir(const char *path)
{
    if (mkdir(path, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "case_util: cannot create %s (%s)\n", path, strerror(errno));
        return -1;
    }
    return 0;
}

int tc_case_create(tc_case *c, const char *exe, const char *tag)
{
    memset(c, 0, sizeof *c);
    snprintf(c->exe, sizeof c->exe, "%s", exe ? exe : "");
    if (!exe || access(exe, X_OK) != 0) {
        fprintf(stderr, "case_util: mpsflow executable '%s' is not runnable (pass its path as "
                        "the first argument)\n",
                exe ? exe : "(none)");
        return -1;
    }
    snprintf(c->dir, sizeof c->dir, "/tmp/mpsflow-test-%s-XXXXXX", tag);
    if (!mkdtemp(c->dir)) {
        fprintf(stderr, "case_util: mkdtemp %s failed (%s)\n", c->dir, strerror(errno));
        c->dir[0] = '\0';
        return -1;
    }
    static const char *const subdirs[] = {"system", "constant", "validation"};
    char path[700];
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/%s", c->dir, subdirs[k]);
        if (make_dir(path) != 0)
            return -1;
    }
    return 0;
}

int tc_case_write(const tc_case *c, const char *rel, const char *text)
{
    char path[1100];
    snprintf(path, sizeof path, "%s/%s", c->dir, rel);
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "case_util: cannot write %s (%s)\n", path, strerror(errno));
        return -1;
    }
    size_t len = strlen(text);
    int rc = fwrite(text, 1, len, f) == len ? 0 : -1;
    if (fclose(f) != 0)
        rc = -1;
    if (rc != 0)
        fprintf(stderr, "case_util: write to %s failed\n", path);
    return rc;
}

int tc_case_from_strings(tc_case *c, const char *exe, const char *tag, const char *control,
                         const char *solver, const char *fluids, const char *geometry)
{
    if (tc_case_create(c, exe, tag) != 0)
        return -1;
    const char *rel[4] = {TC_CONTROL, TC_SOLVER, TC_FLUIDS, TC_GEOMETRY};
    const char *text[4] = {control, solver, fluids, geometry};
    for (int k = 0; k < 4; k++)
        if (text[k] && tc_case_write(c, rel[k], text[k]) != 0)
            return -1;
    return 0;
}

static int copy_file(const char *from, const char *to)
{
    FILE *in = fopen(from, "rb");
    if (!in) {
        fprintf(stderr, "case_util: cannot read %s (%s)\n", from, strerror(errno));
        return -1;
    }
    FILE *out = fopen(to, "wb");
    if (!out) {
        fprintf(stderr, "case_util: cannot write %s (%s)\n", to, strerror(errno));
        fclose(in);
        return -1;
    }
    char buf[65536];
    size_t n;
    int rc = 0;
    while ((n = fread(buf, 1, sizeof buf, in)) > 0)
        if (fwrite(buf, 1, n, out) != n)
            rc = -1;
    if (ferror(in))
        rc = -1;
    fclose(in);
    if (fclose(out) != 0)
        rc = -1;
    if (rc != 0)
        fprintf(stderr, "case_util: copying %s to %s failed\n", from, to);
    return rc;
}

/* Copy a folder's regular files and sub-folders. */
static int copy_tree(const char *from, const char *to)
{
    if (make_dir(to) != 0)
        return -1;
    DIR *d = opendir(from);
    if (!d)
        return 0; /* an absent folder (no validation/) copies as empty */
    int rc = 0;
    struct dirent *e;
    while (rc == 0 && (e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        char a[1400], b[1400];
        snprintf(a, sizeof a, "%s/%s", from, e->d_name);
        snprintf(b, sizeof b, "%s/%s", to, e->d_name);
        struct stat st;
        if (stat(a, &st) != 0)
            continue;
        if (S_ISDIR(st.st_mode))
            rc = copy_tree(a, b);
        else if (S_ISREG(st.st_mode))
            rc = copy_file(a, b);
    }
    closedir(d);
    return rc;
}

int tc_case_from_dir(tc_case *c, const char *exe, const char *tag, const char *src_dir)
{
    if (tc_case_create(c, exe, tag) != 0)
        return -1;
    static const char *const parts[] = {"system", "constant", "validation"};
    for (int k = 0; k < 3; k++) {
        char a[1100], b[1100];
        snprintf(a, sizeof a, "%s/%s", src_dir, parts[k]);
        snprintf(b, sizeof b, "%s/%s", c->dir, parts[k]);
        if (copy_tree(a, b) != 0)
            return -1;
    }
    char probe[1100];
    snprintf(probe, sizeof probe, "%s/%s", c->dir, TC_CONTROL);
    if (access(probe, R_OK) != 0) {
        fprintf(stderr, "case_util: %s is not a case folder (no %s)\n", src_dir, TC_CONTROL);
        return -1;
    }
    return 0;
}

int tc_case_run(tc_case *c, const char *command, const char *const *args)
{
    return tc_case_run_np(c, 0, command, args);
}

int tc_case_run_np(tc_case *c, int np, const char *command, const char *const *args)
{
    const char *argv[64];
    char np_text[16];
    int argc = 0;
    if (np > 0) {
        snprintf(np_text, sizeof np_text, "%d", np);
        argv[argc++] = "mpirun";
        argv[argc++] = "--oversubscribe";
        argv[argc++] = "--allow-run-as-root";
        argv[argc++] = "-np";
        argv[argc++] = np_text;
    }
    argv[argc++] = c->exe;
    if (command && strcmp(command, "run") != 0)
        argv[argc++] = command;
    if (np > 0)
        argv[argc++] = "-parallel";
    argv[argc++] = "-case";
    argv[argc++] = c->dir;
    for (size_t k = 0; args && args[k] && argc < 63; k++)
        argv[argc++] = args[k];
    argv[argc] = NULL;

    char log_path[700];
    snprintf(log_path, sizeof log_path, "%s/log", c->dir);
    FILE *log = fopen(log_path, "a");
    if (!log) {
        fprintf(stderr, "case_util: cannot open %s (%s)\n", log_path, strerror(errno));
        return -1;
    }
    fprintf(log, "\n$");
    for (int k = 0; k < argc; k++)
        fprintf(log, " %s", argv[k]);
    fprintf(log, "\n");
    fclose(log);

    const char *threads = getenv("MF_TEST_THREADS");
    double t0 = wall_now();
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid < 0) {
        fprintf(stderr, "case_util: fork failed (%s)\n", strerror(errno));
        return -1;
    }
    if (pid == 0) {
        int fd = open(log_path, O_WRONLY | O_APPEND | O_CREAT, 0666);
        if (fd < 0)
            _exit(126);
        dup2(fd, STDOUT_FILENO);
        dup2(fd, STDERR_FILENO);
        close(fd);
        setenv("OMP_NUM_THREADS", threads && *threads ? threads : "1", 1);
        execvp(argv[0], (char *const *)argv);
        fprintf(stderr, "case_util: cannot run %s (%s)\n", argv[0], strerror(errno));
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) {
            fprintf(stderr, "case_util: waitpid failed (%s)\n", strerror(errno));
            return -1;
        }
    c->last_wall = wall_now() - t0;
    if (WIFEXITED(status))
        return WEXITSTATUS(status);
    if (WIFSIGNALED(status))
        return 128 + WTERMSIG(status);
    return -1;
}

static char *read_log(const tc_case *c)
{
    char path[700];
    snprintf(path, sizeof path, "%s/log", c->dir);
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = malloc(size > 0 ? (size_t)size + 1 : 1);
    size_t got = text && size > 0 ? fread(text, 1, (size_t)size, f) : 0;
    fclose(f);
    if (text)
        text[got] = '\0';
    return text;
}

void tc_case_log_tail(const tc_case *c, int lines)
{
    char *text = read_log(c);
    if (!text) {
        fprintf(stderr, "(no log in %s)\n", c->dir);
        return;
    }
    size_t len = strlen(text);
    const char *start = text;
    int seen = 0;
    for (size_t k = len; k > 0; k--)
        if (text[k - 1] == '\n' && ++seen > lines) {
            start = &text[k];
            break;
        }
    fprintf(stderr, "---- last lines of %s/log ----\n%s---- end of log ----\n", c->dir, start);
    free(text);
}

bool tc_case_log_contains(const tc_case *c, const char *needle)
{
    char *text = read_log(c);
    bool found = text && strstr(text, needle) != NULL;
    free(text);
    return found;
}

static void remove_tree(const char *path)
{
    DIR *d = opendir(path);
    if (d) {
        struct dirent *e;
        while ((e = readdir(d))) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
                continue;
            char child[1400];
            snprintf(child, sizeof child, "%s/%s", path, e->d_name);
            struct stat st;
            if (lstat(child, &st) == 0 && S_ISDIR(st.st_mode))
                remove_tree(child);
            else
                unlink(child);
        }
        closedir(d);
    }
    rmdir(path);
}

void tc_case_destroy(tc_case *c)
{
    if (!c->dir[0])
        return;
    const char *keep = getenv("MF_TEST_KEEP");
    if (keep && !strcmp(keep, "1"))
        printf("MF_TEST_KEEP=1: keeping %s\n", c->dir);
    else if (strncmp(c->dir, "/tmp/mpsflow-test-", 18) == 0)
        remove_tree(c->dir);
    c->dir[0] = '\0';
}

/* ---- snapshots ----------------------------------------------------------- */
static int by_value(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

int tc_snapshots_list(const char *case_dir, tc_snapshots *s)
{
    s->index = NULL;
    s->n = 0;
    char dir[700];
    snprintf(dir, sizeof dir, "%s/output", case_dir);
    DIR *d = opendir(dir);
    if (!d) {
        fprintf(stderr, "case_util: no output folder %s\n", dir);
        return -1;
    }
    size_t cap = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        int idx, used = 0;
        /* Exactly snapshot_<digits>.h5: not the .tmp files of a write. */
        if (sscanf(e->d_name, "snapshot_%d.h5%n", &idx, &used) != 1 || used == 0 ||
            e->d_name[used] != '\0')
            continue;
        if (s->n == cap) {
            cap = cap ? 2 * cap : 64;
            int *grown = realloc(s->index, cap * sizeof *grown);
            if (!grown) {
                closedir(d);
                return -1;
            }
            s->index = grown;
        }
        s->index[s->n++] = idx;
    }
    closedir(d);
    qsort(s->index, s->n, sizeof *s->index, by_value);
    return 0;
}

void tc_snapshots_free(tc_snapshots *s)
{
    free(s->index);
    s->index = NULL;
    s->n = 0;
}

void tc_snapshot_path(const char *case_dir, int index, char *path, size_t len)
{
    snprintf(path, len, "%s/output/snapshot_%06d.h5", case_dir, index);
}

int tc_snapshot_load(const char *case_dir, int index, mf_sim *sim, mf_hdf5_header *h)
{
    char path[800];
    tc_snapshot_path(case_dir, index, path, sizeof path);
    memset(sim, 0, sizeof *sim);
    mf_hdf5_header local;
    int rc = mf_hdf5_read_header(path, h ? h : &local);
    if (rc == 0)
        rc = mf_hdf5_read_snapshot(path, sim);
    if (rc != 0) {
        fprintf(stderr, "case_util: cannot read %s:\n", path);
        mf_error_print(stderr);
    }
    return rc;
}

void tc_sim_free(mf_sim *sim)
{
    mf_particles_destroy(sim->p);
    sim->p = NULL;
}

const double *tc_field_d(const mf_particles *p, const char *name)
{
    int k = mf_particles_field_index(p, name);
    if (k < 0 || p->field[k].type != MF_FIELD_DOUBLE) {
        fprintf(stderr, "case_util: no double field '%s' in the snapshot\n", name);
        return NULL;
    }
    return mf_particles_fd(p, k);
}

const int32_t *tc_field_i(const mf_particles *p, const char *name)
{
    int k = mf_particles_field_index(p, name);
    if (k < 0 || p->field[k].type != MF_FIELD_INT32) {
        fprintf(stderr, "case_util: no int32 field '%s' in the snapshot\n", name);
        return NULL;
    }
    return mf_particles_fi(p, k);
}

size_t tc_count_kind(const mf_particles *p, int kind)
{
    size_t n = 0;
    for (size_t i = 0; i < p->n; i++)
        n += p->kind[i] == kind;
    return n;
}

int tc_resolved_number(const char *case_dir, const char *key_path, double *out)
{
    char path[700], keys[256];
    snprintf(path, sizeof path, "%s/output/resolvedParameters", case_dir);
    snprintf(keys, sizeof keys, "%s", key_path);
    mf_dict *root = NULL;
    int rc = mf_dict_parse_file(path, &root);
    const mf_dict *d = root;
    char *save = NULL, *key = strtok_r(keys, "/", &save);
    while (rc == 0 && key) {
        char *next = strtok_r(NULL, "/", &save);
        if (!next) {
            rc = mf_dict_get_number(d, key, out);
        } else if (!(d = mf_dict_subdict(d, key))) {
            rc = MF_ERROR(MF_ERR_INPUT, "%s: no sub-dictionary '%s' on the way to %s", path, key,
                          key_path);
        }
        key = next;
    }
    if (rc != 0) {
        fprintf(stderr, "case_util: cannot read %s from %s:\n", key_path, path);
        mf_error_print(stderr);
    }
    mf_dict_free(root);
    return rc;
}

char *tc_read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s)
        s[n] = '\0';
    fclose(f);
    return s;
}

char *tc_with_forces(const char *text, const char *forces)
{
    const char *at = text ? strstr(text, "\nforces") : NULL;
    if (!at)
        return NULL;
    const size_t head = (size_t)(at - text) + 1;
    char *out = malloc(head + strlen(forces) + 1);
    if (out) {
        memcpy(out, text, head);
        strcpy(out + head, forces);
    }
    return out;
}
