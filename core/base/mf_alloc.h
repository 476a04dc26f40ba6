/* mf_alloc.h: growing arrays without losing them. `p = realloc(p, n)` leaks
 * the old block when realloc fails and leaves p NULL; and of several arrays
 * grown to one capacity, those already grown are lost with it. mf_resize
 * keeps the old block on failure: a caller grows every array first, then
 * records the new capacity, so that a failure leaves a consistent (smaller)
 * set behind. */
#ifndef MF_ALLOC_H
#define MF_ALLOC_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stddef.h>

/* Resize the array whose pointer is at `pp` (any T **, passed as void *)
 * to n elements of elem bytes (n = 0 keeps a block of at least one byte).
 * On failure, or when n * elem overflows, *pp is left as it was and
 * MF_ERR_MEMORY is returned with a message. */
int mf_resize(void *pp, size_t n, size_t elem);

/* Give the whole pages inside [ptr, ptr + bytes) back to the system
 * (madvise MADV_DONTNEED) while the array stays allocated: for a scratch
 * array whose contents are dead for a while (the MPS step's across the
 * pressure solve), so that another phase's peak does not stack on it. The
 * released pages read as zeros until written again: the caller must
 * rewrite the contents before it reads them. The partial pages at either
 * end are kept (they may hold the allocator's headers or another block).
 * Arrays under MF_RELEASE_MIN_BYTES are left alone (a system call for a
 * page or two is not worth it). Returns the bytes released: 0 when none, or
 * when the system refused (nothing is lost then but the saving). */
#define MF_RELEASE_MIN_BYTES ((size_t)64 * 1024)
size_t mf_release_pages(void *ptr, size_t bytes);
/* The system's page size in bytes (0 when it cannot say). */
size_t mf_page_size(void);

#pragma GCC visibility pop
#endif
