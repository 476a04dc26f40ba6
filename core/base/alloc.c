/* alloc.c: mf_resize, mf_release_pages (mf_alloc.h). */
#include "mf_alloc.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "mf_error.h"

int mf_resize(void *pp, size_t n, size_t elem)
{
    if (elem && n > SIZE_MAX / elem)
        return MF_ERROR(MF_ERR_MEMORY, "%zu elements of %zu bytes: too large", n, elem);
    size_t bytes = n * elem;
    void *old;
    memcpy(&old, pp, sizeof old); /* *pp is a T *: read it as the bytes of a pointer */
    void *grown = realloc(old, bytes ? bytes : 1);
    if (!grown)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory (%zu elements of %zu bytes)", n, elem);
    memcpy(pp, &grown, sizeof grown);
    return 0;
}

size_t mf_page_size(void)
{
    const long ps = sysconf(_SC_PAGESIZE);
    return ps > 0 ? (size_t)ps : 0;
}

size_t mf_release_pages(void *ptr, size_t bytes)
{
    if (!ptr || bytes < MF_RELEASE_MIN_BYTES)
        return 0;
    const uintptr_t page = (uintptr_t)mf_page_size(), start = (uintptr_t)ptr;
    if (page == 0)
        return 0;
    const uintptr_t first = (start + page - 1) / page * page; /* whole pages only */
    const uintptr_t end = (start + bytes) / page * page;
    if (end <= first)
        return 0;
    /* Linux: private anonymous pages (the heap, malloc's mmapped blocks)
     * read as zero-filled pages after MADV_DONTNEED (madvise(2)). */
    if (madvise((void *)first, end - first, MADV_DONTNEED) != 0)
        return 0;
    return end - first;
}
