/* fuzz_dict_roundtrip.c: parse, write (core/host/dict.c mf_dict_write),
 * parse again: the second tree must equal the first, and writing it again
 * must give the same text. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "mf_dictio.h"
#include "mf_error.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    return 0;
}

static char *write_text(const mf_dict *d, size_t *len)
{
    char *text = NULL;
    FILE *f = open_memstream(&text, len);
    if (!f)
        abort();
    if (mf_dict_write(d, f, 0) != 0) {
        fprintf(stderr, "write failed: %s\n", mf_error_message());
        abort();
    }
    fclose(f);
    return text;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    mf_dict *d = NULL;
    static char name[600];
    if (!name[0])
        snprintf(name, sizeof name, "%s/input", fuzz_tmp_dir());
    if (mf_dict_parse_string((const char *)data, size, name, &d) != 0) {
        mf_error_clear();
        return 0;
    }
    size_t len = 0, len2 = 0;
    char *text = write_text(d, &len);
    mf_dict *back = NULL;
    if (mf_dict_parse_string(text, len, "written", &back) != 0) {
        fprintf(stderr, "the written text does not parse: %s\n%s\n", mf_error_message(), text);
        abort();
    }
    if (!fuzz_dict_equal(d, back)) {
        fprintf(stderr, "the written text parses to another tree:\n%s\n", text);
        abort();
    }
    char *text2 = write_text(back, &len2);
    if (len != len2 || memcmp(text, text2, len) != 0) {
        fprintf(stderr, "writing twice gives two texts:\n%s\n---\n%s\n", text, text2);
        abort();
    }
    free(text);
    free(text2);
    mf_dict_free(back);
    mf_dict_free(d);
    return 0;
}
