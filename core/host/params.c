/* params.c: apply a module's parameter table to a dictionary. */
#include "mf_params.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"

const char *mf_param_type_name(mf_param_type t)
{
    switch (t) {
    case MF_PARAM_SCALAR: return "scalar";
    case MF_PARAM_INT: return "label";
    case MF_PARAM_BOOL: return "bool";
    case MF_PARAM_WORD: return "word";
    case MF_PARAM_VECTOR: return "vector";
    case MF_PARAM_DICT: return "dictionary";
    }
    return "?";
}

static bool has_range(const mf_param *p) { return p->min <= p->max; }

static bool parse_bool_word(const char *s, bool *out)
{
    static const char *const yes[] = {"true", "yes", "on"};
    static const char *const no[] = {"false", "no", "off"};
    for (int k = 0; k < 3; k++) {
        if (strcmp(s, yes[k]) == 0) { *out = true; return true; }
        if (strcmp(s, no[k]) == 0) { *out = false; return true; }
    }
    return false;
}

/* Defaults are written by us in C; a bad one is a bug, reported as internal. */
static int default_value(const mf_param *p, char *base)
{
    void *field = base + p->offset;
    char *end = NULL;
    switch (p->type) {
    case MF_PARAM_SCALAR:
        *(double *)field = strtod(p->def, &end);
        break;
    case MF_PARAM_INT:
        *(long *)field = strtol(p->def, &end, 10);
        break;
    case MF_PARAM_BOOL:
        if (!parse_bool_word(p->def, (bool *)field))
            return MF_ERROR(MF_ERR_INTERNAL, "parameter '%s': bad default '%s'", p->name, p->def);
        return 0;
    case MF_PARAM_WORD:
        *(const char **)field = p->def;
        return 0;
    case MF_PARAM_VECTOR: {
        double *v = (double *)field;
        const char *s = p->def;
        while (*s == ' ' || *s == '(') s++;
        for (int k = 0; k < 3; k++) {
            v[k] = strtod(s, &end);
            if (end == s)
                return MF_ERROR(MF_ERR_INTERNAL, "parameter '%s': bad default '%s'", p->name, p->def);
            s = end;
        }
        return 0;
    }
    case MF_PARAM_DICT:
        *(const mf_dict **)field = NULL;
        return 0;
    }
    if (end == NULL || *end != '\0')
        return MF_ERROR(MF_ERR_INTERNAL, "parameter '%s': bad default '%s'", p->name, p->def);
    return 0;
}

static int check_range(const mf_param *p, const mf_entry *e, double x)
{
    char where[512];
    if (!isfinite(x))
        return MF_ERROR(MF_ERR_INPUT, "%s: key '%s': value must be finite",
                        mf_loc_str(e->loc, where, sizeof where), p->name);
    if (has_range(p) && (x < p->min || x > p->max))
        return MF_ERROR(MF_ERR_INPUT, "%s: key '%s': %g is out of range [%g, %g] (%s)",
                        mf_loc_str(e->loc, where, sizeof where), p->name, x, p->min, p->max,
                        p->doc);
    return 0;
}

static int check_choice(const mf_param *p, const mf_entry *e, const char *word)
{
    if (!p->choices)
        return 0;
    size_t n = 0;
    for (; p->choices[n]; n++)
        if (strcmp(p->choices[n], word) == 0)
            return 0;
    char where[512], list[1024] = "";
    for (size_t k = 0; k < n; k++) {
        strncat(list, k ? ", " : "", sizeof list - strlen(list) - 1);
        strncat(list, p->choices[k], sizeof list - strlen(list) - 1);
    }
    const char *hint = mf_did_you_mean(word, p->choices, n);
    return MF_ERROR(MF_ERR_INPUT, "%s: key '%s': unknown choice '%s'%s%s%s; valid: %s",
                    mf_loc_str(e->loc, where, sizeof where), p->name, word,
                    hint ? " (did you mean '" : "", hint ? hint : "", hint ? "'?)" : "", list);
}

static int given_value(const mf_param *p, const mf_dict *dict, char *base)
{
    void *field = base + p->offset;
    switch (p->type) {
    case MF_PARAM_SCALAR:
        MF_CALL(mf_dict_get_number(dict, p->name, (double *)field));
        return check_range(p, mf_dict_find(dict, p->name), *(double *)field);
    case MF_PARAM_INT:
        MF_CALL(mf_dict_get_int(dict, p->name, (long *)field));
        return check_range(p, mf_dict_find(dict, p->name), (double)*(long *)field);
    case MF_PARAM_BOOL:
        return mf_dict_get_bool(dict, p->name, (bool *)field);
    case MF_PARAM_WORD:
        MF_CALL(mf_dict_get_word(dict, p->name, (const char **)field));
        return check_choice(p, mf_dict_find(dict, p->name), *(const char **)field);
    case MF_PARAM_VECTOR: {
        double *v = (double *)field;
        MF_CALL(mf_dict_get_vector(dict, p->name, v));
        for (int k = 0; k < 3; k++)
            MF_CALL(check_range(p, mf_dict_find(dict, p->name), v[k]));
        return 0;
    }
    case MF_PARAM_DICT: {
        const mf_dict *sub = mf_dict_subdict(dict, p->name);
        if (!sub) {
            char where[512];
            return MF_ERROR(MF_ERR_INPUT, "%s: key '%s' must be a sub-dictionary { ... }",
                            mf_loc_str(mf_dict_find(dict, p->name)->loc, where, sizeof where),
                            p->name);
        }
        mf_dict_find(dict, p->name)->used = true;
        *(const mf_dict **)field = sub;
        return 0;
    }
    }
    return MF_ERROR(MF_ERR_INTERNAL, "parameter '%s': unknown type", p->name);
}

static int write_resolved(const mf_param *p, const char *base, mf_dict *resolved)
{
    const void *field = base + p->offset;
    switch (p->type) {
    case MF_PARAM_SCALAR: return mf_dict_set_number(resolved, p->name, *(const double *)field);
    case MF_PARAM_INT: return mf_dict_set_number(resolved, p->name, (double)*(const long *)field);
    case MF_PARAM_BOOL:
        return mf_dict_set_word(resolved, p->name, *(const bool *)field ? "true" : "false");
    case MF_PARAM_WORD: return mf_dict_set_word(resolved, p->name, *(const char *const *)field);
    case MF_PARAM_VECTOR: return mf_dict_set_vector(resolved, p->name, (const double *)field);
    case MF_PARAM_DICT: {
        const mf_dict *src = *(const mf_dict *const *)field;
        mf_dict *dst = mf_dict_set_subdict(resolved, p->name);
        if (!dst)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory writing parameter '%s'", p->name);
        for (size_t k = 0; src && k < src->n; k++) {
            const mf_entry *e = src->entries[k];
            mf_value **items = calloc(e->n ? e->n : 1, sizeof *items);
            if (!items)
                return MF_ERROR(MF_ERR_MEMORY, "out of memory writing parameter '%s'", p->name);
            for (size_t i = 0; i < e->n; i++)
                items[i] = mf_value_copy(e->items[i], dst);
            if (!mf_dict_set(dst, e->key, e->loc, e->n, items))
                return MF_ERROR(MF_ERR_MEMORY, "out of memory writing parameter '%s'", p->name);
        }
        return 0;
    }
    }
    return 0;
}

static int check_unknown_keys(const mf_param *table, size_t n, const mf_dict *dict,
                              const char *const *extra)
{
    for (size_t k = 0; k < dict->n; k++) {
        const char *key = dict->entries[k]->key;
        bool known = false;
        for (size_t i = 0; i < n && !known; i++)
            known = strcmp(table[i].name, key) == 0;
        for (size_t i = 0; extra && extra[i] && !known; i++)
            known = strcmp(extra[i], key) == 0;
        if (known)
            continue;
        /* Suggest from the declared names and the extra keys together. */
        size_t nextra = 0;
        while (extra && extra[nextra]) nextra++;
        const char **names = malloc((n + nextra + 1) * sizeof *names);
        if (!names)
            return MF_ERROR(MF_ERR_MEMORY, "out of memory");
        for (size_t i = 0; i < n; i++) names[i] = table[i].name;
        for (size_t i = 0; i < nextra; i++) names[n + i] = extra[i];
        const char *hint = mf_did_you_mean(key, names, n + nextra);
        char list[1024] = "", where[512];
        for (size_t i = 0; i < n + nextra; i++) {
            strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
            strncat(list, names[i], sizeof list - strlen(list) - 1);
        }
        int rc = MF_ERROR(MF_ERR_INPUT, "%s: unknown key '%s' in '%s'%s%s%s; valid keys: %s",
                          mf_loc_str(dict->entries[k]->loc, where, sizeof where), key,
                          dict->name && dict->name[0] ? dict->name : "(top level)",
                          hint ? " (did you mean '" : "", hint ? hint : "",
                          hint ? "'?)" : "", n + nextra ? list : "(none)");
        free(names);
        return rc;
    }
    return 0;
}

int mf_params_apply(const mf_param *table, size_t n, const mf_dict *dict,
                    const char *const *extra_keys, void *settings, mf_dict *resolved)
{
    char *base = settings;
    if (dict)
        MF_CALL(check_unknown_keys(table, n, dict, extra_keys));
    for (size_t i = 0; i < n; i++) {
        const mf_param *p = &table[i];
        bool given = dict && mf_dict_find(dict, p->name);
        if (given) {
            MF_CALL(given_value(p, dict, base));
        } else if (p->def || p->type == MF_PARAM_DICT) {
            MF_CALL(default_value(p, base));
        } else {
            char where[512];
            return MF_ERROR(MF_ERR_INPUT, "%s: missing required key '%s' in '%s' (%s: %s)",
                            dict ? mf_loc_str(dict->loc, where, sizeof where) : "(no dictionary)",
                            p->name, dict && dict->name[0] ? dict->name : "(top level)",
                            mf_param_type_name(p->type), p->doc);
        }
        if (resolved && !(p->type == MF_PARAM_DICT && !*(const mf_dict **)(base + p->offset)))
            MF_CALL(write_resolved(p, base, resolved));
    }
    return 0;
}

int mf_params_defaults(const mf_param *table, size_t n, void *settings)
{
    for (size_t i = 0; i < n; i++) {
        if (!table[i].def && table[i].type != MF_PARAM_DICT)
            continue; /* required: no default */
        MF_CALL(default_value(&table[i], settings));
    }
    return 0;
}

void mf_params_print(const mf_param *table, size_t n, FILE *f)
{
    if (n == 0) {
        fprintf(f, "    (no parameters)\n");
        return;
    }
    fprintf(f, "    %-22s %-10s %-14s %-22s %s\n", "name", "type", "default", "range", "doc");
    for (size_t i = 0; i < n; i++) {
        const mf_param *p = &table[i];
        char range[64] = "-";
        if (has_range(p))
            snprintf(range, sizeof range, "[%g, %g]", p->min, p->max);
        else if (p->choices) {
            range[0] = '\0';
            for (size_t k = 0; p->choices[k]; k++) {
                strncat(range, k ? "|" : "", sizeof range - strlen(range) - 1);
                strncat(range, p->choices[k], sizeof range - strlen(range) - 1);
            }
        }
        fprintf(f, "    %-22s %-10s %-14s %-22s %s\n", p->name, mf_param_type_name(p->type),
                p->def ? p->def : (p->type == MF_PARAM_DICT ? "{}" : "(required)"), range, p->doc);
    }
}

/* A table cell: '|' would end the cell. */
static void put_cell(FILE *f, const char *s)
{
    for (; s && *s; s++) {
        if (*s == '|')
            fputs("\\|", f);
        else
            fputc(*s, f);
    }
}

void mf_params_print_markdown(const mf_param *table, size_t n, FILE *f)
{
    if (n == 0) {
        fprintf(f, "(no parameters)\n");
        return;
    }
    fprintf(f, "| key | type | default | range | meaning |\n|---|---|---|---|---|\n");
    for (size_t i = 0; i < n; i++) {
        const mf_param *p = &table[i];
        char range[256] = "";
        if (has_range(p))
            snprintf(range, sizeof range, "[%g, %g]", p->min, p->max);
        else if (p->choices)
            for (size_t k = 0; p->choices[k]; k++) {
                strncat(range, k ? " \\| " : "", sizeof range - strlen(range) - 1);
                strncat(range, p->choices[k], sizeof range - strlen(range) - 1);
            }
        fprintf(f, "| `%s` | %s | ", p->name, mf_param_type_name(p->type));
        put_cell(f, p->def ? p->def : (p->type == MF_PARAM_DICT ? "{}" : "(required)"));
        fprintf(f, " | %s | ", range[0] ? range : "-");
        put_cell(f, p->doc);
        fprintf(f, " |\n");
    }
}
