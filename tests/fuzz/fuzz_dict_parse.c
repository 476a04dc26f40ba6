/* fuzz_dict_parse.c: bytes into the dictionary parser (io/dict/dict_parse.c).
 * Any input must end in a tree or a clean error, never a crash, a leak or a
 * hang; an error must carry a message. */
#include <stdlib.h>

#include "fuzz_util.h"
#include "mf_dictio.h"
#include "mf_error.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    mf_dict *d = NULL;
    /* Named inside an empty folder: a relative #include finds nothing. */
    static char name[600];
    if (!name[0])
        snprintf(name, sizeof name, "%s/input", fuzz_tmp_dir());
    int rc = mf_dict_parse_string((const char *)data, size, name, &d);
    if (rc != 0 && (d != NULL || mf_error_message()[0] == '\0'))
        abort(); /* a failure leaves no tree and says why */
    mf_error_clear();
    mf_dict_free(d);
    return 0;
}
