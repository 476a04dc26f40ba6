/* mf_hashmap.h: the one hash map of the tree, from 64-bit keys to 32-bit
 * values: open addressing with linear probing on a splitmix64 mix of the key,
 * a power-of-two table kept at most half full by its users. Used by the
 * neighbour grid (cell key -> cell), the level set's bricks, the polygon
 * walls' lattice and the dictionary parser's key index (a string's hash ->
 * entries, several per hash). The probe loops are inline: the grid's lookup
 * is on the neighbour search's path. */
#ifndef MF_HASHMAP_H
#define MF_HASHMAP_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mf_hash.h"

#define MF_HASHMAP_EMPTY UINT32_MAX /* the value of a free slot: not a value a map holds */

typedef struct mf_hashmap {
    size_t cap;      /* slots: a power of two, or 0 before the first reset */
    uint64_t *key;   /* cap */
    uint32_t *val;   /* cap; MF_HASHMAP_EMPTY marks a free slot */
} mf_hashmap;

/* The first slot of key's probe sequence, and the one after slot s. */
static inline size_t mf_hashmap_home(const mf_hashmap *m, uint64_t key)
{
    return (size_t)mf_hash_mix64(key) & (m->cap - 1);
}
static inline size_t mf_hashmap_next(const mf_hashmap *m, size_t s)
{
    return (s + 1) & (m->cap - 1);
}

/* The slot holding key, or SIZE_MAX. */
static inline size_t mf_hashmap_find(const mf_hashmap *m, uint64_t key)
{
    if (!m->cap)
        return SIZE_MAX;
    for (size_t s = mf_hashmap_home(m, key); m->val[s] != MF_HASHMAP_EMPTY;
         s = mf_hashmap_next(m, s))
        if (m->key[s] == key)
            return s;
    return SIZE_MAX;
}

/* The value of key, or MF_HASHMAP_EMPTY. One load of the slot's value per
 * probe (the neighbour grid's lookup: no slot index to return). */
static inline uint32_t mf_hashmap_get(const mf_hashmap *m, uint64_t key)
{
    if (!m->cap)
        return MF_HASHMAP_EMPTY;
    const size_t mask = m->cap - 1;
    for (size_t s = (size_t)mf_hash_mix64(key) & mask;; s = (s + 1) & mask) {
        const uint32_t v = m->val[s];
        if (v == MF_HASHMAP_EMPTY || m->key[s] == key)
            return v;
    }
}

/* Store key -> val in the first free slot of key's probe sequence and return
 * the slot. The caller knows key is absent (or keeps several entries per key,
 * as the dictionary's index does) and that a slot is free. */
static inline size_t mf_hashmap_put_new(mf_hashmap *m, uint64_t key, uint32_t val)
{
    size_t s = mf_hashmap_home(m, key);
    while (m->val[s] != MF_HASHMAP_EMPTY)
        s = mf_hashmap_next(m, s);
    m->key[s] = key;
    m->val[s] = val;
    return s;
}

/* Insert key -> val unless key is there. *n is the caller's count of
 * entries (incremented when key is new); the table grows to stay at most half
 * full. *slot receives key's slot, *added whether it was new. */
int mf_hashmap_insert(mf_hashmap *m, size_t *n, uint64_t key, uint32_t val, size_t *slot,
                      bool *added);

/* Empty the map, with at least `slots` slots (rounded up to a power of two,
 * at least 16). The arrays are kept when they hold enough slots and, when
 * slack > 0, no more than slack times the slots asked for. On failure the
 * map is freed (cap 0) and MF_ERR_MEMORY returned. */
int mf_hashmap_reset(mf_hashmap *m, size_t slots, size_t slack);
/* Make every slot free, keeping the arrays. */
void mf_hashmap_clear(mf_hashmap *m);
/* Double the table (16 slots the first time) keeping every entry; on failure the
 * map is unchanged. */
int mf_hashmap_grow(mf_hashmap *m);
void mf_hashmap_free(mf_hashmap *m);
/* Bytes the arrays take. */
size_t mf_hashmap_memory(const mf_hashmap *m);

#pragma GCC visibility pop
#endif
