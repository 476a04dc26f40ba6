/* mf_hash.h: splitmix64's mix of one word (the hash of mf_hashmap.h) and a
 * 64-bit running hash of words (fingerprints: a matrix pattern, the
 * particles a set of matrix rows stands for). */
#ifndef MF_HASH_H
#define MF_HASH_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdint.h>

#define MF_HASH_START 0xcbf29ce484222325ull

/* splitmix64's finaliser: consecutive keys (neighbouring cells, bricks,
 * lattice points) land far apart in a hash table (mf_hashmap.h). */
static inline uint64_t mf_hash_mix64(uint64_t x)
{
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ULL;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebULL;
    x ^= x >> 31;
    return x;
}

/* One word into the running hash h: splitmix64's finaliser on the word,
 * then an FNV-style combine (word by word: hashing stays a small part of
 * what it fingerprints). */
static inline uint64_t mf_hash_word(uint64_t h, uint64_t v)
{
    return (h ^ mf_hash_mix64(v + 0x9e3779b97f4a7c15ull)) * 0x100000001b3ull;
}

#pragma GCC visibility pop
#endif
