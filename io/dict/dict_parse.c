/* dict_parse.c: OpenFOAM-syntax text -> mf_dict tree (see mf_dictio.h).
 *
 * Two layers: a tokenizer that tracks line and column, and a
 * recursive-descent parser with an explicit depth limit, so that hostile
 * input (deep nesting, include cycles, a 100 MB line) ends in a clean error
 * rather than a stack overflow, and every step stays linear in the input.
 *
 * The whole file is read into one buffer that the tokenizer owns: tokens
 * point into it (no copy per token), and strings are unescaped in place.
 */
#include "mf_dictio.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_hashmap.h"

/* ------------------------------------------------------------------------
 * Tokenizer
 * ---------------------------------------------------------------------- */
typedef enum {
    TOK_EOF,
    TOK_WORD,
    TOK_STRING,
    TOK_NUMBER,
    TOK_DIRECTIVE, /* #word */
    TOK_LBRACE,
    TOK_RBRACE,
    TOK_LPAREN,
    TOK_RPAREN,
    TOK_SEMI
} tok_kind;

typedef struct token {
    tok_kind kind;
    mf_loc loc;
    const char *text; /* into the lexer's buffer; not NUL-terminated */
    size_t len;
    double number;
    bool is_integer;
} token;

typedef struct lexer {
    char *buf; /* len bytes plus a NUL; owned */
    size_t len, pos;
    int line, col;
    const char *file; /* interned in the tree's pool */
    bool has_peek;
    token peeked;
} lexer;

/* Raise MF_ERR_INPUT as "file:line:col: message". */
static int syntax_error(mf_loc loc, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int syntax_error(mf_loc loc, const char *fmt, ...)
{
    char msg[1536];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return MF_ERROR(MF_ERR_INPUT, "%s:%d:%d: %s", loc.file ? loc.file : "<input>", loc.line,
                    loc.col, msg);
}

static int out_of_memory(const char *file)
{
    return MF_ERROR(MF_ERR_MEMORY, "out of memory reading %s", file ? file : "a dictionary");
}

static void lexer_init(lexer *lx, char *buf, size_t len, const char *file)
{
    memset(lx, 0, sizeof *lx);
    lx->buf = buf;
    lx->len = len;
    lx->line = 1;
    lx->col = 1;
    lx->file = file;
    /* A UTF-8 byte order mark is not part of the text. */
    if (len >= 3 && memcmp(buf, "\xEF\xBB\xBF", 3) == 0)
        lx->pos = 3;
}

static inline int peek_byte(const lexer *lx, size_t ahead)
{
    return lx->pos + ahead < lx->len ? (unsigned char)lx->buf[lx->pos + ahead] : -1;
}

/* Columns count characters, not bytes: UTF-8 continuation bytes do not
 * move the column. */
static inline void advance(lexer *lx)
{
    unsigned char c = (unsigned char)lx->buf[lx->pos++];
    if (c == '\n') {
        lx->line++;
        lx->col = 1;
    } else if ((c & 0xC0) != 0x80) {
        lx->col++;
    }
}

static inline mf_loc here(const lexer *lx)
{
    return (mf_loc){ lx->file, lx->line, lx->col };
}

/* Control bytes other than tab, CR and LF do not occur in text files. */
static inline bool is_binary(int c)
{
    return c >= 0 && ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f);
}

static int binary_error(const lexer *lx, int c)
{
    return syntax_error(here(lx), "binary data (byte 0x%02x): this is not a text dictionary", c);
}

/* Word bytes: anything printable but space and "(){}; (UTF-8 included).
 * core/host/dict.c writes words by the same rule, so the two must agree. */
static inline bool word_byte(int c)
{
    return c > ' ' && c != 0x7f && c != '"' && c != '(' && c != ')' && c != '{' && c != '}' &&
           c != ';';
}

static inline bool comment_start(const lexer *lx)
{
    return peek_byte(lx, 0) == '/' && (peek_byte(lx, 1) == '/' || peek_byte(lx, 1) == '*');
}

static int skip_space_and_comments(lexer *lx)
{
    for (;;) {
        int c = peek_byte(lx, 0);
        if (c == ' ' || c == '\t' || c == '\r' || c == '\n') {
            advance(lx);
        } else if (c == '/' && peek_byte(lx, 1) == '/') {
            while ((c = peek_byte(lx, 0)) != -1 && c != '\n') {
                if (is_binary(c))
                    return binary_error(lx, c);
                advance(lx);
            }
        } else if (c == '/' && peek_byte(lx, 1) == '*') {
            mf_loc start = here(lx);
            advance(lx);
            advance(lx);
            for (;;) {
                c = peek_byte(lx, 0);
                if (c == -1)
                    return syntax_error(start, "unterminated comment: this '/*' is never "
                                               "closed by '*/'");
                if (c == '*' && peek_byte(lx, 1) == '/') {
                    advance(lx);
                    advance(lx);
                    break;
                }
                if (is_binary(c))
                    return binary_error(lx, c);
                advance(lx);
            }
        } else if (is_binary(c)) {
            return binary_error(lx, c);
        } else {
            return 0;
        }
    }
}

static void scan_word(lexer *lx)
{
    while (word_byte(peek_byte(lx, 0)) && !comment_start(lx))
        advance(lx);
}

/* [+-] digits [. digits] [e [+-] digits], with at least one digit before
 * the exponent; sets *is_integer when there is neither '.' nor exponent.
 * inf, nan and hex are not numbers here: they stay words. */
static bool number_syntax(const char *s, size_t n, bool *is_integer)
{
    size_t k = 0;
    bool digits = false, integer = true;
    if (k < n && (s[k] == '+' || s[k] == '-'))
        k++;
    while (k < n && isdigit((unsigned char)s[k])) {
        k++;
        digits = true;
    }
    if (k < n && s[k] == '.') {
        integer = false;
        k++;
        while (k < n && isdigit((unsigned char)s[k])) {
            k++;
            digits = true;
        }
    }
    if (!digits)
        return false;
    if (k < n && (s[k] == 'e' || s[k] == 'E')) {
        integer = false;
        k++;
        if (k < n && (s[k] == '+' || s[k] == '-'))
            k++;
        if (k == n || !isdigit((unsigned char)s[k]))
            return false;
        while (k < n && isdigit((unsigned char)s[k]))
            k++;
    }
    *is_integer = integer;
    return k == n;
}

static int scan_string(lexer *lx, token *t)
{
    mf_loc start = here(lx);
    advance(lx); /* the opening quote */
    /* Unescape in place: the write position never passes the read one. */
    size_t out = lx->pos;
    t->kind = TOK_STRING;
    t->text = lx->buf + out;
    for (;;) {
        int c = peek_byte(lx, 0);
        if (c == -1)
            return syntax_error(start, "unterminated string: this '\"' is never closed");
        if (c == 0)
            return binary_error(lx, c); /* a C string cannot hold it */
        if (c == '"') {
            advance(lx);
            break;
        }
        if (c == '\\' && (peek_byte(lx, 1) == '"' || peek_byte(lx, 1) == '\\')) {
            advance(lx);
            c = peek_byte(lx, 0);
        }
        advance(lx);
        lx->buf[out++] = (char)c;
    }
    t->len = out - (size_t)(t->text - lx->buf);
    return 0;
}

static int scan_token(lexer *lx, token *t)
{
    MF_CALL(skip_space_and_comments(lx));
    memset(t, 0, sizeof *t);
    t->loc = here(lx);
    int c = peek_byte(lx, 0);
    switch (c) {
    case -1: t->kind = TOK_EOF; return 0;
    case '{': t->kind = TOK_LBRACE; break;
    case '}': t->kind = TOK_RBRACE; break;
    case '(': t->kind = TOK_LPAREN; break;
    case ')': t->kind = TOK_RPAREN; break;
    case ';': t->kind = TOK_SEMI; break;
    case '"': return scan_string(lx, t);
    default: {
        size_t start = lx->pos;
        t->kind = c == '#' ? TOK_DIRECTIVE : TOK_WORD;
        if (c == '#')
            advance(lx);
        scan_word(lx);
        if (lx->pos == start) /* cannot happen: skip_space... stops only at word bytes */
            return binary_error(lx, c);
        t->text = lx->buf + start;
        t->len = lx->pos - start;
        if (t->kind == TOK_WORD && (isdigit(c) || c == '+' || c == '-' || c == '.') &&
            number_syntax(t->text, t->len, &t->is_integer)) {
            /* strtod needs a terminator: borrow the byte after the token
             * (the buffer has a spare NUL at its end) and put it back. */
            char saved = lx->buf[lx->pos];
            lx->buf[lx->pos] = '\0';
            t->number = strtod(t->text, NULL);
            lx->buf[lx->pos] = saved;
            if (isinf(t->number))
                return syntax_error(t->loc, "number %.*s is out of range (beyond +-1.8e308)",
                                    t->len > 60 ? 60 : (int)t->len, t->text);
            t->kind = TOK_NUMBER;
        }
        return 0;
    }
    }
    t->text = lx->buf + lx->pos;
    t->len = 1;
    advance(lx);
    return 0;
}

static int next_token(lexer *lx, token *t)
{
    if (lx->has_peek) {
        *t = lx->peeked;
        lx->has_peek = false;
        return 0;
    }
    return scan_token(lx, t);
}

static int peek_token(lexer *lx, const token **t)
{
    if (!lx->has_peek) {
        MF_CALL(scan_token(lx, &lx->peeked));
        lx->has_peek = true;
    }
    *t = &lx->peeked;
    return 0;
}

/* A token as messages name it: "word 'abc'", "'}'", "end of file". */
static const char *describe(const token *t, char *buf, size_t len)
{
    int n = t->len > 40 ? 40 : (int)t->len;
    const char *more = t->len > 40 ? "..." : "";
    switch (t->kind) {
    case TOK_EOF: return "end of file";
    case TOK_WORD: snprintf(buf, len, "word '%.*s%s'", n, t->text, more); break;
    case TOK_STRING: snprintf(buf, len, "string \"%.*s%s\"", n, t->text, more); break;
    case TOK_NUMBER: snprintf(buf, len, "number %.*s%s", n, t->text, more); break;
    case TOK_DIRECTIVE: snprintf(buf, len, "directive '%.*s%s'", n, t->text, more); break;
    default: snprintf(buf, len, "'%c'", t->text[0]); break;
    }
    return buf;
}

/* ------------------------------------------------------------------------
 * Parser helpers: item vectors and a per-dictionary key index
 * ---------------------------------------------------------------------- */
typedef struct vec {
    mf_value **items;
    size_t n, cap;
} vec;

static int vec_push(vec *v, mf_value *x)
{
    if (v->n == v->cap) {
        size_t cap = v->cap ? 2 * v->cap : 1; /* most entries hold one item */
        if (mf_resize(&v->items, cap, sizeof *v->items)) {
            mf_value_free(x);
            return MF_ERR_MEMORY;
        }
        v->cap = cap;
    }
    v->items[v->n++] = x;
    return 0;
}

static void vec_free(vec *v)
{
    for (size_t k = 0; k < v->n; k++)
        mf_value_free(v->items[k]);
    free(v->items);
    memset(v, 0, sizeof *v);
}

/* OpenFOAM's rule is that a repeated key replaces the earlier entry. A
 * linear search per entry would make a dictionary of a million keys
 * quadratic, so each dictionary being parsed has a hash index of its keys
 * (entry position + 1 per slot; 0 is empty). */
typedef struct key_index {
    mf_hashmap map; /* hash_bytes of a key -> the entry's position (a hash may repeat) */
    size_t count;
} key_index;

static uint64_t hash_bytes(const char *s, size_t n)
{
    uint64_t h = 1469598103934665603ull; /* FNV-1a */
    for (size_t k = 0; k < n; k++) {
        h ^= (unsigned char)s[k];
        h *= 1099511628211ull;
    }
    return h;
}

static mf_entry *index_find(const key_index *ix, const mf_dict *d, const char *key, size_t len)
{
    const mf_hashmap *m = &ix->map;
    if (!m->cap)
        return NULL;
    const uint64_t h = hash_bytes(key, len);
    for (size_t s = mf_hashmap_home(m, h); m->val[s] != MF_HASHMAP_EMPTY;
         s = mf_hashmap_next(m, s)) {
        if (m->key[s] != h)
            continue;
        mf_entry *e = d->entries[m->val[s]];
        /* key holds no NUL, so strncmp stops at a shorter entry key */
        if (strncmp(e->key, key, len) == 0 && e->key[len] == '\0')
            return e;
    }
    return NULL;
}

static int index_add(key_index *ix, const mf_dict *d, size_t pos)
{
    if (2 * (ix->count + 1) > ix->map.cap && mf_hashmap_grow(&ix->map) != 0)
        return MF_ERR_MEMORY;
    const char *key = d->entries[pos]->key;
    mf_hashmap_put_new(&ix->map, hash_bytes(key, strlen(key)), (uint32_t)pos);
    ix->count++;
    return 0;
}

static void index_free(key_index *ix)
{
    mf_hashmap_free(&ix->map);
    ix->count = 0;
}

/* Set `key` in d to the items (taken from v, which is left empty). */
static int add_entry(mf_dict *d, key_index *ix, const token *key, vec *v)
{
    mf_entry *e = index_find(ix, d, key->text, key->len);
    size_t n = v->n;
    mf_value **items = v->items;
    memset(v, 0, sizeof *v);
    if (e) {
        mf_entry_replace(e, key->loc, n, items);
        return 0;
    }
    char *name = strndup(key->text, key->len);
    if (!name) {
        vec tmp = { items, n, n };
        vec_free(&tmp);
        return out_of_memory(key->loc.file);
    }
    e = mf_dict_append(d, name, key->loc, n, items); /* frees items on failure */
    free(name);
    if (!e || index_add(ix, d, d->n - 1) != 0)
        return out_of_memory(key->loc.file);
    return 0;
}

static int token_value(const token *t, mf_value **out)
{
    static const mf_value_kind kind[] = {
        [TOK_WORD] = MF_VAL_WORD, [TOK_STRING] = MF_VAL_STRING, [TOK_NUMBER] = MF_VAL_NUMBER
    };
    mf_value *v = mf_value_new(kind[t->kind], t->loc);
    if (!v || !(v->text = strndup(t->text, t->len))) {
        mf_value_free(v);
        return out_of_memory(t->loc.file);
    }
    v->number = t->number;
    v->is_integer = t->is_integer;
    *out = v;
    return 0;
}

/* ------------------------------------------------------------------------
 * Parser
 * ---------------------------------------------------------------------- */
typedef struct parser {
    mf_dict *root;
    int include_depth;
    int n_open;
    /* real paths of the files being read, outermost first: a file met
     * again while it is still open is an include cycle */
    char *open_files[MF_DICT_MAX_INCLUDE_DEPTH + 2];
} parser;

static int parse_entries(parser *P, lexer *lx, mf_dict *d, key_index *ix, int depth,
                         const token *open);
static int parse_list(parser *P, lexer *lx, mf_dict *d, const token *open, int depth,
                      mf_value **out);

static int too_deep(const token *open)
{
    return syntax_error(open->loc, "dictionaries and lists nested deeper than %d levels",
                        MF_DICT_MAX_DEPTH);
}

/* At the end of the file with a '{' or '(' still open. The message is
 * placed at the opening, which is the one place known to be involved. */
static int never_closed(const token *open, const token *eof)
{
    return syntax_error(open->loc, "'%c' opened at %d:%d is never closed (the file ends at %d:%d)",
                        open->text[0], open->loc.line, open->loc.col, eof->loc.line,
                        eof->loc.col);
}

static int key_len(const token *key)
{
    return key->len > 60 ? 60 : (int)key->len;
}

/* `name { ... }` (or `{ ... }` in a list): a dictionary value at `depth`,
 * the '{' already read. */
static int parse_braced(parser *P, lexer *lx, mf_dict *parent, const char *name, size_t name_len,
                        mf_loc name_loc, const token *brace, int depth, mf_value **out)
{
    if (depth > MF_DICT_MAX_DEPTH)
        return too_deep(brace);
    /* Both the value and the dictionary are placed at the name (at the
     * '{' for an unnamed one): that is the line a reader looks for. */
    mf_value *v = mf_value_new(MF_VAL_DICT, name_loc);
    char *dict_name = strndup(name, name_len);
    if (!v || !dict_name || !(v->dict = mf_dict_new(dict_name, parent))) {
        free(dict_name);
        mf_value_free(v);
        return out_of_memory(lx->file);
    }
    free(dict_name);
    v->dict->loc = name_loc;
    key_index ix = { 0 };
    int rc = parse_entries(P, lx, v->dict, &ix, depth, brace);
    index_free(&ix);
    if (rc) {
        mf_value_free(v);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    *out = v;
    return 0;
}

static int misplaced_directive(const token *t, const char *where)
{
    if (t->len == 8 && memcmp(t->text, "#include", 8) == 0)
        return syntax_error(t->loc, "#include must stand between entries, not inside %s", where);
    return syntax_error(t->loc, "unsupported directive '%.*s' (only #include is supported)",
                        key_len(t), t->text);
}

/* `( ... )` at `depth`, the '(' already read. */
static int parse_list(parser *P, lexer *lx, mf_dict *d, const token *open, int depth,
                      mf_value **out)
{
    if (depth > MF_DICT_MAX_DEPTH)
        return too_deep(open);
    vec items = { 0 };
    token t, brace;
    const token *peek = NULL;
    char found[128];
    int rc;
    for (;;) {
        rc = next_token(lx, &t);
        if (rc || t.kind == TOK_RPAREN)
            break;
        mf_value *v = NULL;
        switch (t.kind) {
        case TOK_WORD:
            rc = peek_token(lx, &peek);
            if (!rc && peek->kind == TOK_LBRACE) {
                next_token(lx, &brace);
                rc = parse_braced(P, lx, d, t.text, t.len, t.loc, &brace, depth + 1, &v);
            } else if (!rc) {
                rc = token_value(&t, &v);
            }
            break;
        case TOK_STRING:
        case TOK_NUMBER: rc = token_value(&t, &v); break;
        case TOK_LBRACE: rc = parse_braced(P, lx, d, "", 0, t.loc, &t, depth + 1, &v); break;
        case TOK_LPAREN: rc = parse_list(P, lx, d, &t, depth + 1, &v); break;
        case TOK_EOF: rc = never_closed(open, &t); break;
        case TOK_DIRECTIVE: rc = misplaced_directive(&t, "a list"); break;
        default:
            rc = syntax_error(t.loc, "expected ')' to close the list opened at %d:%d, found %s",
                              open->loc.line, open->loc.col, describe(&t, found, sizeof found));
            break;
        }
        if (rc)
            break;
        if ((rc = vec_push(&items, v)) != 0) {
            rc = out_of_memory(lx->file);
            break;
        }
    }
    if (rc) {
        vec_free(&items);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    mf_value *list = mf_value_new(MF_VAL_LIST, open->loc);
    if (!list) {
        vec_free(&items);
        return out_of_memory(lx->file);
    }
    list->n = items.n;
    list->items = items.items;
    *out = list;
    return 0;
}

/* The line where a ';' is probably missing, for the hint in messages. */
static int missing_semicolon_line(const token *key, const vec *items, const token *found)
{
    /* Before a '{' the last item is most likely the next dictionary's name:
     * the ';' belongs before it. */
    size_t last = items->n - (found->kind == TOK_LBRACE && items->n > 1 ? 2 : 1);
    if (found->kind == TOK_LBRACE && items->n == 1)
        return key->loc.line;
    return items->items[last]->loc.line;
}

/* The items of `key item item ... ;`, up to and including the ';'. */
static int parse_values(parser *P, lexer *lx, mf_dict *d, const token *key, int depth, vec *items)
{
    token t;
    char found[128];
    for (;;) {
        mf_value *v = NULL;
        MF_CALL(next_token(lx, &t));
        switch (t.kind) {
        case TOK_SEMI:
            if (items->n == 0)
                return syntax_error(key->loc, "key '%.*s' has no value: expected a value "
                                              "before ';'",
                                    key_len(key), key->text);
            return 0;
        case TOK_WORD:
        case TOK_STRING:
        case TOK_NUMBER: MF_CALL(token_value(&t, &v)); break;
        case TOK_LPAREN: MF_CALL(parse_list(P, lx, d, &t, depth + 1, &v)); break;
        case TOK_RPAREN:
            return syntax_error(t.loc, "unbalanced ')' in the value of key '%.*s'",
                                key_len(key), key->text);
        case TOK_DIRECTIVE: return misplaced_directive(&t, "a value");
        case TOK_EOF:
            /* Placed at the key: the end of the file says little. */
            if (items->n == 0)
                return syntax_error(key->loc, "expected a value for key '%.*s', found end of "
                                              "file",
                                    key_len(key), key->text);
            return syntax_error(key->loc, "expected ';' after value of key '%.*s', found end "
                                          "of file",
                                key_len(key), key->text);
        default: /* '{' or '}' */
            if (items->n == 0)
                return syntax_error(t.loc, "expected a value for key '%.*s', found %s",
                                    key_len(key), key->text, describe(&t, found, sizeof found));
            return syntax_error(t.loc, "expected ';' after value of key '%.*s', found %s "
                                       "(is a ';' missing at the end of line %d?)",
                                key_len(key), key->text, describe(&t, found, sizeof found),
                                missing_semicolon_line(key, items, &t));
        }
        if (vec_push(items, v) != 0)
            return out_of_memory(lx->file);
    }
}

/* One entry whose key has been read. */
static int parse_entry(parser *P, lexer *lx, mf_dict *d, key_index *ix, int depth,
                       const token *key)
{
    const token *peek = NULL;
    token brace;
    vec items = { 0 };
    MF_CALL(peek_token(lx, &peek));
    if (peek->kind == TOK_LBRACE) {
        mf_value *v;
        next_token(lx, &brace);
        MF_CALL(parse_braced(P, lx, d, key->text, key->len, key->loc, &brace, depth + 1, &v));
        if (vec_push(&items, v) != 0)
            return out_of_memory(lx->file);
        /* `};` is common in OpenFOAM files: one ';' after '}' is allowed. */
        int rc = peek_token(lx, &peek);
        if (rc) {
            vec_free(&items);
            return mf_error_trace(rc, __FILE__, __LINE__, __func__);
        }
        if (peek->kind == TOK_SEMI)
            next_token(lx, &brace);
    } else {
        int rc = parse_values(P, lx, d, key, depth, &items);
        if (rc) {
            vec_free(&items);
            return mf_error_trace(rc, __FILE__, __LINE__, __func__);
        }
    }
    MF_CALL(add_entry(d, ix, key, &items));
    return 0;
}

/* Read a whole file into a NUL-terminated buffer (*out, *len). Returns
 * READ_OK, READ_ERRNO with *err set, READ_NOT_REGULAR (*what names the kind
 * of file), READ_TOO_BIG past the size limit, or READ_NOMEM.
 *
 * Only regular files are read, and their size is known before the first
 * byte is: a FIFO would block forever and /dev/zero never ends. The open
 * is non-blocking so that opening a FIFO with no writer returns at once. */
enum { READ_OK = 0, READ_ERRNO, READ_NOT_REGULAR, READ_TOO_BIG, READ_NOMEM };

static const char *file_kind(mode_t mode)
{
    if (S_ISDIR(mode)) return "a folder";
    if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

static int slurp(const char *path, char **out, size_t *len, int *err, const char **what)
{
    *out = NULL;
    *len = 0;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        *err = errno;
        return READ_ERRNO;
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
        *err = errno;
        close(fd);
        return READ_ERRNO;
    }
    if (!S_ISREG(st.st_mode)) {
        *what = file_kind(st.st_mode);
        close(fd);
        return READ_NOT_REGULAR;
    }
    if ((uintmax_t)st.st_size > MF_DICT_MAX_FILE_BYTES) {
        close(fd);
        return READ_TOO_BIG;
    }
    size_t size = (size_t)st.st_size, n = 0;
    char *buf = malloc(size + 1);
    if (!buf) {
        close(fd);
        return READ_NOMEM;
    }
    /* The size stat gave, no more: a file that grows while it is read is
     * read as it was. */
    while (n < size) {
        ssize_t got = read(fd, buf + n, size - n);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            *err = errno;
            free(buf);
            close(fd);
            return READ_ERRNO;
        }
        if (got == 0)
            break; /* shrank meanwhile: what is there */
        n += (size_t)got;
    }
    close(fd);
    buf[n] = '\0';
    *out = buf;
    *len = n;
    return READ_OK;
}

/* `#include "name"` found at `dir` in the file lx reads: parse the named
 * file's entries into d, as if they stood here. */
static int include_file(parser *P, const lexer *lx, mf_dict *d, key_index *ix, int depth,
                        const token *dir, const token *name)
{
    int nl = key_len(name);
    if (name->len == 0)
        return syntax_error(dir->loc, "#include needs a file name, found \"\"");
    if (P->include_depth >= MF_DICT_MAX_INCLUDE_DEPTH)
        return syntax_error(dir->loc, "#include \"%.*s\": files included more than %d deep "
                                      "(is there an include cycle?)",
                            nl, name->text, MF_DICT_MAX_INCLUDE_DEPTH);
    /* Relative to the including file's directory, as OpenFOAM does. */
    const char *slash = name->text[0] == '/' ? NULL : strrchr(lx->file, '/');
    size_t dir_len = slash ? (size_t)(slash - lx->file) + 1 : 0;
    char *path = malloc(dir_len + name->len + 1);
    if (!path)
        return out_of_memory(lx->file);
    memcpy(path, lx->file, dir_len);
    memcpy(path + dir_len, name->text, name->len);
    path[dir_len + name->len] = '\0';

    int rc = 0, err = 0;
    char *buf = NULL;
    size_t len = 0;
    char *real = realpath(path, NULL);
    if (!real) {
        err = errno;
        rc = syntax_error(dir->loc, "cannot open #include file \"%.*s\" (%s)", nl, name->text,
                          strerror(err));
        goto done;
    }
    for (int k = 0; k < P->n_open; k++) {
        if (strcmp(P->open_files[k], real) == 0) {
            rc = syntax_error(dir->loc, "#include cycle: \"%.*s\" (%s) is already being read",
                              nl, name->text, real);
            goto done;
        }
    }
    const char *kind = NULL;
    switch (slurp(path, &buf, &len, &err, &kind)) {
    case READ_OK: break;
    case READ_ERRNO:
        rc = syntax_error(dir->loc, "cannot open #include file \"%.*s\" (%s)", nl, name->text,
                          strerror(err));
        goto done;
    case READ_NOT_REGULAR:
        rc = syntax_error(dir->loc, "#include file \"%.*s\" is %s, not a regular file: not a "
                                    "dictionary",
                          nl, name->text, kind);
        goto done;
    case READ_TOO_BIG:
        rc = syntax_error(dir->loc, "#include file \"%.*s\" is larger than 1 GiB: not a "
                                    "dictionary",
                          nl, name->text);
        goto done;
    default: rc = out_of_memory(path); goto done;
    }
    const char *file = mf_dict_intern(P->root, path);
    if (!file) {
        rc = out_of_memory(path);
        goto done;
    }
    lexer sub;
    lexer_init(&sub, buf, len, file);
    P->open_files[P->n_open++] = real;
    real = NULL; /* owned by open_files until popped */
    P->include_depth++;
    rc = parse_entries(P, &sub, d, ix, depth, NULL);
    P->include_depth--;
    free(P->open_files[--P->n_open]);
    if (rc) {
        /* Say where the file was included from (the message is one line;
         * the nested includes each add their own). */
        char msg[2048];
        snprintf(msg, sizeof msg, "%s", mf_error_message());
        rc = MF_ERROR(rc, "%s (included from %s:%d:%d)", msg, lx->file, dir->loc.line,
                      dir->loc.col);
    }
done:
    free(real);
    free(buf);
    free(path);
    return rc;
}

static int parse_directive(parser *P, lexer *lx, mf_dict *d, key_index *ix, int depth,
                           const token *dir)
{
    char found[128];
    if (!(dir->len == 8 && memcmp(dir->text, "#include", 8) == 0))
        return syntax_error(dir->loc, "unsupported directive '%.*s' (only #include is supported)",
                            key_len(dir), dir->text);
    token name;
    MF_CALL(next_token(lx, &name));
    if (name.kind != TOK_STRING)
        return syntax_error(name.loc, "expected a quoted file name after #include, found %s",
                            describe(&name, found, sizeof found));
    MF_CALL(include_file(P, lx, d, ix, depth, dir, &name));
    return 0;
}

/* The entries of d up to the '}' matching `open`, or to the end of the
 * file when open is NULL (a file's top level). */
static int parse_entries(parser *P, lexer *lx, mf_dict *d, key_index *ix, int depth,
                         const token *open)
{
    token t;
    char found[128];
    for (;;) {
        MF_CALL(next_token(lx, &t));
        switch (t.kind) {
        case TOK_EOF: return open ? never_closed(open, &t) : 0;
        case TOK_RBRACE:
            if (open)
                return 0;
            return syntax_error(t.loc, "unbalanced '}': there is no open '{' to close");
        case TOK_WORD: MF_CALL(parse_entry(P, lx, d, ix, depth, &t)); break;
        case TOK_DIRECTIVE: MF_CALL(parse_directive(P, lx, d, ix, depth, &t)); break;
        case TOK_RPAREN:
            return syntax_error(t.loc, "unbalanced ')': there is no open '(' to close");
        default:
            return syntax_error(t.loc, "expected a key (a word), found %s",
                                describe(&t, found, sizeof found));
        }
    }
}

/* Parse buf (owned, NUL-terminated) as the file `name`; real is its real
 * path (owned) or NULL. Frees both. */
static int parse_buffer(char *buf, size_t len, const char *name, char *real, mf_dict **out)
{
    *out = NULL;
    parser P = { 0 };
    int rc = 0;
    P.root = mf_dict_new("", NULL);
    const char *file = P.root ? mf_dict_intern(P.root, name) : NULL;
    if (!file) {
        rc = out_of_memory(name);
        goto done;
    }
    P.root->loc = (mf_loc){ file, 1, 1 };
    if (real) {
        P.open_files[P.n_open++] = real;
        real = NULL;
    }
    lexer lx;
    lexer_init(&lx, buf, len, file);
    key_index ix = { 0 };
    rc = parse_entries(&P, &lx, P.root, &ix, 0, NULL);
    index_free(&ix);
    if (rc == 0 && P.root->n == 0)
        rc = syntax_error(P.root->loc, "empty dictionary file: expected at least one entry");
done:
    while (P.n_open > 0)
        free(P.open_files[--P.n_open]);
    free(real);
    free(buf);
    if (rc) {
        mf_dict_free(P.root);
        return rc;
    }
    *out = P.root;
    return 0;
}

int mf_dict_parse_file(const char *path, mf_dict **out)
{
    if (!out)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_dict_parse_file: no output pointer");
    *out = NULL;
    if (!path)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_dict_parse_file: no path");
    char *buf;
    size_t len;
    int err = 0;
    const char *kind = NULL;
    switch (slurp(path, &buf, &len, &err, &kind)) {
    case READ_OK: break;
    case READ_ERRNO:
        return MF_ERROR(MF_ERR_IO, "cannot open dictionary file '%s' (%s)", path, strerror(err));
    case READ_NOT_REGULAR:
        return MF_ERROR(MF_ERR_INPUT, "%s: is %s, not a regular file: not a dictionary", path,
                        kind);
    case READ_TOO_BIG:
        return MF_ERROR(MF_ERR_INPUT, "%s: file is larger than 1 GiB: not a dictionary", path);
    default: return out_of_memory(path);
    }
    /* The real path is only for spotting include cycles; without it a cycle
     * is still stopped one file later, or by the depth limit. */
    MF_CALL(parse_buffer(buf, len, path, realpath(path, NULL), out));
    return 0;
}

int mf_dict_parse_string(const char *text, size_t len, const char *name, mf_dict **out)
{
    if (!out)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_dict_parse_string: no output pointer");
    *out = NULL;
    if (!text && len)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_dict_parse_string: no text");
    if (!name)
        name = "<string>";
    if (len > MF_DICT_MAX_FILE_BYTES)
        return MF_ERROR(MF_ERR_INPUT, "%s: text is larger than 1 GiB: not a dictionary", name);
    /* A private copy: the tokenizer unescapes strings in place. */
    char *buf = malloc(len + 1);
    if (!buf)
        return out_of_memory(name);
    if (len)
        memcpy(buf, text, len);
    buf[len] = '\0';
    MF_CALL(parse_buffer(buf, len, name, NULL, out));
    return 0;
}
