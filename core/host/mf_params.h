/* mf_params.h: the parameter table every module declares.
 *
 * A module lists its parameters (name, type, default, range, one-line doc)
 * and where each lands in its settings struct (offsetof). The host uses the
 * one table to print the parameters (`mpsflow modules NAME`), to validate a
 * case dictionary (unknown key -> error with "did you mean"), to fill the
 * settings struct with defaults and given values, and to write the resolved
 * parameters of a run next to its output.
 */
#ifndef MF_PARAMS_H
#define MF_PARAMS_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "mf_dict.h"

typedef enum {
    MF_PARAM_SCALAR, /* double */
    MF_PARAM_INT,    /* long */
    MF_PARAM_BOOL,   /* bool */
    MF_PARAM_WORD,   /* const char * (points into the dictionary tree or def) */
    MF_PARAM_VECTOR, /* double[3] */
    MF_PARAM_DICT    /* const mf_dict * (a sub-dictionary the module reads itself) */
} mf_param_type;

typedef struct mf_param {
    const char *name;
    mf_param_type type;
    const char *def;              /* default as text ("0.97", "true", "(0 -9.81 0)"), NULL = required */
    double min, max;              /* inclusive range for SCALAR/INT; ignored when min > max */
    const char *const *choices;   /* WORD: NULL-terminated list of allowed words, or NULL */
    size_t offset;                /* offsetof(settings struct, field) */
    const char *doc;              /* one line */
} mf_param;

#define MF_NO_RANGE 1.0, 0.0

const char *mf_param_type_name(mf_param_type t);

/* Fill settings from defaults and dict. Every key of dict must be declared
 * (extra_keys lists others the caller handles itself, NULL-terminated, may be
 * NULL); an unknown key is an error with a suggestion. If resolved is not
 * NULL the full set of values (defaults included) is written into it. */
int mf_params_apply(const mf_param *table, size_t n, const mf_dict *dict,
                    const char *const *extra_keys, void *settings, mf_dict *resolved);
/* Same, but with no dictionary: defaults only. */
int mf_params_defaults(const mf_param *table, size_t n, void *settings);
/* Print the table for `mpsflow modules NAME`. */
void mf_params_print(const mf_param *table, size_t n, FILE *f);
/* The same as a markdown table (docs/reference.md). */
void mf_params_print_markdown(const mf_param *table, size_t n, FILE *f);

/* One table of a case dictionary that is not a module's: controlDict, the
 * watch {} block, each element kind of constant/geometry, a fluid of
 * constant/fluids, a validation metric, compareDict, stabilityDict. `name`
 * says where the keys go ("geometry: fluidBlocks/<name>, type box"). The
 * code that reads the dictionary applies the same table (mf_params_apply),
 * so that what is printed is what is checked. */
typedef struct mf_param_section {
    const char *name;
    const char *summary;
    const mf_param *params;
    size_t nparams;
} mf_param_section;

#pragma GCC visibility pop
#endif
