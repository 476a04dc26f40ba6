/* fuzz_util.c: see fuzz_util.h. */
#include "fuzz_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static bool value_equal(const mf_value *a, const mf_value *b)
{
    if (a->kind != b->kind)
        return false;
    switch (a->kind) {
    case MF_VAL_WORD:
    case MF_VAL_STRING: return strcmp(a->text ? a->text : "", b->text ? b->text : "") == 0;
    case MF_VAL_NUMBER:
        return memcmp(&a->number, &b->number, sizeof a->number) == 0 &&
               a->is_integer == b->is_integer;
    case MF_VAL_LIST:
        if (a->n != b->n)
            return false;
        for (size_t k = 0; k < a->n; k++)
            if (!value_equal(a->items[k], b->items[k]))
                return false;
        return true;
    case MF_VAL_DICT:
        if (strcmp(a->dict->name, b->dict->name) != 0)
            return false;
        return fuzz_dict_equal(a->dict, b->dict);
    }
    return false;
}

bool fuzz_dict_equal(const mf_dict *a, const mf_dict *b)
{
    if (a->n != b->n)
        return false;
    for (size_t k = 0; k < a->n; k++) {
        const mf_entry *x = a->entries[k], *y = b->entries[k];
        if (strcmp(x->key, y->key) != 0 || x->n != y->n)
            return false;
        for (size_t i = 0; i < x->n; i++)
            if (!value_equal(x->items[i], y->items[i]))
                return false;
    }
    return true;
}

static char tmp_dir[512];

static void remove_tmp(void)
{
    if (tmp_dir[0]) {
        char cmd[600];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp_dir);
        if (system(cmd) != 0)
            fprintf(stderr, "fuzz: could not remove %s\n", tmp_dir);
    }
}

const char *fuzz_tmp_dir(void)
{
    if (!tmp_dir[0]) {
        const char *t = getenv("TMPDIR");
        snprintf(tmp_dir, sizeof tmp_dir, "%s/mpsflow-fuzz-XXXXXX", t && *t ? t : "/tmp");
        if (!mkdtemp(tmp_dir)) {
            perror("fuzz: mkdtemp");
            abort();
        }
        atexit(remove_tmp);
    }
    return tmp_dir;
}

bool fuzz_write_file(const char *dir, const char *rel, const void *data, size_t size)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    for (char *s = path + 1; (s = strchr(s, '/')) != NULL; s++) {
        *s = '\0';
        mkdir(path, 0700);
        *s = '/';
    }
    FILE *f = fopen(path, "wb");
    if (!f)
        return false;
    bool ok = fwrite(data, 1, size, f) == size;
    return fclose(f) == 0 && ok;
}
