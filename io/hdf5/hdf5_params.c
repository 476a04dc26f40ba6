/* hdf5_params.c: the resolved case dictionary as an HDF5 group tree
 * (/Parameters), so a snapshot says which settings produced it.
 * Sub-dictionaries become sub-groups; every other entry a string attribute
 * holding its value text: numbers in the fewest digits (15 to 17) that read
 * back exactly,
 * lists as "(a b c)", several items separated by spaces. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hdf5_internal.h"
#include "mf_error.h"

static void format_value(FILE *f, const mf_value *v);

static void format_dict(FILE *f, const mf_dict *d)
{
    fputs("{", f);
    for (size_t e = 0; e < d->n; e++) {
        const mf_entry *entry = d->entries[e];
        fprintf(f, " %s", entry->key);
        for (size_t k = 0; k < entry->n; k++) {
            fputc(' ', f);
            format_value(f, entry->items[k]);
        }
        fputc(';', f);
    }
    fputs(" }", f);
}

static void format_value(FILE *f, const mf_value *v)
{
    switch (v->kind) {
    case MF_VAL_NUMBER: {
        char number[32];
        fputs(mf_h5_format_double(v->number, number, sizeof number), f);
        break;
    }
    case MF_VAL_WORD:
    case MF_VAL_STRING:
        fputs(v->text ? v->text : "", f);
        break;
    case MF_VAL_LIST:
        fputc('(', f);
        for (size_t k = 0; k < v->n; k++) {
            if (k > 0)
                fputc(' ', f);
            format_value(f, v->items[k]);
        }
        fputc(')', f);
        break;
    case MF_VAL_DICT:
        if (v->dict)
            format_dict(f, v->dict);
        else
            fputs("{ }", f);
        break;
    }
}

/* A key as an HDF5 name: '/' would be read as a path and "." is the group
 * itself, so replace them. */
static void h5_name(const char *key, char *buf, size_t len)
{
    snprintf(buf, len, "%s", key && key[0] ? key : "_");
    for (char *c = buf; *c; c++)
        if (*c == '/')
            *c = '_';
    if (strcmp(buf, ".") == 0)
        snprintf(buf, len, "_");
}

static int write_entry_attribute(hid_t group, const char *name, const mf_entry *entry,
                                 const char *what)
{
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    if (!f)
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory formatting %s", what, entry->key);
    for (size_t k = 0; k < entry->n; k++) {
        if (k > 0)
            fputc(' ', f);
        format_value(f, entry->items[k]);
    }
    int failed = ferror(f);
    fclose(f);
    int rc = failed ? MF_ERROR(MF_ERR_MEMORY, "%s: out of memory formatting %s", what, entry->key)
                    : mf_h5_attr_write_string(group, name, text, what);
    free(text);
    return rc;
}

int mf_h5_write_dict(hid_t group, const mf_dict *d, const char *what)
{
    char detail[256], name[256], sub_what[MF_H5_PATH_MAX];
    for (size_t e = 0; e < d->n; e++) {
        const mf_entry *entry = d->entries[e];
        h5_name(entry->key, name, sizeof name);
        if (entry->n == 1 && entry->items[0]->kind == MF_VAL_DICT && entry->items[0]->dict) {
            /* Keys are unique in a dictionary, so the sub-group is new. */
            hid_t sub = H5Gcreate2(group, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
            if (sub < 0)
                return MF_ERROR(MF_ERR_IO, "%s: cannot create group %s (%s)", what, name,
                                mf_h5_error_detail(detail, sizeof detail));
            snprintf(sub_what, sizeof sub_what, "%s/%s", what, name);
            int rc = mf_h5_write_dict(sub, entry->items[0]->dict, sub_what);
            H5Gclose(sub);
            MF_CALL(rc);
        } else {
            MF_CALL(write_entry_attribute(group, name, entry, what));
        }
    }
    return 0;
}
