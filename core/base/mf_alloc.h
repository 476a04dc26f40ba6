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

#pragma GCC visibility pop
#endif
