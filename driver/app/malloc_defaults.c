/* malloc_defaults.c: mf_malloc_gives_back (mf_malloc_defaults.h).
 *
 * Why: libsuperlu_dist (Debian's libsuperlu-dist8, linked in through
 * libHYPRE) calls, from an ELF constructor that runs before main,
 *     mallopt(M_MMAP_MAX, 0);  mallopt(M_TRIM_THRESHOLD, -1);
 * (checked with gdb: `break mallopt`, the backtrace ends in _dl_init from
 * libsuperlu_dist.so.8; nothing calls mallopt after main starts). With it
 * glibc never maps a large block on its own and never trims the heap's top,
 * so memory freed by one phase (hypre's AMG set-up, the PPE matrix of the
 * last step, the snapshot's image) stays resident for the rest of the run
 * and every later peak stacks on it. mpsflow never uses SuperLU.
 *
 * The values are glibc's documented defaults (The GNU C Library manual,
 * "Malloc Tunable Parameters", section 3.2.3.7; mallopt(3)):
 *   M_MMAP_MAX       65536      blocks that may be mmapped at once
 *   M_MMAP_THRESHOLD 128*1024   blocks at least this large are mmapped,
 *                               and unmapped (returned) when freed
 *   M_TRIM_THRESHOLD 128*1024   a free top of the heap this large is
 *                               returned to the system
 * Setting any of them turns glibc's dynamic mmap threshold off (it already
 * is: the library's mallopt did so), so the thresholds stay at 128 KiB. */
#include "mf_malloc_defaults.h"

#include <malloc.h>

int mf_malloc_gives_back(void)
{
    int refused = 0;
    refused += mallopt(M_MMAP_MAX, 65536) != 1;
    refused += mallopt(M_MMAP_THRESHOLD, 128 * 1024) != 1;
    refused += mallopt(M_TRIM_THRESHOLD, 128 * 1024) != 1;
    return refused;
}
