/* fuzz_util.h: what the fuzz harnesses share (tests/fuzz/README.md).
 *
 * Each harness defines LLVMFuzzerTestOneInput (and may define
 * LLVMFuzzerInitialize). Built with clang -fsanitize=fuzzer it is a
 * libFuzzer target (meson -Dfuzz=true, bench/fuzz.sh); built with
 * replay_main.c it replays a corpus folder under the sanitizers of the tree
 * it is built in (the fuzz_replay_* tests of ./Alltest). A finding is a
 * crash, a sanitizer report, or abort() from a harness's own check. */
#ifndef MF_FUZZ_UTIL_H
#define MF_FUZZ_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mf_dict.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

/* Two trees hold the same keys in the same order with the same values
 * (kinds, texts, numbers bit for bit, integer flags, nested trees). */
bool fuzz_dict_equal(const mf_dict *a, const mf_dict *b);

/* A private folder for the files a harness writes (made once, removed at
 * exit). */
const char *fuzz_tmp_dir(void);
/* Write size bytes to dir/rel (folders made as needed); false on failure. */
bool fuzz_write_file(const char *dir, const char *rel, const void *data, size_t size);

#endif
