/* alloc.c: mf_resize (mf_alloc.h). */
#include "mf_alloc.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

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
