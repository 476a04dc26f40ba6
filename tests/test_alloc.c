/* test_alloc: memory given back to the system.
 *
 * - mf_release_pages (core/base/mf_alloc.h): the released interior reads as
 *   zeros, the partial pages at the ends keep their bytes, the array stays
 *   usable (written again, read back), the resident size drops, and small
 *   arrays are left alone;
 * - mf_malloc_gives_back (driver/app/malloc_defaults.c), linked with
 *   libHYPRE as mpsflow is (and so with libsuperlu_dist, whose constructor
 *   sets M_MMAP_MAX 0 and M_TRIM_THRESHOLD -1): before it, a large block is
 *   not mmapped and freeing it leaves it resident; after it, a large block
 *   is mmapped and unmapped when freed, and a freed top of the heap is
 *   trimmed. Under AddressSanitizer malloc is the sanitizer's own: those
 *   checks are skipped (said so), the page checks still run. */
#include <HYPRE_IJ_mv.h>
#include <malloc.h>
#include <stdint.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "mf_alloc.h"
#include "mf_malloc_defaults.h"
#include "mf_test.h"

#if defined(__SANITIZE_ADDRESS__)
#define MF_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MF_TEST_ASAN 1
#endif
#endif
#ifndef MF_TEST_ASAN
#define MF_TEST_ASAN 0
#endif

/* Resident bytes of this process (/proc/self/statm, second field). */
static size_t resident_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long size = 0, resident = 0;
    if (!f)
        return 0;
    if (fscanf(f, "%lu %lu", &size, &resident) != 2)
        resident = 0;
    fclose(f);
    return (size_t)resident * (size_t)sysconf(_SC_PAGESIZE);
}

static void fill(double *a, size_t n, double base)
{
    for (size_t i = 0; i < n; i++)
        a[i] = base + (double)i;
}

static void test_release_pages(void)
{
    const size_t page = (size_t)sysconf(_SC_PAGESIZE);
    const size_t n = (8u << 20) / sizeof(double); /* 8 MiB */
    double *a = malloc(n * sizeof *a);
    CHECK(a != NULL);
    if (!a)
        return;
    fill(a, n, 1.0);
    const size_t before = resident_bytes();
    const size_t released = mf_release_pages(a, n * sizeof *a);
    const size_t after = resident_bytes();
    /* all but at most the two partial pages at the ends */
    CHECK_MSG(released + 2 * page >= n * sizeof *a && released <= n * sizeof *a,
              "released %zu of %zu bytes", released, n * sizeof *a);
    CHECK_MSG(before - after >= released / 2, "resident %zu -> %zu bytes after releasing %zu",
              before, after, released);
    /* the released pages are whole pages inside the array; they read as 0,
     * the rest keeps its values */
    const uintptr_t first = ((uintptr_t)a + page - 1) / page * page;
    const uintptr_t end = ((uintptr_t)a + n * sizeof *a) / page * page;
    size_t wrong = 0, zeros = 0;
    for (size_t i = 0; i < n; i++) {
        const uintptr_t at = (uintptr_t)&a[i];
        const int inside = at >= first && at + sizeof *a <= end;
        if (inside)
            zeros += a[i] == 0.0;
        else
            wrong += a[i] != 1.0 + (double)i;
    }
    CHECK_MSG(wrong == 0, "%zu values outside the released pages changed", wrong);
    CHECK_MSG(zeros * sizeof *a == released, "%zu zero values in %zu released bytes", zeros,
              released);
    /* usable again: written, read back */
    fill(a, n, -3.0);
    wrong = 0;
    for (size_t i = 0; i < n; i++)
        wrong += a[i] != -3.0 + (double)i;
    CHECK_MSG(wrong == 0, "%zu values differ after writing the array again", wrong);
    CHECK(resident_bytes() >= after + released / 2); /* resident again once written */
    /* a second release, then a partial rewrite: only what was written is kept */
    CHECK(mf_release_pages(a, n * sizeof *a) == released);
    fill(a, n / 2, 7.0);
    CHECK(a[0] == 7.0 && a[n / 2 - 1] == 7.0 + (double)(n / 2 - 1));
    free(a);
    /* arrays under the threshold are left alone, and NULL is nothing */
    double small[1024];
    fill(small, 1024, 5.0);
    CHECK(MF_RELEASE_MIN_BYTES > sizeof small);
    CHECK(mf_release_pages(small, sizeof small) == 0);
    CHECK(small[0] == 5.0 && small[1023] == 5.0 + 1023.0);
    CHECK(mf_release_pages(NULL, (size_t)1 << 30) == 0);
}

/* The blocks go through this: a compiler may otherwise drop a malloc,
 * memset and free whose memory nobody reads (clang does), and there would
 * be nothing to measure. */
static void *volatile sink;

static void *kept_malloc(size_t bytes)
{
    void *b = malloc(bytes);
    sink = b;
    return sink;
}

/* A 32 MiB block: is it mmapped (mallinfo2's hblkhd), and how much of it
 * stays resident once freed? */
static void large_block(size_t *mapped, size_t *kept)
{
    const size_t bytes = (size_t)32 << 20;
    const size_t base = resident_bytes();
    char *b = kept_malloc(bytes);
    CHECK(b != NULL);
    if (!b)
        return;
    memset(b, 1, bytes);
    *mapped = mallinfo2().hblkhd;
    free(b);
    const size_t now = resident_bytes();
    *kept = now > base ? now - base : 0;
}

/* Many blocks below the mmap threshold, freed: is the heap's top trimmed? */
static size_t small_blocks_kept(void)
{
    enum { count = 512 };
    static char *b[count];
    const size_t base = resident_bytes();
    for (int k = 0; k < count; k++) {
        b[k] = kept_malloc(64 * 1024);
        if (b[k])
            memset(b[k], 1, 64 * 1024);
    }
    for (int k = count - 1; k >= 0; k--)
        free(b[k]);
    const size_t now = resident_bytes();
    return now > base ? now - base : 0;
}

/* What the libraries left (libsuperlu_dist's constructor), in a child so
 * that the parent's heap starts clean for glibc's defaults: a large block
 * not mapped and kept resident once freed, small ones kept too. Returns
 * the child's failed checks. */
static int libraries_tuning(void)
{
    pid_t pid = fork();
    if (pid == 0) {
        size_t mapped = 0, kept = 0;
        large_block(&mapped, &kept);
        const size_t small_kept = small_blocks_kept();
        printf("libraries' tuning: a 32 MiB block %s mmapped, %zu KiB kept resident once freed;"
               " 512 blocks of 64 KiB freed, %zu KiB kept\n",
               mapped ? "is" : "is not", kept >> 10, small_kept >> 10);
        fflush(stdout);
        CHECK_MSG(mapped == 0, "a 32 MiB block was mmapped before mf_malloc_gives_back: "
                  "libsuperlu_dist no longer turns mmap off? (%zu bytes mapped)", mapped);
        CHECK_MSG(kept >= (size_t)16 << 20, "only %zu bytes of a freed 32 MiB block kept", kept);
        _exit(mf_test_failures);
    }
    int status = 0;
    if (pid < 0 || waitpid(pid, &status, 0) != pid || !WIFEXITED(status))
        return 1;
    return WEXITSTATUS(status);
}

static void test_malloc_gives_back(void)
{
    /* libHYPRE (and through it libsuperlu_dist) linked in, as in mpsflow */
    const void *volatile hypre = (const void *)&HYPRE_IJMatrixCreate;
    CHECK(hypre != NULL);
    if (MF_TEST_ASAN) {
        printf("malloc checks skipped: AddressSanitizer's allocator has no mallopt\n");
        return;
    }
    fflush(stdout);
    CHECK_MSG(libraries_tuning() == 0, "the libraries' tuning is not what this test assumes");
    CHECK(mf_malloc_gives_back() == 0);
    size_t mapped = 0, kept = 0;
    large_block(&mapped, &kept);
    const size_t small_kept = small_blocks_kept();
    printf("glibc's defaults: a 32 MiB block %s mmapped, %zu KiB kept resident once freed;"
           " 512 blocks of 64 KiB freed, %zu KiB kept\n",
           mapped ? "is" : "is not", kept >> 10, small_kept >> 10);
    CHECK_MSG(mapped >= (size_t)32 << 20, "a 32 MiB block not mmapped (%zu bytes)", mapped);
    CHECK_MSG(kept < (size_t)1 << 20, "%zu bytes of a freed 32 MiB block still resident", kept);
    CHECK_MSG(small_kept < (size_t)2 << 20, "%zu bytes of 32 MiB freed in small blocks kept",
              small_kept);
}

int main(void)
{
    test_malloc_gives_back(); /* first: the heap as the libraries left it */
    test_release_pages();
    return mf_test_summary("alloc");
}
