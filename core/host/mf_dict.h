/* mf_dict.h: the dictionary tree of a case (OpenFOAM syntax), with the
 * file, line and column of every key and value so that any error can name
 * them. The text parser lives in io/ (mf_dict_parse); this is the data and
 * its typed accessors.
 *
 * An entry is `key item item ... ;` or `key { ... }`. Most entries carry one
 * item. Items are words, strings, numbers, lists `( ... )` or dictionaries.
 * Booleans are the words true/false, yes/no, on/off. A vector is a list of
 * three numbers.
 */
#ifndef MF_DICT_H
#define MF_DICT_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

typedef struct mf_loc {
    const char *file; /* owned by the root dictionary's string pool */
    int line, col;    /* 1-based */
} mf_loc;

typedef enum {
    MF_VAL_WORD,
    MF_VAL_STRING,
    MF_VAL_NUMBER,
    MF_VAL_LIST,
    MF_VAL_DICT
} mf_value_kind;

typedef struct mf_dict mf_dict;

typedef struct mf_value {
    mf_value_kind kind;
    mf_loc loc;
    char *text;              /* word, string, or a number's source text */
    double number;           /* MF_VAL_NUMBER */
    bool is_integer;         /* MF_VAL_NUMBER written without '.', 'e' */
    size_t n;                /* MF_VAL_LIST: item count */
    struct mf_value **items; /* MF_VAL_LIST */
    mf_dict *dict;           /* MF_VAL_DICT */
} mf_value;

typedef struct mf_entry {
    char *key;
    mf_loc loc;
    size_t n;          /* number of items after the key */
    mf_value **items;
    bool used;         /* set by accessors: what a run did not read can be reported */
} mf_entry;

struct mf_dict {
    char *name;        /* "" for a file's root, else the key it sits under */
    mf_loc loc;
    size_t n, cap;
    mf_entry **entries;
    mf_dict *parent;
    struct mf_strpool *pool; /* file names; shared by a tree */
};

/* Build and free ------------------------------------------------------- */
mf_dict *mf_dict_new(const char *name, mf_dict *parent);
void mf_dict_free(mf_dict *d);
/* Intern a file name in the tree's pool; the pointer lives as long as the root. */
const char *mf_dict_intern(mf_dict *d, const char *s);
/* Append (or replace, OpenFOAM's rule: the last one wins) an entry; takes
 * ownership of items. Returns the entry or NULL on allocation failure. */
mf_entry *mf_dict_set(mf_dict *d, const char *key, mf_loc loc, size_t n, mf_value **items);
/* Append an entry without looking for one with the same key: for a caller
 * that knows the key is new (the parser keeps its own hash index, so that
 * huge dictionaries stay linear). Ownership as for mf_dict_set: on failure
 * the items are freed and NULL is returned. */
mf_entry *mf_dict_append(mf_dict *d, const char *key, mf_loc loc, size_t n, mf_value **items);
/* Give an existing entry new items (freeing the old ones, clearing `used`);
 * takes ownership of items. */
void mf_entry_replace(mf_entry *e, mf_loc loc, size_t n, mf_value **items);
mf_value *mf_value_new(mf_value_kind kind, mf_loc loc);
void mf_value_free(mf_value *v);
/* Deep copy into the tree of parent (file names re-interned there); with
 * parent NULL a dictionary value becomes a new root with its own pool. */
mf_value *mf_value_copy(const mf_value *v, mf_dict *parent);
/* Convenience builders used when writing resolved parameters. */
int mf_dict_set_number(mf_dict *d, const char *key, double x);
int mf_dict_set_word(mf_dict *d, const char *key, const char *word);
int mf_dict_set_vector(mf_dict *d, const char *key, const double v[3]);
mf_dict *mf_dict_set_subdict(mf_dict *d, const char *key);

/* Look up ------------------------------------------------------------------ */
mf_entry *mf_dict_find(const mf_dict *d, const char *key);
mf_dict *mf_dict_subdict(const mf_dict *d, const char *key); /* NULL if absent or not a dict */
/* "file:line:col" of a dictionary (its opening) for messages. */
const char *mf_loc_str(mf_loc loc, char *buf, size_t len);

/* Typed access. Each returns 0, or MF_ERR_INPUT with a message that names
 * file, line, column and key (and what was expected). The _or variants
 * return the default when the key is absent. */
int mf_dict_get_number(const mf_dict *d, const char *key, double *out);
int mf_dict_get_number_or(const mf_dict *d, const char *key, double def, double *out);
int mf_dict_get_int(const mf_dict *d, const char *key, long *out);
int mf_dict_get_bool(const mf_dict *d, const char *key, bool *out);
int mf_dict_get_bool_or(const mf_dict *d, const char *key, bool def, bool *out);
int mf_dict_get_word(const mf_dict *d, const char *key, const char **out);
int mf_dict_get_word_or(const mf_dict *d, const char *key, const char *def, const char **out);
int mf_dict_get_vector(const mf_dict *d, const char *key, double out[3]);
int mf_dict_get_vector_or(const mf_dict *d, const char *key, const double def[3], double out[3]);
/* Item conversions, for code that walks lists itself. `what` names it in errors. */
int mf_value_number(const mf_value *v, const char *what, double *out);
int mf_value_bool(const mf_value *v, const char *what, bool *out);
int mf_value_vector(const mf_value *v, const char *what, double out[3]);

/* Write the tree back in OpenFOAM syntax (round-trips through the parser).
 * indent is the nesting level of d's entries (4 spaces each). */
int mf_dict_write(const mf_dict *d, FILE *f, int indent);

/* The closest key among candidates (Damerau-Levenshtein), or NULL if none
 * is close enough to suggest. */
const char *mf_did_you_mean(const char *word, const char *const *candidates, size_t n);

#pragma GCC visibility pop
#endif
