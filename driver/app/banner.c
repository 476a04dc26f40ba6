/* banner.c: the head of a run's log, with OpenFOAM's field names so that
 * people and log parsers find the same lines (Build, Exec, Date, Time, Host,
 * PID, Case, nProcs). */
#include <limits.h>
#include <mpi.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "mf_app.h"
#include "mf_version.h"

const char *mf_app_version(void)
{
    static char text[128];
    if (!text[0]) {
        if (strcmp(MPSFLOW_BUILD, MPSFLOW_VERSION) == 0)
            snprintf(text, sizeof text, "mpsflow %s", MPSFLOW_VERSION);
        else
            snprintf(text, sizeof text, "mpsflow %s (git %s)", MPSFLOW_VERSION, MPSFLOW_BUILD);
    }
    return text;
}

void mf_app_banner(FILE *f, int argc, char **argv, const char *case_dir)
{
    char host[256] = "", where[PATH_MAX] = "", date[64] = "", clock[64] = "";
    gethostname(host, sizeof host - 1);
    if (!realpath(case_dir, where))
        snprintf(where, sizeof where, "%s", case_dir);
    time_t now = time(NULL);
    struct tm tm;
    localtime_r(&now, &tm);
    strftime(date, sizeof date, "%b %d %Y", &tm);
    strftime(clock, sizeof clock, "%H:%M:%S", &tm);
    int nprocs = 1, initialized = 0;
    MPI_Initialized(&initialized);
    if (initialized)
        MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
    fprintf(f, "/*---------------------------------------------------------------------------*\\\n"
               "  %s: particle fluid solver (MPS, MPS-MAFL, multi-fluid)\n"
               "\\*---------------------------------------------------------------------------*/\n",
            mf_app_version());
    fprintf(f, "Build  : %s\n", MPSFLOW_BUILD);
    fprintf(f, "Exec   :");
    for (int k = 0; k < argc; k++)
        fprintf(f, " %s", argv[k]);
    fprintf(f, "\nDate   : %s\nTime   : %s\nHost   : %s\nPID    : %ld\nCase   : %s\n"
               "nProcs : %d\n\n",
            date, clock, host, (long)getpid(), where, nprocs);
    fflush(f);
}
