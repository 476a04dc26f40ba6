/* mf_malloc_defaults.h: glibc's malloc tuning put back to its defaults. */
#ifndef MF_MALLOC_DEFAULTS_H
#define MF_MALLOC_DEFAULTS_H

/* Restore glibc's documented defaults for M_MMAP_MAX, M_MMAP_THRESHOLD and
 * M_TRIM_THRESHOLD, which a linked library's constructor changed (see
 * malloc_defaults.c). Call it first thing in main, after every constructor
 * ran. Returns 0, or the number of mallopt calls glibc refused (then the
 * tuning is whatever the libraries left: slower to give memory back, not
 * wrong). */
int mf_malloc_gives_back(void);

#endif
