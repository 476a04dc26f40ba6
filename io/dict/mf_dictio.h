/* mf_dictio.h: reading dictionaries in OpenFOAM syntax into an mf_dict tree.
 *
 * Accepted: an optional `FoamFile { ... }` header (kept as an ordinary
 * sub-dictionary), `key value;`, `key item item ...;`, sub-dictionaries
 * `name { ... }` (a ';' after '}' is allowed, not needed), lists `( ... )`
 * (nestable, and holding `name { ... }` or `{ ... }` dictionaries), words,
 * "strings" (with \" and \\ escapes), numbers, line and block comments, and
 * `#include "file"` (relative to the including file's directory). A repeated
 * key replaces the earlier one. Every error names file:line:col and what
 * was expected.
 *
 * Limits: files up to 1 GiB, dictionaries and lists nested up to 200 deep,
 * #include nested up to 16 deep.
 */
#ifndef MF_DICTIO_H
#define MF_DICTIO_H

#include <stddef.h>

#include "mf_dict.h"

#define MF_DICT_MAX_DEPTH 200
#define MF_DICT_MAX_INCLUDE_DEPTH 16
#define MF_DICT_MAX_FILE_BYTES ((size_t)1 << 30)

/* Parse the file at path into a new tree (*out, free with mf_dict_free).
 * On failure *out is NULL and the status is <0. */
int mf_dict_parse_file(const char *path, mf_dict **out);
/* Parse len bytes of text; name is used in messages and as the base of
 * relative #include paths (its directory part). */
int mf_dict_parse_string(const char *text, size_t len, const char *name, mf_dict **out);

#endif
