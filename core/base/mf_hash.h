/* mf_hash.h: a 64-bit running hash of words (fingerprints: a matrix
 * pattern, the particles a set of matrix rows stands for). */
#ifndef MF_HASH_H
#define MF_HASH_H

#include <stdint.h>

#define MF_HASH_START 0xcbf29ce484222325ull

/* One word into the running hash h: splitmix64's finaliser on the word,
 * then an FNV-style combine (word by word: hashing stays a small part of
 * what it fingerprints). */
static inline uint64_t mf_hash_word(uint64_t h, uint64_t v)
{
    v += 0x9e3779b97f4a7c15ull;
    v = (v ^ (v >> 30)) * 0xbf58476d1ce4e5b9ull;
    v = (v ^ (v >> 27)) * 0x94d049bb133111ebull;
    v ^= v >> 31;
    return (h ^ v) * 0x100000001b3ull;
}

#endif
