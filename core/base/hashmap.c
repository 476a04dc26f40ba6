/* hashmap.c: the allocation side of mf_hashmap.h. */
#include "mf_hashmap.h"

#include <stdlib.h>
#include <string.h>

#include "mf_error.h"

static int slots_for(size_t want, size_t *out)
{
    size_t cap = 16;
    while (cap < want) {
        if (cap > SIZE_MAX / 2 / sizeof(uint64_t))
            return MF_ERROR(MF_ERR_MEMORY, "a hash table of %zu slots is too large", want);
        cap *= 2;
    }
    *out = cap;
    return 0;
}

void mf_hashmap_clear(mf_hashmap *m)
{
    if (m->val) /* all bytes 0xFF: MF_HASHMAP_EMPTY */
        memset(m->val, 0xFF, m->cap * sizeof *m->val);
}

void mf_hashmap_free(mf_hashmap *m)
{
    free(m->key);
    free(m->val);
    memset(m, 0, sizeof *m);
}

int mf_hashmap_reset(mf_hashmap *m, size_t slots, size_t slack)
{
    size_t cap = 0;
    MF_CALL(slots_for(slots, &cap));
    if (!m->key || m->cap < cap || (slack && m->cap > slack * cap)) {
        mf_hashmap_free(m);
        m->key = malloc(cap * sizeof *m->key);
        m->val = malloc(cap * sizeof *m->val);
        if (!m->key || !m->val) {
            mf_hashmap_free(m);
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for a hash table of %zu slots", cap);
        }
        m->cap = cap;
    }
    mf_hashmap_clear(m);
    return 0;
}

int mf_hashmap_grow(mf_hashmap *m)
{
    mf_hashmap g = {0, NULL, NULL};
    MF_CALL(mf_hashmap_reset(&g, m->cap ? 2 * m->cap : 16, 0));
    for (size_t s = 0; s < m->cap; s++)
        if (m->val[s] != MF_HASHMAP_EMPTY)
            mf_hashmap_put_new(&g, m->key[s], m->val[s]);
    mf_hashmap_free(m);
    *m = g;
    return 0;
}

int mf_hashmap_insert(mf_hashmap *m, size_t *n, uint64_t key, uint32_t val, size_t *slot,
                      bool *added)
{
    size_t s = mf_hashmap_find(m, key);
    if (s != SIZE_MAX) {
        *slot = s;
        *added = false;
        return 0;
    }
    if (2 * (*n + 1) > m->cap)
        MF_CALL(mf_hashmap_grow(m));
    *slot = mf_hashmap_put_new(m, key, val);
    *added = true;
    (*n)++;
    return 0;
}

size_t mf_hashmap_memory(const mf_hashmap *m)
{
    return m->cap * (sizeof *m->key + sizeof *m->val);
}
