/* fuzz_case.c: the case reader and scene builder on a case folder built from
 * fuzzed dictionaries, dry run only (what `mpsflow -dryRun` does: read the
 * case, build the scene, create the modules it names, print the summary).
 *
 * The input is up to four texts separated by NUL bytes (a NUL cannot occur
 * in a dictionary): system/controlDict, system/solverDict, constant/fluids,
 * constant/geometry. A missing text is a small valid default, so that an
 * input can fuzz one file and keep the others sound. The harness appends
 * `maxMemory 0.05;` (GB) to the controlDict: a fuzzed spacing must be
 * refused by the memory estimate, not grow the process. Inputs that name
 * plugins (`libs`) are skipped: loading arbitrary shared libraries is not
 * the reader's business. */
#include <mpi.h>
#include <HYPRE_utilities.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "mf_app.h"
#include "mf_error.h"

static const char *const defaults[4] = {
    "endTime 0.01;\nwriteInterval 0.01;\n",
    "solver MPS;\npressure { solver PCG_BoomerAMG; }\nforces { gravity { g (0 -9.81 0); } }\n",
    "water { rho 1000; nu 1e-6; }\n",
    "dimension 2;\nparticleSpacing 0.02;\n"
    "fluidBlocks { column { type box; min (0 0 0); max (0.1 0.1 0); fluid water; } }\n"
    "walls { tank { type box; min (0 0 0); max (0.2 0.2 0); open (ymax); } }\n",
};
static const char *const files[4] = {"system/controlDict", "system/solverDict",
                                     "constant/fluids", "constant/geometry"};

static mf_registry *reg;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    MPI_Init(argc, argv);
    HYPRE_Init();
    if (mf_registry_create(&reg) != 0 || mf_register_builtins(reg) != 0) {
        mf_error_print(stderr);
        abort();
    }
    /* The dry run's summary goes to stdout: not wanted thousands of times a second. */
    if (!freopen("/dev/null", "w", stdout))
        abort();
    return 0;
}

static bool has(const uint8_t *data, size_t size, const char *word)
{
    size_t n = strlen(word);
    for (size_t k = 0; k + n <= size; k++)
        if (memcmp(data + k, word, n) == 0)
            return true;
    return false;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (has(data, size, "libs"))
        return 0;
    char dir[700];
    snprintf(dir, sizeof dir, "%s/case", fuzz_tmp_dir());
    size_t start = 0;
    for (int k = 0; k < 4; k++) {
        const uint8_t *end = start < size ? memchr(data + start, 0, size - start) : NULL;
        size_t stop = end ? (size_t)(end - data) : size;
        const char *text = start < size ? (const char *)data + start : defaults[k];
        size_t len = start < size ? stop - start : strlen(defaults[k]);
        char *buf = malloc(len + 32);
        if (!buf)
            abort();
        memcpy(buf, text, len);
        if (k == 0) {
            memcpy(buf + len, "\nmaxMemory 0.05;\n", 17);
            len += 17;
        }
        if (!fuzz_write_file(dir, files[k], buf, len))
            abort();
        free(buf);
        start = stop + 1;
    }
    mf_app app;
    memset(&app, 0, sizeof app);
    app.reg = reg;
    app.opt.case_dir = dir;
    app.opt.dry_run = true;
    app.opt.log_level = MF_LOG_QUIET;
    int rc = mf_app_setup(&app);
    if (rc == 0)
        mf_app_summary(&app);
    else if (mf_error_message()[0] == '\0')
        abort(); /* a refusal says why */
    mf_error_clear();
    mf_app_teardown(&app);
    return 0;
}
