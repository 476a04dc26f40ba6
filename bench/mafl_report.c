/* mafl_report.c: error against run time for the MPS-MAFL convection
 * schemes (not a test). Runs tutorials/scalarAdvection with each scheme at
 * several particle spacings (fixed Courant number 0.2: dt = 0.2 l0 / U),
 * scores each run with `mpsflow validate` (RMS error of the carried
 * Gaussian against the exact, shifted profile) and writes
 *   OUT/mafl_scalar_advection.csv   scheme, l0, error, wall seconds, order
 *   OUT/mafl_scalar_advection.png   error against run time, one line per scheme
 * through io/report/mf_report.h.
 *
 *   build/bench/mafl_report MPSFLOW TUTORIAL_DIR OUT_DIR [l0 ...]
 *   (bench/mafl_report.sh runs it with the defaults: l0 = 0.02 0.01 0.005)
 *
 * Each run is single-threaded (OMP_NUM_THREADS=1), so the times compare. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mf_error.h"
#include "mf_report.h"

typedef struct variant {
    const char *label, *coeffs;
} variant;

static const variant variants[] = {
    {"upwind", "scheme upwind; filter no;"},
    {"QUICK", "scheme QUICK; filter no;"},
    {"QUICK + filter", "scheme QUICK; filter yes;"},
    {"QUICK eq. 25 as printed", "scheme QUICK; filter no; streamingTerms no;"},
};
#define NVARIANTS (sizeof variants / sizeof variants[0])
#define MAX_L0 8

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return MF_ERROR(MF_ERR_IO, "%s: cannot write", path);
    fputs(text, f);
    return fclose(f) == 0 ? 0 : MF_ERROR(MF_ERR_IO, "%s: write failed", path);
}

/* One run; error and wall seconds of the mpsflow run (not of validate). */
static int run_one(const char *exe, const char *tutorial, const variant *v, double l0,
                   double *error, double *seconds)
{
    char dir[] = "/tmp/mpsflow-mafl-report-XXXXXX";
    if (!mkdtemp(dir))
        return MF_ERROR(MF_ERR_IO, "mkdtemp failed");
    char cmd[8192], path[4400], text[2048];
    snprintf(cmd, sizeof cmd, "cp -r '%s/system' '%s/constant' '%s/validation' '%s/'", tutorial,
             tutorial, tutorial, dir);
    int rc = system(cmd) == 0 ? 0 : MF_ERROR(MF_ERR_IO, "cannot copy %s", tutorial);
    if (rc == 0) {
        snprintf(cmd, sizeof cmd, "sed -i 's/^deltaT .*/deltaT %.17g;/' '%s/system/controlDict'",
                 0.2 * l0, dir);
        rc = system(cmd) == 0 ? 0 : MF_ERROR(MF_ERR_IO, "cannot edit the controlDict");
    }
    if (rc == 0) {
        snprintf(path, sizeof path, "%s/system/solverDict", dir);
        snprintf(text, sizeof text,
                 "solver MAFL;\nMAFLCoeffs\n{\n    reconfiguration fixed;\n    densityReference "
                 "divergence;\n    convection { %s }\n}\npressure { solver PCG_BoomerAMG; "
                 "tolerance 1e-10; }\n",
                 v->coeffs);
        rc = write_text(path, text);
    }
    if (rc == 0) {
        snprintf(cmd, sizeof cmd, "OMP_NUM_THREADS=1 '%s' -case '%s' -l0 %g -quiet > '%s/log' 2>&1",
                 exe, dir, l0, dir);
        double t0 = now();
        rc = system(cmd) == 0 ? 0 : MF_ERROR(MF_ERR_NUMERIC, "%s at l0 = %g failed (log: %s/log)",
                                             v->label, l0, dir);
        *seconds = now() - t0;
    }
    if (rc == 0) {
        snprintf(cmd, sizeof cmd, "'%s' validate -case '%s' 2>&1", exe, dir);
        FILE *p = popen(cmd, "r");
        *error = NAN;
        char line[512];
        while (p && fgets(line, sizeof line, p))
            if (strncmp(line, "error scalarAdvection = ", 24) == 0)
                *error = strtod(line + 24, NULL);
        if (p)
            pclose(p);
        if (isnan(*error))
            rc = MF_ERROR(MF_ERR_NUMERIC, "%s at l0 = %g: validate gave no error", v->label, l0);
    }
    if (rc == 0) {
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        if (system(cmd) != 0)
            fprintf(stderr, "mafl_report: could not remove %s\n", dir);
    }
    return rc;
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: %s MPSFLOW TUTORIAL_DIR OUT_DIR [l0 ...]\n", argv[0]);
        return 2;
    }
    double l0[MAX_L0] = {0.02, 0.01, 0.005};
    int nl0 = 3;
    if (argc > 4) {
        nl0 = 0;
        for (int k = 4; k < argc && nl0 < MAX_L0; k++)
            l0[nl0++] = atof(argv[k]);
    }
    double err[NVARIANTS][MAX_L0], sec[NVARIANTS][MAX_L0];
    int rc = 0;
    for (size_t v = 0; v < NVARIANTS && rc == 0; v++)
        for (int k = 0; k < nl0 && rc == 0; k++) {
            rc = run_one(argv[1], argv[2], &variants[v], l0[k], &err[v][k], &sec[v][k]);
            if (rc == 0)
                printf("%-24s l0 %-7g error %.4e  run %.2f s\n", variants[v].label, l0[k],
                       err[v][k], sec[v][k]);
        }
    if (rc != 0) {
        mf_error_print(stderr);
        return 1;
    }
    /* CSV: one row per run; the order between consecutive spacings. */
    const size_t nrows = NVARIANTS * (size_t)nl0;
    double *cols[5];
    for (int c = 0; c < 5; c++)
        cols[c] = calloc(nrows, sizeof *cols[c]);
    char header[256], comment[1024], path[4400];
    size_t r = 0;
    for (size_t v = 0; v < NVARIANTS; v++)
        for (int k = 0; k < nl0; k++, r++) {
            cols[0][r] = (double)v;
            cols[1][r] = l0[k];
            cols[2][r] = err[v][k];
            cols[3][r] = sec[v][k];
            cols[4][r] = k ? log(err[v][k - 1] / err[v][k]) / log(l0[k - 1] / l0[k]) : NAN;
        }
    snprintf(header, sizeof header, "scheme,l0,error,run_seconds,order");
    snprintf(comment, sizeof comment,
             "tutorials/scalarAdvection (MPS-MAFL, points fixed), Courant number 0.2, t = 0.3 s\n"
             "error: RMS of the carried Gaussian against the exact shifted profile\n"
             "scheme: 0 %s, 1 %s, 2 %s, 3 %s\n"
             "order: from the row above (same scheme); run_seconds: single-threaded mpsflow",
             variants[0].label, variants[1].label, variants[2].label, variants[3].label);
    snprintf(path, sizeof path, "%s/mafl_scalar_advection.csv", argv[3]);
    const double *const ccols[5] = {cols[0], cols[1], cols[2], cols[3], cols[4]};
    rc = mf_report_csv(path, comment, header, 5, ccols, nrows);
    if (rc == 0) {
        mf_series series[NVARIANTS];
        static const char *const styles[NVARIANTS] = {"linespoints pt 7", "linespoints pt 5",
                                                      "linespoints pt 9", "linespoints pt 11"};
        static char labels[NVARIANTS][MAX_L0][32];
        static const char *label_ptr[NVARIANTS][MAX_L0];
        for (size_t v = 0; v < NVARIANTS; v++) {
            for (int k = 0; k < nl0; k++) {
                snprintf(labels[v][k], sizeof labels[v][k], "l0 %g", l0[k]);
                label_ptr[v][k] = labels[v][k];
            }
            series[v] = (mf_series){variants[v].label, sec[v], err[v], (size_t)nl0, styles[v],
                                    v == 0 ? label_ptr[v] : NULL};
        }
        mf_plot plot = {"scalarAdvection: error against run time", "run time, s (one thread)",
                        "RMS error of the Gaussian", true, true, NULL};
        snprintf(path, sizeof path, "%s/mafl_scalar_advection.png", argv[3]);
        rc = mf_report_plot(path, &plot, series, NVARIANTS);
    }
    for (int c = 0; c < 5; c++)
        free(cols[c]);
    if (rc != 0) {
        mf_error_print(stderr);
        return 1;
    }
    printf("wrote %s/mafl_scalar_advection.csv and .png\n", argv[3]);
    return 0;
}
