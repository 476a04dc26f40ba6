/* test_dict.c: the dictionary tree (core/host/dict.c) and the OpenFOAM-syntax
 * parser (io/dict/dict_parse.c).
 *
 * Usage: test_dict CORPUS_DIR, where CORPUS_DIR holds the malformed inputs
 * bad_*.dict (meson passes tests/dict_corpus). Inputs that must not be
 * committed (binary data, very deep nesting, a 100 MB line) are written to
 * a temporary directory at run time.
 */
#include <dirent.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "mf_dict.h"
#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_test.h"

/* ------------------------------------------------------------------------
 * Helpers
 * ---------------------------------------------------------------------- */
static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static char tmp_dir[256];
static char *tmp_files[128];
static int n_tmp_files;

/* Write a file in the temporary directory; returns its path (owned by the
 * list above, removed at the end). */
static const char *write_tmp(const char *name, const char *text, size_t len)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmp_dir, name);
    char *slash = strrchr(path, '/');
    if (slash > path + strlen(tmp_dir)) { /* a sub-folder */
        *slash = '\0';
        mkdir(path, 0700);
        *slash = '/';
    }
    FILE *f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(EXIT_FAILURE);
    }
    fwrite(text, 1, len, f);
    fclose(f);
    for (int k = 0; k < n_tmp_files; k++)
        if (strcmp(tmp_files[k], path) == 0)
            return tmp_files[k];
    tmp_files[n_tmp_files] = strdup(path);
    return tmp_files[n_tmp_files++];
}

static const char *write_tmp_str(const char *name, const char *text)
{
    return write_tmp(name, text, strlen(text));
}

static void remove_tmp(void)
{
    for (int k = n_tmp_files - 1; k >= 0; k--) {
        remove(tmp_files[k]);
        free(tmp_files[k]);
    }
    char sub[512];
    snprintf(sub, sizeof sub, "%s/sub", tmp_dir);
    rmdir(sub);
    rmdir(tmp_dir);
}

static mf_dict *parse(const char *text, const char *name)
{
    mf_dict *d = NULL;
    int rc = mf_dict_parse_string(text, strlen(text), name, &d);
    if (rc != 0) {
        fprintf(stderr, "unexpected parse failure of %s:\n", name);
        mf_error_print(stderr);
    }
    return d;
}

/* Recursive structural equality. Numbers compare by value and integer
 * flag (their source text may change: 1e-4 is written as 0.0001). */
static bool dict_equal(const mf_dict *a, const mf_dict *b);

static bool value_equal(const mf_value *a, const mf_value *b)
{
    if (a->kind != b->kind)
        return false;
    switch (a->kind) {
    case MF_VAL_WORD:
    case MF_VAL_STRING: return strcmp(a->text, b->text) == 0;
    case MF_VAL_NUMBER: return a->number == b->number && a->is_integer == b->is_integer;
    case MF_VAL_LIST:
        if (a->n != b->n)
            return false;
        for (size_t k = 0; k < a->n; k++)
            if (!value_equal(a->items[k], b->items[k]))
                return false;
        return true;
    case MF_VAL_DICT: return dict_equal(a->dict, b->dict);
    }
    return false;
}

static bool dict_equal(const mf_dict *a, const mf_dict *b)
{
    if (strcmp(a->name, b->name) != 0 || a->n != b->n)
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

/* Write d to memory and parse it back. */
static mf_dict *round_trip(const mf_dict *d, char **text_out)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    CHECK(f != NULL);
    if (!f)
        return NULL;
    CHECK_OK(mf_dict_write(d, f, 0));
    fclose(f);
    mf_dict *back = NULL;
    int rc = mf_dict_parse_string(text, len, "roundtrip", &back);
    CHECK_MSG(rc == 0, "written text does not parse back:\n%s", text);
    if (rc)
        mf_error_print(stderr);
    if (text_out)
        *text_out = text;
    else
        free(text);
    return back;
}

static bool contains(const char *hay, const char *needle)
{
    return strstr(hay, needle) != NULL;
}

/* The call fails with MF_ERR_INPUT and a message holding each needle. */
#define CHECK_FAILS_WITH(expr, ...)                                                 \
    do {                                                                            \
        mf_error_clear();                                                           \
        int rc_ = (expr);                                                           \
        CHECK_MSG(rc_ == MF_ERR_INPUT, "%s returned %d", #expr, rc_);               \
        const char *needles_[] = { __VA_ARGS__, NULL };                             \
        for (const char **n_ = needles_; *n_; n_++)                                 \
            CHECK_MSG(contains(mf_error_message(), *n_), "'%s' not in message: %s", \
                      *n_, mf_error_message());                                     \
        printf("  expected error: %s\n", mf_error_message());                       \
        mf_error_clear();                                                           \
    } while (0)

/* ------------------------------------------------------------------------
 * Good input
 * ---------------------------------------------------------------------- */
static const char good_text[] =
    "FoamFile\n"                                                 /* 1 */
    "{\n"                                                        /* 2 */
    "    version     2.0;\n"                                     /* 3 */
    "    format      ascii;\n"                                   /* 4 */
    "    class       dictionary;\n"                              /* 5 */
    "    location    \"system\";\n"                              /* 6 */
    "    object      controlDict;\n"                             /* 7 */
    "}\n"                                                        /* 8 */
    "// a line comment\n"                                        /* 9 */
    "/* a block\n"                                               /* 10 */
    "   comment */\n"                                            /* 11 */
    "application     mpsFoam;\n"                                 /* 12 */
    "startTime       0;\n"                                       /* 13 */
    "endTime         1.5;   // trailing comment\n"               /* 14 */
    "deltaT          1e-4;\n"                                    /* 15 */
    "nSteps          1000;\n"                                    /* 16 */
    "negative        -12;\n"                                     /* 17 */
    "flag1 true; flag2 off; flag3 yes; flag4 No;\n"              /* 18 */
    "gravity         (0 -9.81 0);\n"                             /* 19 */
    "title           \"a \\\"quoted\\\" title with \\\\ and \\n\";\n" /* 20 */
    "wordy           a.b:c-d+e<f>|g/h$i;\n"                      /* 21 */
    "multi           linear 0.5 \"str\" (1 2);\n"                /* 22 */
    "emptyList       ();\n"                                      /* 23 */
    "nested          ((1 2) (3 (4 5)) ());\n"                    /* 24 */
    "MPSCoeffs\n"                                                /* 25 */
    "{\n"                                                        /* 26 */
    "    re          2.1;\n"                                     /* 27 */
    "    inner { a 1; b { c 2; } }\n"                            /* 28 */
    "};\n"                                                       /* 29 */
    "bodies\n"                                                   /* 30 */
    "(\n"                                                        /* 31 */
    "    box { min (0 0 0); max (1 1 1); }\n"                    /* 32 */
    "    sphere\n"                                               /* 33 */
    "    {\n"                                                    /* 34 */
    "        centre (0.5 0.5 0.5);\n"                            /* 35 */
    "        radius 0.1;\n"                                      /* 36 */
    "    }\n"                                                    /* 37 */
    "    { anonymous 1; }\n"                                     /* 38 */
    ");\n"                                                       /* 39 */
    "emptyDict {}\n"                                             /* 40 */
    "dup 1;\n"                                                   /* 41 */
    "dup 2;\n"                                                   /* 42 */
    "notNumber 1e5x; infWord inf; nanWord nan; hexWord 0x10;\r\n" /* 43 */
    "dot .; minus -; plus +3; neg -.5; exp 1E+3; tiny 5e-324;\r\n" /* 44 */
    "utf8 \"h\xc3\xa9llo\"; w\xc3\xa9rd 1;\r\n"                   /* 45 */
    "multiline \"line one\n"                                     /* 46 */
    "line two\";\n"                                              /* 47 */
    "maybe maybe; frac 2.5; huge 99999999999999999999; oneE3 1e3;\n" /* 48 */
    "twoVec (1 2); wordVec (1 a 3);\n"                           /* 49 */
    "endTimeMissingSemicolon 10\n"                               /* 50 */
    "writeInterval 1;\n";                                        /* 51 */

static void test_good(void)
{
    mf_dict *d = parse(good_text, "case/system/controlDict");
    CHECK(d != NULL);
    if (!d)
        return;
    char where[256];
    double x, v[3];
    long i;
    bool b;
    const char *w;

    /* The header is an ordinary sub-dictionary. */
    mf_dict *header = mf_dict_subdict(d, "FoamFile");
    CHECK(header != NULL);
    CHECK_OK(mf_dict_get_word(header, "object", &w));
    CHECK(strcmp(w, "controlDict") == 0);
    CHECK_OK(mf_dict_get_word(header, "location", &w)); /* a string is read as a word */
    CHECK(strcmp(w, "system") == 0);
    CHECK_OK(mf_dict_get_number(header, "version", &x));
    CHECK(x == 2.0);
    CHECK(header->parent == d);
    CHECK(strcmp(header->name, "FoamFile") == 0);

    CHECK_OK(mf_dict_get_word(d, "application", &w));
    CHECK(strcmp(w, "mpsFoam") == 0);
    CHECK_OK(mf_dict_get_number(d, "endTime", &x));
    CHECK(x == 1.5);
    CHECK_OK(mf_dict_get_number(d, "deltaT", &x));
    CHECK(x == 1e-4);
    CHECK_OK(mf_dict_get_int(d, "nSteps", &i));
    CHECK(i == 1000);
    CHECK_OK(mf_dict_get_int(d, "negative", &i));
    CHECK(i == -12);
    CHECK_OK(mf_dict_get_int(d, "oneE3", &i)); /* a whole number written as 1e3 */
    CHECK(i == 1000);
    CHECK_OK(mf_dict_get_int(d, "plus", &i));
    CHECK(i == 3);
    CHECK(mf_dict_find(d, "startTime")->items[0]->is_integer);
    CHECK(!mf_dict_find(d, "endTime")->items[0]->is_integer);
    CHECK(!mf_dict_find(d, "exp")->items[0]->is_integer);

    /* Locations: the value of endTime is at 14:17. */
    const mf_entry *e = mf_dict_find(d, "endTime");
    CHECK(e->loc.line == 14 && e->loc.col == 1);
    CHECK(e->items[0]->loc.line == 14 && e->items[0]->loc.col == 17);
    CHECK(strcmp(mf_loc_str(e->items[0]->loc, where, sizeof where),
                 "case/system/controlDict:14:17") == 0);
    CHECK(strcmp(mf_loc_str(d->loc, where, sizeof where), "case/system/controlDict:1:1") == 0);
    /* Columns count characters, not bytes: the 1 of line 45 is at column 20... */
    e = mf_dict_find(d, "w\xc3\xa9rd");
    CHECK(e != NULL && e->loc.line == 45 && e->items[0]->loc.col == 20);
    /* ...and a string spanning lines moves the line count. */
    CHECK(mf_dict_find(d, "maybe")->loc.line == 48);

    /* Booleans. */
    CHECK_OK(mf_dict_get_bool(d, "flag1", &b));
    CHECK(b);
    CHECK_OK(mf_dict_get_bool(d, "flag2", &b));
    CHECK(!b);
    CHECK_OK(mf_dict_get_bool(d, "flag3", &b));
    CHECK(b);
    CHECK_OK(mf_dict_get_bool(d, "flag4", &b));
    CHECK(!b);
    CHECK_OK(mf_dict_get_bool_or(d, "noSuchFlag", true, &b));
    CHECK(b);

    /* Vectors. */
    CHECK_OK(mf_dict_get_vector(d, "gravity", v));
    CHECK(v[0] == 0 && v[1] == -9.81 && v[2] == 0);
    const double def[3] = { 1, 2, 3 };
    CHECK_OK(mf_dict_get_vector_or(d, "noSuchVector", def, v));
    CHECK(v[0] == 1 && v[1] == 2 && v[2] == 3);

    /* Strings with escapes (\n is not an escape: kept as written). */
    CHECK_OK(mf_dict_get_word(d, "title", &w));
    CHECK(strcmp(w, "a \"quoted\" title with \\ and \\n") == 0);
    CHECK(mf_dict_find(d, "title")->items[0]->kind == MF_VAL_STRING);
    CHECK_OK(mf_dict_get_word(d, "utf8", &w));
    CHECK(strcmp(w, "h\xc3\xa9llo") == 0);
    CHECK_OK(mf_dict_get_word(d, "multiline", &w));
    CHECK(strcmp(w, "line one\nline two") == 0);
    CHECK_OK(mf_dict_get_word(d, "wordy", &w));
    CHECK(strcmp(w, "a.b:c-d+e<f>|g/h$i") == 0);

    /* Words that look a bit like numbers stay words. */
    const char *words[] = { "notNumber", "infWord", "nanWord", "hexWord", "dot", "minus" };
    for (size_t k = 0; k < sizeof words / sizeof *words; k++) {
        e = mf_dict_find(d, words[k]);
        CHECK_MSG(e && e->items[0]->kind == MF_VAL_WORD, "%s is not a word", words[k]);
    }
    CHECK_OK(mf_dict_get_number(d, "neg", &x));
    CHECK(x == -0.5);
    CHECK_OK(mf_dict_get_number(d, "tiny", &x));
    CHECK(x > 0 && x < 1e-300);

    /* Several items; lists; nesting. */
    e = mf_dict_find(d, "multi");
    CHECK(e->n == 4);
    CHECK(e->items[0]->kind == MF_VAL_WORD && e->items[1]->kind == MF_VAL_NUMBER);
    CHECK(e->items[2]->kind == MF_VAL_STRING && e->items[3]->kind == MF_VAL_LIST);
    CHECK(e->items[3]->n == 2);
    e = mf_dict_find(d, "emptyList");
    CHECK(e->n == 1 && e->items[0]->kind == MF_VAL_LIST && e->items[0]->n == 0);
    e = mf_dict_find(d, "nested");
    CHECK(e->items[0]->n == 3);
    CHECK(e->items[0]->items[1]->items[1]->items[1]->number == 5);
    CHECK(e->items[0]->items[2]->n == 0);

    mf_dict *mps = mf_dict_subdict(d, "MPSCoeffs");
    CHECK(mps != NULL);
    CHECK_OK(mf_dict_get_number(mps, "re", &x));
    CHECK(x == 2.1);
    mf_dict *inner_b = mf_dict_subdict(mf_dict_subdict(mps, "inner"), "b");
    CHECK(inner_b != NULL);
    CHECK_OK(mf_dict_get_int(inner_b, "c", &i));
    CHECK(i == 2);
    CHECK(mf_dict_subdict(d, "emptyDict") && mf_dict_subdict(d, "emptyDict")->n == 0);

    /* A list of dictionaries: each `name { }` is a DICT item named name. */
    e = mf_dict_find(d, "bodies");
    CHECK(e->n == 1 && e->items[0]->kind == MF_VAL_LIST && e->items[0]->n == 3);
    if (e->items[0]->n == 3) {
        mf_value *const *bodies = e->items[0]->items;
        CHECK(bodies[0]->kind == MF_VAL_DICT && strcmp(bodies[0]->dict->name, "box") == 0);
        CHECK(bodies[1]->kind == MF_VAL_DICT && strcmp(bodies[1]->dict->name, "sphere") == 0);
        CHECK(bodies[2]->kind == MF_VAL_DICT && strcmp(bodies[2]->dict->name, "") == 0);
        CHECK_OK(mf_dict_get_vector(bodies[0]->dict, "max", v));
        CHECK(v[0] == 1 && v[1] == 1 && v[2] == 1);
        CHECK_OK(mf_dict_get_number(bodies[1]->dict, "radius", &x));
        CHECK(x == 0.1);
        CHECK(bodies[1]->dict->loc.line == 33);
    }

    /* The last duplicate wins. */
    CHECK_OK(mf_dict_get_int(d, "dup", &i));
    CHECK(i == 2);
    CHECK(mf_dict_find(d, "dup")->loc.line == 42);

    /* The accessors mark what they read. */
    CHECK(mf_dict_find(d, "endTime")->used);
    CHECK(!mf_dict_find(d, "negativeNever") && !mf_dict_find(d, "startTime")->used);

    /* Accessor errors: file:line:col, key, what was expected. */
    CHECK_FAILS_WITH(mf_dict_get_number(d, "application", &x), "case/system/controlDict:12:17:",
                     "key 'application'", "expected a number", "found word 'mpsFoam'");
    CHECK_FAILS_WITH(mf_dict_get_number(d, "endTme", &x), "case/system/controlDict:1:1:",
                     "missing key 'endTme'", "did you mean 'endTime'?");
    CHECK_FAILS_WITH(mf_dict_get_number(mps, "nu", &x), "case/system/controlDict:25:1:",
                     "missing key 'nu' in dictionary 'MPSCoeffs'");
    CHECK_FAILS_WITH(mf_dict_get_int(inner_b, "zz", &i), "in dictionary 'MPSCoeffs/inner/b'");
    CHECK_FAILS_WITH(mf_dict_get_int(d, "frac", &i), "controlDict:48:", "key 'frac'",
                     "expected an integer", "found number 2.5");
    CHECK_FAILS_WITH(mf_dict_get_int(d, "huge", &i), "controlDict:48:", "key 'huge'",
                     "out of range");
    CHECK_FAILS_WITH(mf_dict_get_int(d, "title", &i), "controlDict:20:", "expected an integer",
                     "found string");
    CHECK_FAILS_WITH(mf_dict_get_bool(d, "maybe", &b), "controlDict:48:7:",
                     "expected a boolean", "found word 'maybe'");
    CHECK_FAILS_WITH(mf_dict_get_bool(d, "nSteps", &b), "controlDict:16:", "expected a boolean");
    CHECK_FAILS_WITH(mf_dict_get_vector(d, "twoVec", v), "controlDict:49:", "key 'twoVec'",
                     "expected a vector", "a list of 2 items");
    CHECK_FAILS_WITH(mf_dict_get_vector(d, "wordVec", v), "controlDict:49:", "component 2",
                     "found word 'a'");
    CHECK_FAILS_WITH(mf_dict_get_vector(d, "endTime", v), "controlDict:14:",
                     "expected a vector");
    CHECK_FAILS_WITH(mf_dict_get_word(d, "gravity", &w), "controlDict:19:", "expected a word",
                     "a list of 3 items");
    CHECK_FAILS_WITH(mf_dict_get_word(d, "MPSCoeffs", &w), "controlDict:25:",
                     "a dictionary");
    CHECK_FAILS_WITH(mf_dict_get_number(d, "multi", &x), "controlDict:22:",
                     "expected a number, found 4 items");
    /* The forgotten ';' of line 50 swallowed line 51: the message says so. */
    CHECK_FAILS_WITH(mf_dict_get_number(d, "endTimeMissingSemicolon", &x), "controlDict:50:",
                     "found 3 items", "is a ';' missing at the end of line 50?");
    CHECK_FAILS_WITH(mf_dict_get_number_or(d, "application", 1.0, &x), "found word");
    CHECK_FAILS_WITH(mf_dict_get_word_or(d, "gravity", "x", &w), "expected a word");
    CHECK_FAILS_WITH(mf_dict_get_bool_or(d, "maybe", true, &b), "expected a boolean");
    CHECK_FAILS_WITH(mf_dict_get_vector_or(d, "twoVec", def, v), "expected a vector");
    CHECK_OK(mf_dict_get_number_or(d, "absent", 7.5, &x));
    CHECK(x == 7.5);
    CHECK_OK(mf_dict_get_word_or(d, "absent", "dflt", &w));
    CHECK(strcmp(w, "dflt") == 0);
    CHECK_FAILS_WITH(mf_dict_get_number(NULL, "x", &x), "missing key 'x'");

    /* Round trip: write, parse, compare. */
    char *text = NULL;
    mf_dict *back = round_trip(d, &text);
    CHECK(back != NULL);
    if (back) {
        CHECK_MSG(dict_equal(d, back), "round trip differs; written text:\n%s", text);
        /* and a second trip gives the same text */
        char *text2 = NULL;
        mf_dict *again = round_trip(back, &text2);
        CHECK(again && text2 && strcmp(text, text2) == 0);
        mf_dict_free(again);
        free(text2);
    }
    mf_dict_free(back);
    free(text);
    mf_dict_free(d);
}

/* Values built by the program round-trip too (resolved parameters). */
static void test_build_and_write(void)
{
    mf_dict *d = mf_dict_new("", NULL);
    CHECK(d != NULL);
    const double g[3] = { 0, -9.81, 1.0 / 3.0 };
    CHECK_OK(mf_dict_set_number(d, "count", 1000));
    CHECK_OK(mf_dict_set_number(d, "third", 1.0 / 3.0));
    CHECK_OK(mf_dict_set_number(d, "five", 5.0));
    CHECK_OK(mf_dict_set_number(d, "big", 1e300));
    CHECK_OK(mf_dict_set_number(d, "wholeButHuge", 1e20));
    CHECK_OK(mf_dict_set_word(d, "solver", "PCG"));
    CHECK_OK(mf_dict_set_word(d, "spaced", "two words"));
    CHECK_OK(mf_dict_set_word(d, "numeric", "123"));
    CHECK_OK(mf_dict_set_vector(d, "gravity", g));
    mf_dict *sub = mf_dict_set_subdict(d, "sub");
    CHECK(sub != NULL);
    CHECK(mf_dict_set_subdict(d, "sub") == sub); /* get-or-create */
    CHECK_OK(mf_dict_set_number(sub, "x", -0.1));
    CHECK_OK(mf_dict_set_number(d, "five", 5.5)); /* replaces */
    CHECK(d->n == 10);

    char *text = NULL;
    mf_dict *back = round_trip(d, &text);
    CHECK(back != NULL);
    if (back) {
        printf("  written:\n%s", text);
        double x, v[3];
        long i;
        const char *w;
        CHECK_OK(mf_dict_get_int(back, "count", &i));
        CHECK(i == 1000);
        CHECK(contains(text, "count 1000;"));
        CHECK_OK(mf_dict_get_number(back, "third", &x));
        CHECK(x == 1.0 / 3.0); /* %.17g is exact */
        CHECK_OK(mf_dict_get_number(back, "five", &x));
        CHECK(x == 5.5);
        CHECK_OK(mf_dict_get_number(back, "big", &x));
        CHECK(x == 1e300);
        CHECK_OK(mf_dict_get_vector(back, "gravity", v));
        CHECK(v[0] == g[0] && v[1] == g[1] && v[2] == g[2]);
        CHECK_OK(mf_dict_get_word(back, "spaced", &w));
        CHECK(strcmp(w, "two words") == 0);
        CHECK_OK(mf_dict_get_word(back, "numeric", &w)); /* quoted: not the number 123 */
        CHECK(strcmp(w, "123") == 0);
        CHECK_OK(mf_dict_get_number(mf_dict_subdict(back, "sub"), "x", &x));
        CHECK(x == -0.1);
        CHECK(dict_equal(mf_dict_subdict(d, "sub"), mf_dict_subdict(back, "sub")));
    }
    /* A non-integer whole number keeps its '.0' so it reads back as such. */
    mf_dict *f = parse("a 5.0; b -0.0; c 1e20;", "float");
    mf_dict *fb = f ? round_trip(f, NULL) : NULL;
    CHECK(fb && dict_equal(f, fb));
    mf_dict_free(f);
    mf_dict_free(fb);

    /* A copy outlives its source, file names included. */
    mf_dict *src = parse("sub { a (1 two \"three\"); l ( x { y 1; } ); }", "dir/src.dict");
    CHECK(src != NULL);
    if (src) {
        mf_value *copy = mf_value_copy(mf_dict_find(src, "sub")->items[0], NULL);
        CHECK(copy && copy->kind == MF_VAL_DICT);
        mf_dict *holder = mf_dict_new("", NULL);
        mf_value *copy2 = mf_value_copy(mf_dict_find(src, "sub")->items[0], holder);
        CHECK(copy2 != NULL);
        mf_dict_free(src);
        if (copy) {
            char where[256];
            const mf_entry *a = mf_dict_find(copy->dict, "a");
            CHECK(a && a->items[0]->n == 3);
            CHECK(strcmp(mf_loc_str(a->items[0]->loc, where, sizeof where), "dir/src.dict:1:9") ==
                  0);
            CHECK(strcmp(mf_loc_str(copy2->dict->loc, where, sizeof where),
                         "dir/src.dict:1:1") == 0);
        }
        mf_value_free(copy);
        mf_value_free(copy2);
        mf_dict_free(holder);
    }
    free(text);
    mf_dict_free(back);
    mf_dict_free(d);
}

static void test_did_you_mean(void)
{
    const char *keys[] = { "startTime", "endTime", "deltaT", "writeInterval", "nu" };
    size_t n = sizeof keys / sizeof *keys;
    const char *s = mf_did_you_mean("endTim", keys, n);
    CHECK(s && strcmp(s, "endTime") == 0);
    s = mf_did_you_mean("ENDTIME", keys, n); /* case alone */
    CHECK(s && strcmp(s, "endTime") == 0);
    s = mf_did_you_mean("edntime", keys, n); /* a swap and a case */
    CHECK(s && strcmp(s, "endTime") == 0);
    s = mf_did_you_mean("writeIntervall", keys, n);
    CHECK(s && strcmp(s, "writeInterval") == 0);
    CHECK(mf_did_you_mean("pressureSolver", keys, n) == NULL);
    CHECK(mf_did_you_mean("xyzzy", keys, n) == NULL);
    CHECK(mf_did_you_mean("dt", keys, n) == NULL); /* shares nothing with "nu" */
    CHECK(mf_did_you_mean("endTime", NULL, 0) == NULL);
    CHECK(mf_did_you_mean("", keys, n) == NULL);
}

/* ------------------------------------------------------------------------
 * #include
 * ---------------------------------------------------------------------- */
static void test_include(void)
{
    write_tmp_str("sub/inc.dict", "b 2;\n#include \"deeper.dict\"\na 10;\n");
    write_tmp_str("sub/deeper.dict", "// relative to sub/\nd 4;\n");
    write_tmp_str("sub/empty.dict", "// an empty include is fine\n");
    write_tmp_str("sub/broken.dict", "x 1;\ny (1 2;\n");
    const char *main_path = write_tmp_str("main.dict",
                                          "a 1;\n"
                                          "#include \"sub/inc.dict\"\n"
                                          "c 3;\n"
                                          "inner\n"
                                          "{\n"
                                          "    #include \"sub/deeper.dict\"\n"
                                          "    #include \"sub/empty.dict\"\n"
                                          "}\n");
    mf_dict *d = NULL;
    CHECK_OK(mf_dict_parse_file(main_path, &d));
    if (d) {
        long i;
        CHECK_OK(mf_dict_get_int(d, "a", &i));
        CHECK(i == 10); /* redefined by the include: the last one wins */
        CHECK_OK(mf_dict_get_int(d, "b", &i));
        CHECK(i == 2);
        CHECK_OK(mf_dict_get_int(d, "d", &i));
        CHECK(i == 4);
        CHECK_OK(mf_dict_get_int(mf_dict_subdict(d, "inner"), "d", &i));
        CHECK(i == 4);
        const mf_entry *b = mf_dict_find(d, "b");
        CHECK(b && contains(b->loc.file, "sub/inc.dict") && b->loc.line == 1);
        const mf_entry *dd = mf_dict_find(d, "d");
        CHECK(dd && contains(dd->loc.file, "sub/deeper.dict") && dd->loc.line == 2);
        CHECK(strcmp(mf_dict_find(d, "c")->loc.file, main_path) == 0);
        /* the tree's files are interned once each */
        CHECK(mf_dict_find(mf_dict_subdict(d, "inner"), "d")->loc.file == dd->loc.file);
        mf_dict_free(d);
    }
    /* An error inside an included file names both files. */
    const char *p = write_tmp_str("main2.dict", "a 1;\n\n#include \"sub/broken.dict\"\n");
    d = NULL;
    CHECK_FAILS_WITH(mf_dict_parse_file(p, &d), "sub/broken.dict:2:", "main2.dict:3:1",
                     "included from");
    CHECK(d == NULL);
    /* Including oneself. */
    p = write_tmp_str("self.dict", "a 1;\n#include \"self.dict\"\n");
    CHECK_FAILS_WITH(mf_dict_parse_file(p, &d), "self.dict:2:1", "#include cycle");
    /* Relative includes from a parsed string use the name's directory. */
    char name[512], text[600];
    snprintf(name, sizeof name, "%s/fromstring", tmp_dir);
    snprintf(text, sizeof text, "#include \"sub/deeper.dict\"\n");
    CHECK_OK(mf_dict_parse_string(text, strlen(text), name, &d));
    CHECK(d && mf_dict_find(d, "d"));
    mf_dict_free(d);
    /* A file that does not exist at all. */
    snprintf(name, sizeof name, "%s/nothing/here.dict", tmp_dir);
    d = NULL;
    mf_error_clear();
    CHECK(mf_dict_parse_file(name, &d) == MF_ERR_IO);
    CHECK(contains(mf_error_message(), "here.dict") &&
          contains(mf_error_message(), "No such file"));
    printf("  expected error: %s\n", mf_error_message());
    mf_error_clear();
    CHECK(mf_dict_parse_file(tmp_dir, &d) < 0 && contains(mf_error_message(), "is a folder"));
    CHECK(d == NULL);
    printf("  expected error: %s\n", mf_error_message());
    mf_error_clear();
}

/* Only regular files are read: a FIFO (no writer: reading it would block
 * forever) and /dev/zero (endless) are refused at once, before a byte is
 * read, as dictionaries and as includes. */
static void test_not_regular(void)
{
    char fifo[600];
    snprintf(fifo, sizeof fifo, "%s/fifo", tmp_dir);
    CHECK(mkfifo(fifo, 0600) == 0);
    mf_dict *d = NULL;
    mf_error_clear();
    CHECK(mf_dict_parse_file(fifo, &d) == MF_ERR_INPUT);
    CHECK(contains(mf_error_message(), "a FIFO (named pipe), not a regular file"));
    printf("  expected error: %s\n", mf_error_message());
    mf_error_clear();
    const char *p = write_tmp_str("inc_fifo.dict", "a 1;\n#include \"fifo\"\n");
    CHECK_FAILS_WITH(mf_dict_parse_file(p, &d), "inc_fifo.dict:2:1", "is a FIFO");
    p = write_tmp_str("inc_zero.dict", "a 1;\n#include \"/dev/zero\"\n");
    CHECK_FAILS_WITH(mf_dict_parse_file(p, &d), "inc_zero.dict:2:1",
                     "is a character device, not a regular file");
    CHECK(d == NULL);
    CHECK(mf_dict_parse_file("/dev/zero", &d) == MF_ERR_INPUT && d == NULL);
    mf_error_clear();
    unlink(fifo);
}

/* A stray UTF-8 byte order mark: the parser drops one at the start of a
 * file; a second one is part of the first key, and the writer must keep it
 * there (not write it where the parser would drop it). */
static void test_stray_bom(void)
{
    static const char text[] = "\xEF\xBB\xBF\xEF\xBB\xBFkey 1;\nw \xEF\xBB\xBFword;\n";
    mf_dict *d = NULL;
    CHECK_OK(mf_dict_parse_string(text, sizeof text - 1, "bom", &d));
    if (!d)
        return;
    CHECK(d->n == 2 && strcmp(d->entries[0]->key, "\xEF\xBB\xBFkey") == 0);
    char *written = NULL;
    mf_dict *back = round_trip(d, &written);
    CHECK_MSG(back && dict_equal(d, back), "stray BOM lost in the round trip:\n%s", written);
    free(written);
    mf_dict_free(back);
    mf_dict_free(d);
}

/* ------------------------------------------------------------------------
 * Malformed input
 * ---------------------------------------------------------------------- */
static const struct {
    const char *file;
    int line;          /* the line the message must name */
    const char *words; /* and a phrase it must hold */
} corpus[] = {
    { "bad_truncated.dict", 13, "expected ';' after value of key 'deltaT', found end of file" },
    { "bad_unclosed_brace.dict", 4, "'{' opened at 4:1 is never closed" },
    { "bad_unbalanced_brace.dict", 6, "unbalanced '}'" },
    { "bad_bare_brace.dict", 2, "unbalanced '}'" },
    { "bad_unbalanced_paren.dict", 3, "expected ')' to close the list opened at 3:9, found ';'" },
    { "bad_extra_paren.dict", 2, "unbalanced ')'" },
    { "bad_unclosed_list.dict", 3, "'(' opened at 3:1 is never closed" },
    { "bad_missing_semicolon.dict", 5, "expected ';' after value of key 'endTime', found '}'" },
    { "bad_missing_semicolon_before_dict.dict", 3, "missing at the end of line 1" },
    { "bad_unterminated_string.dict", 2, "unterminated string" },
    { "bad_unterminated_comment.dict", 2, "unterminated comment" },
    { "bad_missing_include.dict", 2,
      "cannot open #include file \"does_not_exist.inc\" (No such file or directory)" },
    { "bad_include_cycle.dict", 3, "#include cycle" },
    { "bad_include_not_string.dict", 2, "expected a quoted file name after #include" },
    { "bad_empty.dict", 1, "empty dictionary file" },
    { "bad_comments_only.dict", 1, "empty dictionary file" },
    { "bad_no_value.dict", 2, "key 'key' has no value" },
    { "bad_include_etc.dict", 2, "unsupported directive '#includeEtc'" },
    { "bad_input_mode.dict", 3, "unsupported directive '#inputMode'" },
    { "bad_key_is_string.dict", 2, "expected a key (a word), found string \"quotedKey\"" },
    { "bad_key_is_number.dict", 3, "expected a key (a word), found number 12" },
    { "bad_number_out_of_range.dict", 2, "out of range" },
    { "bad_directive_in_list.dict", 4, "#include must stand between entries" },
    { "bad_brace_in_list.dict", 1, "expected ')' to close the list opened at 1:6, found '}'" },
};

/* Parse path; it must fail with the message naming file_name:line. */
static void expect_failure(const char *path, const char *file_name, int line, const char *words)
{
    mf_dict *d = (mf_dict *)1;
    mf_error_clear();
    int rc = mf_dict_parse_file(path, &d);
    const char *msg = mf_error_message();
    char located[300];
    snprintf(located, sizeof located, "%s:%d:", file_name, line);
    printf("  %-40s -> %s\n", file_name, msg);
    CHECK_MSG(rc < 0, "%s: parse returned %d", file_name, rc);
    CHECK_MSG(d == NULL, "%s: *out not NULL on failure", file_name);
    CHECK_MSG(contains(msg, located), "%s: message does not name '%s': %s", file_name, located,
              msg);
    if (words)
        CHECK_MSG(contains(msg, words), "%s: message lacks '%s': %s", file_name, words, msg);
    mf_error_clear();
}

static void test_corpus(const char *dir)
{
    size_t n = sizeof corpus / sizeof *corpus;
    char path[1024];
    for (size_t k = 0; k < n; k++) {
        snprintf(path, sizeof path, "%s/%s", dir, corpus[k].file);
        expect_failure(path, corpus[k].file, corpus[k].line, corpus[k].words);
    }
    /* Every bad_*.dict of the folder must be in the table above. */
    DIR *dp = opendir(dir);
    CHECK_MSG(dp != NULL, "cannot open corpus folder %s", dir);
    size_t seen = 0;
    for (struct dirent *de; dp && (de = readdir(dp));) {
        if (strncmp(de->d_name, "bad_", 4) != 0)
            continue;
        bool listed = false;
        for (size_t k = 0; k < n; k++)
            listed = listed || strcmp(de->d_name, corpus[k].file) == 0;
        CHECK_MSG(listed, "%s is not in the corpus table of test_dict.c", de->d_name);
        seen++;
    }
    if (dp)
        closedir(dp);
    CHECK(seen == n);
}

/* Malformed inputs made at run time. */
static void test_generated_failures(void)
{
    /* Binary data: a NUL byte at 2:2, a 0x01 inside a comment, a 0x7f
     * starting an ELF-like header. */
    static const char nul_text[] = "a 1;\nb\0\0\1\2garbage";
    const char *p = write_tmp("bad_binary.dict", nul_text, sizeof nul_text - 1);
    expect_failure(p, "bad_binary.dict", 2, "binary data (byte 0x00)");
    p = write_tmp_str("bad_binary_comment.dict", "a 1;\n\n// here \x01 it is\n");
    expect_failure(p, "bad_binary_comment.dict", 3, "binary data (byte 0x01)");
    p = write_tmp_str("bad_elf.dict", "\x7f" "ELF\x02\x01\x01");
    expect_failure(p, "bad_elf.dict", 1, "this is not a text dictionary");
    static const char nul_string[] = "a \"x\0y\";";
    p = write_tmp("bad_nul_string.dict", nul_string, sizeof nul_string - 1);
    expect_failure(p, "bad_nul_string.dict", 1, "binary data");

    /* Nesting: 200 levels are fine, 201 are not, and 100000 do not
     * overflow the stack. */
    size_t deep = 100000;
    char *text = malloc(2 * deep + 16);
    CHECK(text != NULL);
    if (!text)
        return;
    for (size_t levels = 200; levels <= 201; levels++) {
        size_t len = 0;
        len += (size_t)sprintf(text, "x ");
        memset(text + len, '(', levels);
        len += levels;
        memset(text + len, ')', levels);
        len += levels;
        text[len++] = ';';
        mf_dict *d = NULL;
        int rc = mf_dict_parse_string(text, len, "deep", &d);
        if (levels == 200) {
            CHECK_MSG(rc == 0, "200 nested lists: %s", mf_error_message());
            mf_dict *back = d ? round_trip(d, NULL) : NULL;
            CHECK(back && dict_equal(d, back));
            mf_dict_free(back);
        } else {
            CHECK(rc == MF_ERR_INPUT && contains(mf_error_message(), "deep:1:203:") &&
                  contains(mf_error_message(), "nested deeper than 200"));
            printf("  %-40s -> %s\n", "201 nested lists", mf_error_message());
        }
        mf_dict_free(d);
        mf_error_clear();
    }
    memcpy(text, "x ", 2);
    memset(text + 2, '(', deep);
    p = write_tmp("bad_deep_lists.dict", text, deep + 2);
    expect_failure(p, "bad_deep_lists.dict", 1, "nested deeper than 200");
    /* Dictionaries nested 300 deep, one per line. */
    size_t len = 0;
    for (int k = 0; k < 300; k++)
        len += (size_t)sprintf(text + len, "d%d {\n", k);
    p = write_tmp("bad_deep_dicts.dict", text, len);
    expect_failure(p, "bad_deep_dicts.dict", 201, "nested deeper than 200");
    free(text);

    /* Include cycle through three files (a -> b -> c -> a). */
    write_tmp_str("cyc_b.dict", "b 1;\n#include \"cyc_c.dict\"\n");
    write_tmp_str("cyc_c.dict", "c 1;\n\n#include \"bad_cyc_a.dict\"\n");
    p = write_tmp_str("bad_cyc_a.dict", "a 1;\n#include \"cyc_b.dict\"\n");
    expect_failure(p, "cyc_c.dict", 3, "#include cycle");
    expect_failure(p, "bad_cyc_a.dict", 2, "included from");

    /* A chain of 20 includes without a cycle stops at 16 deep. */
    char name[64], body[128];
    for (int k = 0; k < 20; k++) {
        snprintf(name, sizeof name, "chain%02d.dict", k);
        snprintf(body, sizeof body, "k%d 1;\n#include \"chain%02d.dict\"\n", k, k + 1);
        p = write_tmp_str(name, body);
        if (k == 0)
            text = strdup(p);
    }
    expect_failure(text, "chain16.dict", 2, "included more than 16 deep");
    free(text);

    /* Over 1 GiB: refused from the size alone (a sparse file, nothing read). */
    p = write_tmp_str("bad_huge.dict", "a 1;\n");
    CHECK(truncate(p, (off_t)((size_t)1 << 30) + 1) == 0);
    mf_dict *d = NULL;
    mf_error_clear();
    CHECK(mf_dict_parse_file(p, &d) == MF_ERR_INPUT && d == NULL);
    CHECK(contains(mf_error_message(), "bad_huge.dict") &&
          contains(mf_error_message(), "larger than 1 GiB"));
    printf("  %-40s -> %s\n", "bad_huge.dict", mf_error_message());
    mf_error_clear();
}

/* ------------------------------------------------------------------------
 * Size: a 100 MB line and many keys must stay linear
 * ---------------------------------------------------------------------- */
static void test_big(void)
{
    const size_t target = (size_t)100 << 20;
    const char unit[] = "a 1; ";
    size_t ulen = sizeof unit - 1, count = target / ulen;
    char path[512];
    snprintf(path, sizeof path, "%s/big_line.dict", tmp_dir);
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f)
        return;
    char chunk[5 * 4096];
    for (size_t k = 0; k < sizeof chunk / ulen; k++)
        memcpy(chunk + k * ulen, unit, ulen);
    size_t per_chunk = sizeof chunk / ulen;
    for (size_t done = 0; done < count; done += per_chunk) {
        size_t n = count - done < per_chunk ? count - done : per_chunk;
        fwrite(chunk, ulen, n, f);
    }
    fputs("last 2;", f);
    fclose(f);
    tmp_files[n_tmp_files++] = strdup(path);

    double t0 = now_seconds();
    mf_dict *d = NULL;
    int rc = mf_dict_parse_file(path, &d);
    double t1 = now_seconds();
    printf("  100 MB single line (%zu entries): parse %s in %.2f s\n", count + 1,
           rc == 0 ? "ok" : "failed", t1 - t0);
    CHECK_OK(rc);
    if (d) {
        long i;
        CHECK(d->n == 2);
        CHECK_OK(mf_dict_get_int(d, "last", &i));
        CHECK(i == 2);
        const mf_entry *e = mf_dict_find(d, "last");
        CHECK(e->loc.line == 1 && e->loc.col == (int)(count * ulen + 1));
    }
    mf_dict_free(d);

    /* 200000 distinct keys: quadratic duplicate checks would take minutes. */
    size_t nkeys = 200000;
    char *text = malloc(nkeys * 24);
    CHECK(text != NULL);
    if (!text)
        return;
    size_t len = 0;
    for (size_t k = 0; k < nkeys; k++)
        len += (size_t)sprintf(text + len, "key%zu %zu;\n", k, k);
    len += (size_t)sprintf(text + len, "key17 -1;\n"); /* a late duplicate */
    t0 = now_seconds();
    d = NULL;
    CHECK_OK(mf_dict_parse_string(text, len, "manykeys", &d));
    t1 = now_seconds();
    printf("  %zu distinct keys: parse in %.2f s\n", nkeys, t1 - t0);
    if (d) {
        long i;
        CHECK(d->n == nkeys);
        CHECK_OK(mf_dict_get_int(d, "key17", &i));
        CHECK(i == -1);
        CHECK_OK(mf_dict_get_int(d, "key199999", &i));
        CHECK(i == 199999);
    }
    mf_dict_free(d);
    free(text);

    /* One 8 MB string and one 8 MB word. */
    size_t big = (size_t)8 << 20;
    text = malloc(2 * big + 64);
    CHECK(text != NULL);
    if (!text)
        return;
    len = (size_t)sprintf(text, "s \"");
    memset(text + len, 'x', big);
    len += big;
    len += (size_t)sprintf(text + len, "\"; w ");
    memset(text + len, 'y', big);
    len += big;
    text[len++] = ';';
    d = NULL;
    CHECK_OK(mf_dict_parse_string(text, len, "bigtokens", &d));
    if (d) {
        const char *w;
        CHECK_OK(mf_dict_get_word(d, "w", &w));
        CHECK(strlen(w) == big);
        CHECK_OK(mf_dict_get_word(d, "s", &w));
        CHECK(strlen(w) == big);
    }
    mf_dict_free(d);
    free(text);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s CORPUS_DIR\n", argv[0]);
        return EXIT_FAILURE;
    }
    snprintf(tmp_dir, sizeof tmp_dir, "%s/mf_test_dict_XXXXXX",
             getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return EXIT_FAILURE;
    }
    printf("good input\n");
    test_good();
    printf("building and writing\n");
    test_build_and_write();
    test_did_you_mean();
    printf("#include\n");
    test_include();
    printf("files that are not regular files; a stray byte order mark\n");
    test_not_regular();
    test_stray_bom();
    printf("malformed corpus (%s)\n", argv[1]);
    test_corpus(argv[1]);
    printf("malformed input made at run time\n");
    test_generated_failures();
    printf("size\n");
    test_big();
    remove_tmp();
    return mf_test_summary("test_dict");
}
