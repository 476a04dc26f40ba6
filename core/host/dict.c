/* dict.c: the dictionary tree behind mf_dict.h: building and freeing, the
 * string pool for file names, typed accessors with located error messages,
 * writing back in OpenFOAM syntax, and "did you mean" suggestions.
 *
 * The text parser is in io/dict/dict_parse.c; nothing here reads files.
 */
#include "mf_dict.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "mf_alloc.h"
#include "mf_error.h"

/* ------------------------------------------------------------------------
 * String pool
 *
 * Every mf_loc names its file by a pointer into the tree's pool, so that a
 * tree of a million values holds each file name once. The pool is shared by
 * all dictionaries of a tree and reference-counted, so freeing a sub-tree
 * (a replaced entry, say) never frees names that the rest still uses.
 * ---------------------------------------------------------------------- */
struct mf_strpool {
    int refs;
    size_t n, cap;
    char **strings;
};

static struct mf_strpool *pool_new(void)
{
    struct mf_strpool *p = calloc(1, sizeof *p);
    if (p)
        p->refs = 1;
    return p;
}

static void pool_release(struct mf_strpool *p)
{
    if (!p || --p->refs > 0)
        return;
    for (size_t k = 0; k < p->n; k++)
        free(p->strings[k]);
    free(p->strings);
    free(p);
}

/* A tree holds few file names (one per #include'd file): a linear search is
 * the simplest thing that is fast enough. */
static const char *pool_intern(struct mf_strpool *p, const char *s)
{
    if (!p || !s)
        return NULL;
    for (size_t k = 0; k < p->n; k++)
        if (strcmp(p->strings[k], s) == 0)
            return p->strings[k];
    if (p->n == p->cap) {
        size_t cap = p->cap ? 2 * p->cap : 8;
        if (mf_resize(&p->strings, cap, sizeof *p->strings))
            return NULL;
        p->cap = cap;
    }
    char *copy = strdup(s);
    if (!copy)
        return NULL;
    p->strings[p->n++] = copy;
    return copy;
}

const char *mf_dict_intern(mf_dict *d, const char *s)
{
    return d ? pool_intern(d->pool, s) : NULL;
}

/* ------------------------------------------------------------------------
 * Build and free
 * ---------------------------------------------------------------------- */
mf_dict *mf_dict_new(const char *name, mf_dict *parent)
{
    mf_dict *d = calloc(1, sizeof *d);
    if (!d)
        return NULL;
    d->name = strdup(name ? name : "");
    if (parent) {
        d->pool = parent->pool;
        if (d->pool)
            d->pool->refs++;
    } else {
        d->pool = pool_new();
    }
    if (!d->name || !d->pool) {
        free(d->name);
        pool_release(d->pool);
        free(d);
        return NULL;
    }
    d->parent = parent;
    return d;
}

static void free_items(size_t n, mf_value **items)
{
    for (size_t k = 0; k < n; k++)
        mf_value_free(items[k]);
    free(items);
}

static void entry_free(mf_entry *e)
{
    if (!e)
        return;
    free(e->key);
    free_items(e->n, e->items);
    free(e);
}

void mf_dict_free(mf_dict *d)
{
    if (!d)
        return;
    for (size_t k = 0; k < d->n; k++)
        entry_free(d->entries[k]);
    free(d->entries);
    free(d->name);
    pool_release(d->pool);
    free(d);
}

mf_value *mf_value_new(mf_value_kind kind, mf_loc loc)
{
    mf_value *v = calloc(1, sizeof *v);
    if (v) {
        v->kind = kind;
        v->loc = loc;
    }
    return v;
}

void mf_value_free(mf_value *v)
{
    if (!v)
        return;
    free(v->text);
    free_items(v->n, v->items);
    mf_dict_free(v->dict);
    free(v);
}

void mf_entry_replace(mf_entry *e, mf_loc loc, size_t n, mf_value **items)
{
    free_items(e->n, e->items);
    e->loc = loc;
    e->n = n;
    e->items = items;
    e->used = false;
}

mf_entry *mf_dict_append(mf_dict *d, const char *key, mf_loc loc, size_t n, mf_value **items)
{
    if (!d || !key)
        goto fail;
    if (d->n == d->cap) {
        size_t cap = d->cap ? 2 * d->cap : 8;
        if (mf_resize(&d->entries, cap, sizeof *d->entries))
            goto fail;
        d->cap = cap;
    }
    mf_entry *e = calloc(1, sizeof *e);
    if (!e)
        goto fail;
    e->key = strdup(key);
    if (!e->key) {
        free(e);
        goto fail;
    }
    e->loc = loc;
    e->n = n;
    e->items = items;
    d->entries[d->n++] = e;
    return e;
fail:
    free_items(n, items);
    return NULL;
}

/* OpenFOAM's rule: a repeated key replaces the earlier entry (in place, so
 * the order of first appearance is kept when the tree is written back). */
mf_entry *mf_dict_set(mf_dict *d, const char *key, mf_loc loc, size_t n, mf_value **items)
{
    mf_entry *e = d && key ? mf_dict_find(d, key) : NULL;
    if (e) {
        mf_entry_replace(e, loc, n, items);
        return e;
    }
    return mf_dict_append(d, key, loc, n, items);
}

static mf_dict *dict_copy(const mf_dict *src, mf_dict *parent);

/* Deep copy. File names are re-interned into the destination tree's pool,
 * so the copy stays valid after the source tree is freed. */
mf_value *mf_value_copy(const mf_value *v, mf_dict *parent)
{
    if (!v)
        return NULL;
    mf_value *c = mf_value_new(v->kind, v->loc);
    if (!c)
        return NULL;
    c->number = v->number;
    c->is_integer = v->is_integer;
    if (v->text && !(c->text = strdup(v->text)))
        goto fail;
    if (v->n) {
        c->items = calloc(v->n, sizeof *c->items);
        if (!c->items)
            goto fail;
        for (size_t k = 0; k < v->n; k++) {
            c->items[k] = mf_value_copy(v->items[k], parent);
            c->n = k + 1; /* so that a failure frees what was copied */
            if (!c->items[k])
                goto fail;
        }
    }
    if (v->dict && !(c->dict = dict_copy(v->dict, parent)))
        goto fail;
    /* The value's own file name goes into the destination pool: the
     * parent's, or a copied dictionary's own. Only a non-dictionary value
     * copied with no parent keeps pointing at the source tree's name. */
    mf_dict *pool_owner = parent ? parent : c->dict;
    if (pool_owner && c->loc.file && !(c->loc.file = mf_dict_intern(pool_owner, c->loc.file)))
        goto fail;
    return c;
fail:
    mf_value_free(c);
    return NULL;
}

static mf_dict *dict_copy(const mf_dict *src, mf_dict *parent)
{
    mf_dict *d = mf_dict_new(src->name, parent);
    if (!d)
        return NULL;
    d->loc = src->loc;
    if (d->loc.file && !(d->loc.file = mf_dict_intern(d, src->loc.file)))
        goto fail;
    for (size_t k = 0; k < src->n; k++) {
        const mf_entry *e = src->entries[k];
        mf_loc loc = e->loc;
        if (loc.file && !(loc.file = mf_dict_intern(d, loc.file)))
            goto fail;
        mf_value **items = e->n ? calloc(e->n, sizeof *items) : NULL;
        if (e->n && !items)
            goto fail;
        for (size_t i = 0; i < e->n; i++) {
            items[i] = mf_value_copy(e->items[i], d);
            if (!items[i]) {
                free_items(i, items);
                goto fail;
            }
        }
        mf_entry *c = mf_dict_append(d, e->key, loc, e->n, items);
        if (!c)
            goto fail;
        c->used = e->used;
    }
    return d;
fail:
    mf_dict_free(d);
    return NULL;
}

/* Values made by the program (resolved parameters) have no source file. */
static const mf_loc generated_loc = { NULL, 0, 0 };

static mf_value *number_value(double x)
{
    mf_value *v = mf_value_new(MF_VAL_NUMBER, generated_loc);
    if (!v)
        return NULL;
    char text[64];
    v->number = x;
    /* Integral values (an MF_PARAM_INT, a count) are written as integers. */
    v->is_integer = isfinite(x) && x == floor(x) && fabs(x) < 9007199254740992.0;
    if (v->is_integer)
        snprintf(text, sizeof text, "%.0f", x);
    else
        snprintf(text, sizeof text, "%.17g", x);
    v->text = strdup(text);
    if (!v->text) {
        mf_value_free(v);
        return NULL;
    }
    return v;
}

/* Set key to the given items (count n, each possibly NULL on a failed
 * allocation: then everything is freed and an error raised). */
static int set_items(mf_dict *d, const char *key, size_t n, mf_value **items)
{
    bool ok = items != NULL;
    for (size_t k = 0; ok && k < n; k++)
        ok = items[k] != NULL;
    if (!ok) {
        if (items)
            free_items(n, items);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory setting key '%s'", key);
    }
    if (!mf_dict_set(d, key, generated_loc, n, items))
        return MF_ERROR(MF_ERR_MEMORY, "out of memory setting key '%s'", key);
    return 0;
}

int mf_dict_set_number(mf_dict *d, const char *key, double x)
{
    mf_value **items = calloc(1, sizeof *items);
    if (items)
        items[0] = number_value(x);
    return set_items(d, key, 1, items);
}

int mf_dict_set_word(mf_dict *d, const char *key, const char *word)
{
    mf_value **items = calloc(1, sizeof *items);
    if (items) {
        items[0] = mf_value_new(MF_VAL_WORD, generated_loc);
        if (items[0] && !(items[0]->text = strdup(word ? word : ""))) {
            mf_value_free(items[0]);
            items[0] = NULL;
        }
    }
    return set_items(d, key, 1, items);
}

int mf_dict_set_vector(mf_dict *d, const char *key, const double v[3])
{
    mf_value **items = calloc(1, sizeof *items);
    mf_value *list = items ? mf_value_new(MF_VAL_LIST, generated_loc) : NULL;
    if (list) {
        list->items = calloc(3, sizeof *list->items);
        for (size_t k = 0; list->items && k < 3; k++) {
            list->items[k] = number_value(v[k]);
            list->n = k + 1;
            if (!list->items[k]) {
                mf_value_free(list);
                list = NULL;
                break;
            }
        }
        if (list && !list->items) {
            mf_value_free(list);
            list = NULL;
        }
    }
    if (items)
        items[0] = list;
    return set_items(d, key, 1, items);
}

/* Get-or-create: writing a module's resolved sub-dictionary twice must not
 * throw away what the first call put there. */
mf_dict *mf_dict_set_subdict(mf_dict *d, const char *key)
{
    if (!d || !key)
        return NULL;
    mf_dict *sub = mf_dict_subdict(d, key);
    if (sub)
        return sub;
    mf_value **items = calloc(1, sizeof *items);
    if (!items)
        return NULL;
    items[0] = mf_value_new(MF_VAL_DICT, generated_loc);
    if (!items[0] || !(items[0]->dict = mf_dict_new(key, d))) {
        free_items(1, items);
        return NULL;
    }
    sub = items[0]->dict;
    return mf_dict_set(d, key, generated_loc, 1, items) ? sub : NULL;
}

/* ------------------------------------------------------------------------
 * Look up
 * ---------------------------------------------------------------------- */
mf_entry *mf_dict_find(const mf_dict *d, const char *key)
{
    if (!d || !key)
        return NULL;
    for (size_t k = 0; k < d->n; k++)
        if (strcmp(d->entries[k]->key, key) == 0)
            return d->entries[k];
    return NULL;
}

mf_dict *mf_dict_subdict(const mf_dict *d, const char *key)
{
    const mf_entry *e = mf_dict_find(d, key);
    if (!e || e->n != 1 || e->items[0]->kind != MF_VAL_DICT)
        return NULL;
    return e->items[0]->dict;
}

const char *mf_loc_str(mf_loc loc, char *buf, size_t len)
{
    if (!buf || len == 0)
        return "";
    if (!loc.file)
        snprintf(buf, len, "<generated>");
    else
        snprintf(buf, len, "%s:%d:%d", loc.file, loc.line, loc.col);
    return buf;
}

/* ------------------------------------------------------------------------
 * Typed access
 * ---------------------------------------------------------------------- */

/* "word 'abc'", "number 2.5", "a list of 2 items": what was found, for
 * messages. Long texts are cut so that a message stays one readable line. */
static const char *describe(const mf_value *v, char *buf, size_t len)
{
    const char *text = v->text ? v->text : "";
    int cut = strlen(text) > 40;
    switch (v->kind) {
    case MF_VAL_WORD:
        snprintf(buf, len, "word '%.40s%s'", text, cut ? "..." : "");
        break;
    case MF_VAL_STRING:
        snprintf(buf, len, "string \"%.40s%s\"", text, cut ? "..." : "");
        break;
    case MF_VAL_NUMBER:
        if (v->text)
            snprintf(buf, len, "number %.40s%s", text, cut ? "..." : "");
        else
            snprintf(buf, len, "number %.17g", v->number);
        break;
    case MF_VAL_LIST:
        snprintf(buf, len, "a list of %zu item%s", v->n, v->n == 1 ? "" : "s");
        break;
    case MF_VAL_DICT:
        snprintf(buf, len, "a dictionary");
        break;
    }
    return buf;
}

static int value_error(const mf_value *v, const char *what, const char *expected)
{
    char where[512], found[128];
    return MF_ERROR(MF_ERR_INPUT, "%s: %s: expected %s, found %s",
                    mf_loc_str(v->loc, where, sizeof where), what ? what : "value", expected,
                    describe(v, found, sizeof found));
}

int mf_value_number(const mf_value *v, const char *what, double *out)
{
    if (!v)
        return MF_ERROR(MF_ERR_INTERNAL, "%s: no value", what ? what : "value");
    if (v->kind != MF_VAL_NUMBER)
        return value_error(v, what, "a number");
    *out = v->number;
    return 0;
}

static bool word_is(const char *text, const char *const *words)
{
    for (; *words; words++)
        if (strcasecmp(text, *words) == 0)
            return true;
    return false;
}

int mf_value_bool(const mf_value *v, const char *what, bool *out)
{
    static const char *const yes[] = { "true", "yes", "on", NULL };
    static const char *const no[] = { "false", "no", "off", NULL };
    if (!v)
        return MF_ERROR(MF_ERR_INTERNAL, "%s: no value", what ? what : "value");
    if (v->kind == MF_VAL_WORD && v->text) {
        if (word_is(v->text, yes)) {
            *out = true;
            return 0;
        }
        if (word_is(v->text, no)) {
            *out = false;
            return 0;
        }
    }
    return value_error(v, what, "a boolean (true/false, yes/no, on/off)");
}

int mf_value_vector(const mf_value *v, const char *what, double out[3])
{
    if (!v)
        return MF_ERROR(MF_ERR_INTERNAL, "%s: no value", what ? what : "value");
    if (v->kind != MF_VAL_LIST || v->n != 3)
        return value_error(v, what, "a vector (a list of 3 numbers, like (0 -9.81 0))");
    double x[3];
    for (int k = 0; k < 3; k++) {
        const mf_value *c = v->items[k];
        if (c->kind != MF_VAL_NUMBER) {
            char component[300];
            snprintf(component, sizeof component, "%s, component %d", what ? what : "vector",
                     k + 1);
            return value_error(c, component, "a number");
        }
        x[k] = c->number;
    }
    memcpy(out, x, sizeof x);
    return 0;
}

/* Append the dictionary's scoped name ("solvers/p") at buf[pos], keeping
 * the NUL; returns the new length. */
static size_t path_append(const mf_dict *d, char *buf, size_t len, size_t pos)
{
    if (d->parent && d->parent->parent) {
        pos = path_append(d->parent, buf, len, pos);
        if (pos + 1 < len)
            buf[pos++] = '/';
    }
    for (const char *s = d->name; s && *s && pos + 1 < len; s++)
        buf[pos++] = *s;
    buf[pos] = '\0';
    return pos;
}

/* The dictionary's name for messages: "solvers/p", or "(top level)". */
static void dict_path(const mf_dict *d, char *buf, size_t len)
{
    if (!d->name || !d->name[0])
        snprintf(buf, len, "(top level)");
    else
        path_append(d, buf, len, 0);
}

static int missing_key(const mf_dict *d, const char *key)
{
    char where[512], path[256], hint[300] = "";
    const char **keys = d->n ? malloc(d->n * sizeof *keys) : NULL;
    if (keys) {
        for (size_t k = 0; k < d->n; k++)
            keys[k] = d->entries[k]->key;
        const char *best = mf_did_you_mean(key, keys, d->n);
        if (best)
            snprintf(hint, sizeof hint, " (did you mean '%s'?)", best);
        free(keys);
    }
    dict_path(d, path, sizeof path);
    return MF_ERROR(MF_ERR_INPUT, "%s: missing key '%s' in dictionary '%s'%s",
                    mf_loc_str(d->loc, where, sizeof where), key, path, hint);
}

/* The one item of entry `key`, marked used. *item is NULL (and 0 returned)
 * when the key is absent and absent_ok. */
static int single_item(const mf_dict *d, const char *key, const char *expected, bool absent_ok,
                       const mf_value **item)
{
    *item = NULL;
    if (!d)
        return absent_ok ? 0 : MF_ERROR(MF_ERR_INPUT, "missing key '%s' (no dictionary)", key);
    mf_entry *e = mf_dict_find(d, key);
    if (!e)
        return absent_ok ? 0 : missing_key(d, key);
    e->used = true; /* bookkeeping: what a run never read can be reported */
    if (e->n != 1) {
        char where[512], hint[128] = "";
        /* `endTime 10` with its ';' forgotten swallows the next line's entry:
         * the items then span lines, which says where the ';' is missing. */
        if (e->n > 1 && e->items[e->n - 1]->loc.line > e->loc.line)
            snprintf(hint, sizeof hint, " (is a ';' missing at the end of line %d?)",
                     e->loc.line);
        return MF_ERROR(MF_ERR_INPUT, "%s: key '%s': expected %s, found %zu items%s",
                        mf_loc_str(e->loc, where, sizeof where), key, expected, e->n, hint);
    }
    *item = e->items[0];
    return 0;
}

static void what_key(const char *key, char *buf, size_t len)
{
    snprintf(buf, len, "key '%s'", key);
}

int mf_dict_get_number(const mf_dict *d, const char *key, double *out)
{
    const mf_value *v;
    char what[300];
    MF_CALL(single_item(d, key, "a number", false, &v));
    what_key(key, what, sizeof what);
    return mf_value_number(v, what, out);
}

int mf_dict_get_number_or(const mf_dict *d, const char *key, double def, double *out)
{
    const mf_value *v;
    char what[300];
    MF_CALL(single_item(d, key, "a number", true, &v));
    if (!v) {
        *out = def;
        return 0;
    }
    what_key(key, what, sizeof what);
    return mf_value_number(v, what, out);
}

int mf_dict_get_int(const mf_dict *d, const char *key, long *out)
{
    const mf_value *v;
    char what[300], where[512];
    MF_CALL(single_item(d, key, "an integer", false, &v));
    what_key(key, what, sizeof what);
    if (v->kind != MF_VAL_NUMBER)
        return value_error(v, what, "an integer");
    const char *range = "is out of range for a long integer";
    if (v->is_integer && v->text) {
        /* Exact: the double may have lost digits of a long integer. */
        char *end;
        errno = 0;
        long x = strtol(v->text, &end, 10);
        if (errno == ERANGE)
            return MF_ERROR(MF_ERR_INPUT, "%s: %s: integer %s %s (%ld to %ld)",
                            mf_loc_str(v->loc, where, sizeof where), what, v->text, range,
                            LONG_MIN, LONG_MAX);
        if (*end == '\0' && end != v->text) {
            *out = x;
            return 0;
        }
    }
    /* Written as 1e6 or 100.0: fine if the value is a whole number. */
    double x = v->number;
    if (x != floor(x))
        return value_error(v, what, "an integer");
    if (!(x >= (double)LONG_MIN && x < -(double)LONG_MIN))
        return MF_ERROR(MF_ERR_INPUT, "%s: %s: integer %.17g %s (%ld to %ld)",
                        mf_loc_str(v->loc, where, sizeof where), what, x, range, LONG_MIN,
                        LONG_MAX);
    *out = (long)x;
    return 0;
}

int mf_dict_get_bool(const mf_dict *d, const char *key, bool *out)
{
    const mf_value *v;
    char what[300];
    MF_CALL(single_item(d, key, "a boolean", false, &v));
    what_key(key, what, sizeof what);
    return mf_value_bool(v, what, out);
}

int mf_dict_get_bool_or(const mf_dict *d, const char *key, bool def, bool *out)
{
    const mf_value *v;
    char what[300];
    MF_CALL(single_item(d, key, "a boolean", true, &v));
    if (!v) {
        *out = def;
        return 0;
    }
    what_key(key, what, sizeof what);
    return mf_value_bool(v, what, out);
}

/* A word, or a quoted string: there is no separate string accessor, and
 * `solver "PCG";` means the same as `solver PCG;`. */
static int word_of(const mf_value *v, const char *key, const char **out)
{
    char what[300];
    if (v->kind != MF_VAL_WORD && v->kind != MF_VAL_STRING) {
        what_key(key, what, sizeof what);
        return value_error(v, what, "a word");
    }
    *out = v->text;
    return 0;
}

int mf_dict_get_word(const mf_dict *d, const char *key, const char **out)
{
    const mf_value *v;
    MF_CALL(single_item(d, key, "a word", false, &v));
    return word_of(v, key, out);
}

int mf_dict_get_word_or(const mf_dict *d, const char *key, const char *def, const char **out)
{
    const mf_value *v;
    MF_CALL(single_item(d, key, "a word", true, &v));
    if (!v) {
        *out = def;
        return 0;
    }
    return word_of(v, key, out);
}

int mf_dict_get_vector(const mf_dict *d, const char *key, double out[3])
{
    const mf_value *v;
    char what[300];
    MF_CALL(single_item(d, key, "a vector", false, &v));
    what_key(key, what, sizeof what);
    return mf_value_vector(v, what, out);
}

int mf_dict_get_vector_or(const mf_dict *d, const char *key, const double def[3], double out[3])
{
    const mf_value *v;
    char what[300];
    MF_CALL(single_item(d, key, "a vector", true, &v));
    if (!v) {
        memmove(out, def, 3 * sizeof *out);
        return 0;
    }
    what_key(key, what, sizeof what);
    return mf_value_vector(v, what, out);
}

/* ------------------------------------------------------------------------
 * Writing
 *
 * The output must read back to the same tree: strings are quoted with \"
 * and \\ escaped, numbers keep exact values (%.17g) and their integer flag,
 * words that would not read back as the same word are quoted.
 * ---------------------------------------------------------------------- */
static void put_indent(FILE *f, int level)
{
    for (int k = 0; k < level; k++)
        fputs("    ", f);
}

static void put_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"' || *s == '\\')
            fputc('\\', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

/* The same rule as the parser's tokenizer: a word is a run of bytes that
 * are not space, control, or one of "(){}; and does not start a comment,
 * a directive, or read as a number. */
static bool word_byte(unsigned char c)
{
    return c > ' ' && c != 0x7f && !strchr("\"(){};", c);
}

static bool reads_as_number(const char *s)
{
    const char *p = s;
    bool digits = false;
    if (*p == '+' || *p == '-')
        p++;
    while (isdigit((unsigned char)*p)) {
        p++;
        digits = true;
    }
    if (*p == '.') {
        p++;
        while (isdigit((unsigned char)*p)) {
            p++;
            digits = true;
        }
    }
    if (!digits)
        return false;
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-')
            p++;
        if (!isdigit((unsigned char)*p))
            return false;
        while (isdigit((unsigned char)*p))
            p++;
    }
    return *p == '\0';
}

static bool writable_word(const char *s)
{
    if (!s || !*s || *s == '#')
        return false;
    for (const char *p = s; *p; p++)
        if (!word_byte((unsigned char)*p) || (p[0] == '/' && (p[1] == '/' || p[1] == '*')))
            return false;
    return !reads_as_number(s);
}

static bool is_integer_literal(const char *s)
{
    if (*s == '+' || *s == '-')
        s++;
    if (!*s)
        return false;
    for (; *s; s++)
        if (!isdigit((unsigned char)*s))
            return false;
    return true;
}

static void put_number(FILE *f, const mf_value *v)
{
    if (v->is_integer && v->text && is_integer_literal(v->text)) {
        fputs(v->text, f); /* exact, even beyond the 53 bits of a double */
        return;
    }
    char text[64];
    snprintf(text, sizeof text, "%.17g", v->number);
    /* 5.0 must not read back as the integer 5. inf and nan cannot be
     * written as numbers at all: they read back as words (no such number
     * comes from the parser). */
    if (!v->is_integer && !strpbrk(text, ".eEna"))
        strcat(text, ".0");
    fputs(text, f);
}

static int write_entries(const mf_dict *d, FILE *f, int level);

static bool list_has_dict(const mf_value *v)
{
    for (size_t k = 0; k < v->n; k++)
        if (v->items[k]->kind == MF_VAL_DICT)
            return true;
    return false;
}

static void put_dict_block(FILE *f, const mf_dict *d, int level, int *rc)
{
    fputs("{\n", f);
    int r = write_entries(d, f, level + 1);
    if (r && !*rc)
        *rc = r;
    put_indent(f, level);
    fputc('}', f);
}

/* One item. Lists holding dictionaries go one item per line at `level`+1;
 * other lists stay on one line. */
static void put_value(FILE *f, const mf_value *v, int level, int *rc)
{
    switch (v->kind) {
    case MF_VAL_WORD:
        if (writable_word(v->text))
            fputs(v->text, f);
        else
            put_string(f, v->text ? v->text : "");
        break;
    case MF_VAL_STRING:
        put_string(f, v->text ? v->text : "");
        break;
    case MF_VAL_NUMBER:
        put_number(f, v);
        break;
    case MF_VAL_LIST:
        if (list_has_dict(v)) {
            fputs("\n", f);
            put_indent(f, level);
            fputs("(\n", f);
            for (size_t k = 0; k < v->n; k++) {
                put_indent(f, level + 1);
                put_value(f, v->items[k], level + 1, rc);
                fputc('\n', f);
            }
            put_indent(f, level);
            fputc(')', f);
        } else {
            fputc('(', f);
            for (size_t k = 0; k < v->n; k++) {
                if (k)
                    fputc(' ', f);
                put_value(f, v->items[k], level, rc);
            }
            fputc(')', f);
        }
        break;
    case MF_VAL_DICT:
        /* Only inside a list: `name { ... }` (an entry's dict is written by
         * write_entries). */
        if (v->dict && v->dict->name && v->dict->name[0]) {
            fputs(v->dict->name, f);
            fputc('\n', f);
            put_indent(f, level);
        }
        if (v->dict)
            put_dict_block(f, v->dict, level, rc);
        else
            fputs("{\n}", f);
        break;
    }
}

static int write_entries(const mf_dict *d, FILE *f, int level)
{
    int rc = 0;
    for (size_t k = 0; k < d->n; k++) {
        const mf_entry *e = d->entries[k];
        put_indent(f, level);
        /* The parser drops a UTF-8 byte order mark at the very start of a
         * file; a key that begins with one (a stray mark inside the file)
         * must not be written there, or it would read back without it. */
        if (level == 0 && strncmp(e->key, "\xEF\xBB\xBF", 3) == 0)
            fputc(' ', f);
        fputs(e->key, f);
        if (e->n == 1 && e->items[0]->kind == MF_VAL_DICT && e->items[0]->dict) {
            fputc('\n', f);
            put_indent(f, level);
            put_dict_block(f, e->items[0]->dict, level, &rc);
            fputc('\n', f);
            continue;
        }
        if (e->n == 0 && !rc)
            rc = MF_ERROR(MF_ERR_INPUT, "cannot write key '%s': it has no value", e->key);
        for (size_t i = 0; i < e->n; i++) {
            if (e->items[i]->kind == MF_VAL_DICT && !rc)
                rc = MF_ERROR(MF_ERR_INPUT,
                              "cannot write key '%s': a dictionary must be its only item",
                              e->key);
            /* a list of dictionaries starts on its own line */
            if (!(e->items[i]->kind == MF_VAL_LIST && list_has_dict(e->items[i])))
                fputc(' ', f);
            put_value(f, e->items[i], level, &rc);
        }
        fputs(";\n", f);
    }
    return rc;
}

int mf_dict_write(const mf_dict *d, FILE *f, int indent)
{
    if (!d || !f)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_dict_write: no dictionary or no file");
    MF_CALL(write_entries(d, f, indent < 0 ? 0 : indent));
    if (ferror(f))
        return MF_ERROR(MF_ERR_IO, "writing dictionary '%s' failed (%s)", d->name,
                        strerror(errno));
    return 0;
}

/* ------------------------------------------------------------------------
 * Did you mean
 * ---------------------------------------------------------------------- */
#define MF_DYM_MAX 128 /* longer words get no suggestion (and no big tables) */

/* Damerau-Levenshtein (optimal string alignment: adjacent swaps cost one),
 * with case folded if fold, over three rolling rows. */
static int edit_distance(const char *a, size_t na, const char *b, size_t nb, bool fold)
{
    int rows[3][MF_DYM_MAX + 1];
    int *prev2 = rows[0], *prev = rows[1], *cur = rows[2];
    for (size_t j = 0; j <= nb; j++)
        prev[j] = (int)j;
    for (size_t i = 1; i <= na; i++) {
        cur[0] = (int)i;
        for (size_t j = 1; j <= nb; j++) {
            int ca = (unsigned char)a[i - 1], cb = (unsigned char)b[j - 1];
            if (fold) {
                ca = tolower(ca);
                cb = tolower(cb);
            }
            int best = prev[j - 1] + (ca != cb);
            if (prev[j] + 1 < best)
                best = prev[j] + 1;
            if (cur[j - 1] + 1 < best)
                best = cur[j - 1] + 1;
            if (i > 1 && j > 1) {
                int pa = (unsigned char)a[i - 2], pb = (unsigned char)b[j - 2];
                if (fold) {
                    pa = tolower(pa);
                    pb = tolower(pb);
                }
                if (ca == pb && pa == cb && prev2[j - 2] + 1 < best)
                    best = prev2[j - 2] + 1;
            }
            cur[j] = best;
        }
        int *t = prev2;
        prev2 = prev;
        prev = cur;
        cur = t;
    }
    return prev[nb];
}

const char *mf_did_you_mean(const char *word, const char *const *candidates, size_t n)
{
    if (!word || !candidates)
        return NULL;
    size_t nw = strlen(word);
    if (nw == 0 || nw > MF_DYM_MAX)
        return NULL;
    int limit = nw / 3 > 2 ? (int)(nw / 3) : 2;
    const char *best = NULL;
    int best_fold = INT_MAX, best_exact = INT_MAX;
    for (size_t k = 0; k < n; k++) {
        const char *c = candidates[k];
        size_t nc = c ? strlen(c) : 0;
        if (nc == 0 || nc > MF_DYM_MAX)
            continue;
        /* Case-folded distance decides (endtime -> endTime is distance 0);
         * the exact distance breaks ties. */
        int fold = edit_distance(word, nw, c, nc, true);
        /* "dt" vs "nu" is distance 2 but shares nothing: not a suggestion. */
        size_t longer = nw > nc ? nw : nc;
        if (fold > limit || (size_t)fold >= longer)
            continue;
        int exact = edit_distance(word, nw, c, nc, false);
        if (fold < best_fold || (fold == best_fold && exact < best_exact)) {
            best = c;
            best_fold = fold;
            best_exact = exact;
        }
    }
    return best;
}
