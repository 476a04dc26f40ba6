/* test_levelset_cli.c: `mpsflow surface` and the `surface` function object,
 * run as a user runs them.
 *   - snapshots of a sphere (written with mf_hdf5_write_snapshot): blobby
 *     and levelSet frames in postProcessing/surface/, the XDMF index listing
 *     them in time order, -time and -latestTime selecting, the resolved
 *     parameters written;
 *   - ParaView (when pvbatch is installed) opens surface.xdmf and a PLY and
 *     finds the triangles the files hold;
 *   - a snapshot without fluid particles is skipped, said so;
 *   - bad input gives a non-zero exit and a message naming the file: a
 *     snapshot with a NaN position, a zero-byte
 *     snapshot, a grid too fine for the memory limit, a misspelt key in
 *     system/surfaceDict, an unknown method;
 *   - the `surface` function object writes frames at the write times of a
 *     short 3-D dam break.
 * argv[1]: mpsflow; argv[2]: tutorials/damBreak3D. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "case_util.h"
#include "mf_mesh_writer.h"
#include "mf_test.h"

#define L0 0.01

static bool exists(const tc_case *c, const char *rel)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", c->dir, rel);
    struct stat st;
    return stat(path, &st) == 0 && st.st_size > 0;
}

static size_t count_in_file(const tc_case *c, const char *rel, const char *text)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", c->dir, rel);
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    size_t n = 0, len = strlen(text);
    char line[4096];
    while (fgets(line, sizeof line, f))
        for (char *p = line; (p = strstr(p, text)); p += len)
            n++;
    fclose(f);
    return n;
}

/* A snapshot of a sphere of radius R at centre (x, 0, 0); mode 1: no fluid
 * (one wall particle), mode 2: one NaN position. */
static int write_snapshot(const tc_case *c, int index, double time, double x, int mode)
{
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    sim.dim = 3;
    sim.l0 = L0;
    sim.time = time;
    sim.step = index;
    sim.dt = 1e-3;
    if (mf_particles_create(3, 4096, &sim.p) != 0)
        return -1;
    const double v[3] = {0, 0, 0};
    int rc = 0;
    if (mode == 1) {
        const double w[3] = {0, -0.1, 0};
        rc = mf_particles_add(sim.p, MF_WALL, w, v, NULL);
    } else {
        for (int k = -6; k <= 6 && rc == 0; k++)
            for (int j = -6; j <= 6 && rc == 0; j++)
                for (int i = -6; i <= 6 && rc == 0; i++)
                    if (i * i + j * j + k * k <= 36) {
                        double p[3] = {x + i * L0, j * L0, k * L0};
                        if (mode == 2 && i == 0 && j == 0 && k == 0)
                            p[1] = NAN;
                        rc = mf_particles_add(sim.p, MF_FLUID, p, v, NULL);
                    }
    }
    char path[1024];
    snprintf(path, sizeof path, "%s/output", c->dir);
    mkdir(path, 0777);
    snprintf(path, sizeof path, "%s/output/snapshot_%06d.h5", c->dir, index);
    if (rc == 0)
        rc = mf_hdf5_write_snapshot(path, &sim, NULL, 0);
    if (rc != 0)
        mf_error_print(stderr);
    mf_particles_destroy(sim.p);
    return rc;
}

static void expect_failure(tc_case *c, const char *const *args, const char *file,
                           const char *text, const char *what)
{
    int status = tc_case_run(c, "surface", args);
    bool named = tc_case_log_contains(c, file), said = tc_case_log_contains(c, text);
    printf("%s: exit %d, message names %s: %s, says '%s': %s\n", what, status, file,
           named ? "yes" : "no", text, said ? "yes" : "no");
    CHECK_MSG(status != 0, "%s: exit status 0", what);
    CHECK_MSG(named && said, "%s: the message does not name '%s' or say '%s'", what, file, text);
    if (!(named && said))
        tc_case_log_tail(c, 10);
}

/* ParaView opens the index and a PLY (skipped without pvbatch). */
static void paraview_check(const tc_case *c, size_t ntris_last)
{
    if (system("command -v pvbatch > /dev/null 2>&1") != 0) {
        printf("pvbatch not found: ParaView check skipped\n");
        return;
    }
    char script[1024], cmd[4096];
    snprintf(script, sizeof script, "%s/check.py", c->dir);
    FILE *f = fopen(script, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fprintf(f,
            "import sys\n"
            "from paraview.simple import *\n"
            "r = XDMFReader(FileNames=[sys.argv[1]])\n"
            "r.UpdatePipelineInformation()\n"
            "times = list(r.TimestepValues)\n"
            "r.UpdatePipeline(times[-1])\n"
            "d = servermanager.Fetch(r)\n"
            "b = d.GetBlock(0) if d.IsA('vtkMultiBlockDataSet') else d\n"
            "p = PLYReader(FileNames=[sys.argv[2]])\n"
            "p.UpdatePipeline()\n"
            "q = servermanager.Fetch(p)\n"
            "print('PVCHECK', len(times), b.GetNumberOfCells(), q.GetNumberOfCells(), "
            "q.GetPointData().GetNormals() is not None)\n");
    fclose(f);
    snprintf(cmd, sizeof cmd,
             "cd '%s' && timeout 300 pvbatch check.py postProcessing/surface/surface.xdmf "
             "postProcessing/surface/surface_000001.ply > pv.log 2>&1",
             c->dir);
    int rc = system(cmd);
    snprintf(cmd, sizeof cmd, "%s/pv.log", c->dir);
    f = fopen(cmd, "r");
    char line[512];
    long ntimes = -1, cells = -1, plycells = -1;
    char normals[16] = "";
    while (f && fgets(line, sizeof line, f))
        sscanf(line, "PVCHECK %ld %ld %ld %15s", &ntimes, &cells, &plycells, normals);
    if (f)
        fclose(f);
    printf("ParaView: %ld times in surface.xdmf, %ld triangles in the last, PLY %ld triangles, "
           "normals %s (pvbatch exit %d)\n",
           ntimes, cells, plycells, normals, rc);
    CHECK_MSG(ntimes == 2, "ParaView sees %ld times", ntimes);
    CHECK_MSG(cells == (long)ntris_last && plycells == (long)ntris_last,
              "ParaView: %ld and %ld triangles, the files hold %zu", cells, plycells, ntris_last);
    CHECK(strcmp(normals, "True") == 0);
}

static void test_command(const char *exe)
{
    tc_case c;
    if (tc_case_create(&c, exe, "surface") != 0) {
        CHECK(0);
        return;
    }
    CHECK_OK(write_snapshot(&c, 0, 0.0, 0.0, 0));
    CHECK_OK(write_snapshot(&c, 1, 0.1, 0.003, 0));
    /* blobby, every snapshot */
    const char *blobby[] = {"-method", "blobby", NULL};
    int status = tc_case_run(&c, "surface", blobby);
    CHECK_MSG(status == 0, "mpsflow surface -method blobby: exit %d", status);
    if (status != 0)
        tc_case_log_tail(&c, 20);
    CHECK(exists(&c, "postProcessing/surface/surface_000000.ply"));
    CHECK(exists(&c, "postProcessing/surface/surface_000001.obj"));
    CHECK(exists(&c, "postProcessing/surface/surface_000001.h5"));
    CHECK(count_in_file(&c, "postProcessing/surface/surface.xdmf", "<Time Value=") == 2);
    CHECK(count_in_file(&c, "postProcessing/surface/resolvedParameters", "isoValue") == 1);
    /* levelSet on the newest only, parameters from system/surfaceDict */
    CHECK_OK(tc_case_write(&c, "system/surfaceDict",
                           "method levelSet;\nlevelSetCoeffs { gridSpacing 0.004; }\n"
                           "writeOBJ no;\n"));
    char obj1[1024];
    snprintf(obj1, sizeof obj1, "%s/postProcessing/surface/surface_000001.obj", c.dir);
    remove(obj1);
    const char *latest[] = {"-latestTime", NULL};
    status = tc_case_run(&c, "surface", latest);
    CHECK_MSG(status == 0, "mpsflow surface -latestTime: exit %d", status);
    if (status != 0)
        tc_case_log_tail(&c, 20);
    CHECK(tc_case_log_contains(&c, "levelSet ERKStep"));
    CHECK(!exists(&c, "postProcessing/surface/surface_000001.obj")); /* writeOBJ no */
    CHECK(count_in_file(&c, "postProcessing/surface/resolvedParameters", "gridSpacing 0.004") ==
          1);
    mf_mesh m;
    mf_mesh_init(&m);
    char ply[1024];
    snprintf(ply, sizeof ply, "%s/postProcessing/surface/surface_000001.ply", c.dir);
    CHECK_OK(mf_mesh_read_ply(ply, &m));
    printf("levelSet frame of the moved sphere: %zu vertices, %zu triangles\n", m.nverts, m.ntris);
    CHECK(m.ntris > 1000);
    /* -time picks the nearest snapshot */
    const char *at[] = {"-time", "0.01", "-method", "blobby", NULL};
    CHECK(tc_case_run(&c, "surface", at) == 0);
    CHECK(tc_case_log_contains(&c, "snapshot_000000.h5"));
    paraview_check(&c, m.ntris);
    mf_mesh_free(&m);

    /* A snapshot without fluid (a scene that fills over time starts so) is
     * skipped, said so, and the others are done. */
    CHECK_OK(write_snapshot(&c, 2, 0.2, 0.0, 1));
    char frame2[1024], frame1[1024];
    snprintf(frame2, sizeof frame2, "%s/postProcessing/surface/surface_000002.h5", c.dir);
    snprintf(frame1, sizeof frame1, "%s/postProcessing/surface/surface_000001.h5", c.dir);
    remove(frame1);
    const char *t2[] = {"-time", "0.05:0.2", "-method", "blobby", NULL};
    status = tc_case_run(&c, "surface", t2);
    CHECK_MSG(status == 0, "surface over a snapshot without fluid: exit %d", status);
    CHECK(tc_case_log_contains(&c, "snapshot_000002.h5): no fluid yet, skipped"));
    CHECK(tc_case_log_contains(&c, "1 frames (1 snapshot(s) without fluid skipped)"));
    CHECK(access(frame1, F_OK) == 0 && access(frame2, F_OK) != 0);

    /* bad input */
    CHECK_OK(write_snapshot(&c, 3, 0.3, 0.0, 2));
    const char *t3[] = {"-time", "0.3", NULL};
    /* the snapshot reader refuses it already (the module would too: test_levelset.c) */
    expect_failure(&c, t3, "snapshot_000003.h5", "not finite", "snapshot with a NaN");
    CHECK_OK(tc_case_write(&c, "output/snapshot_000004.h5", ""));
    expect_failure(&c, t3, "snapshot_000004.h5", "snapshot_000004.h5", "zero-byte snapshot");
    char zero[1024];
    snprintf(zero, sizeof zero, "%s/output/snapshot_000004.h5", c.dir);
    remove(zero);
    CHECK_OK(tc_case_write(&c, "system/surfaceDict",
                           "levelSetCoeffs { gridSpacing 1e-7; maxMemory 256; }\n"));
    const char *t0[] = {"-time", "0", NULL};
    expect_failure(&c, t0, "snapshot_000000.h5", "too fine", "grid too fine for the memory");
    CHECK_OK(tc_case_write(&c, "system/surfaceDict", "levelSetCoeffs { gridSpacng 0.004; }\n"));
    expect_failure(&c, t0, "surfaceDict", "did you mean 'gridSpacing'", "misspelt key");
    CHECK_OK(tc_case_write(&c, "system/surfaceDict", "method marchingSquares;\n"));
    expect_failure(&c, t0, "marchingSquares", "levelSet", "unknown method");
    tc_case_destroy(&c);
}

static void test_function_object(const char *exe, const char *tutorial)
{
    tc_case c;
    if (tc_case_from_dir(&c, exe, "surface-fo", tutorial) != 0) {
        CHECK(0);
        return;
    }
    CHECK_OK(tc_case_write(&c, TC_CONTROL,
                           "endTime 0.02;\ndeltaT 1e-4;\nadjustTimeStep yes;\nmaxCo 0.2;\n"
                           "maxDeltaT 1e-3;\nwriteControl adjustableRunTime;\n"
                           "writeInterval 0.01;\n"
                           "functions\n{\n    surface\n    {\n        type surface;\n"
                           "        method levelSet;\n"
                           "        levelSetCoeffs { gridSpacing 0.0125; }\n"
                           "        writeOBJ no;\n    }\n}\n"));
    const char *args[] = {"-l0", "0.025", NULL};
    int status = tc_case_run(&c, NULL, args);
    CHECK_MSG(status == 0, "dam break with the surface function object: exit %d", status);
    if (status != 0)
        tc_case_log_tail(&c, 30);
    size_t frames = count_in_file(&c, "postProcessing/surface/surface.xdmf", "<Time Value=");
    printf("function object: %zu frames in postProcessing/surface/surface.xdmf\n", frames);
    CHECK(frames == 3); /* t = 0, 0.01, 0.02 */
    CHECK(exists(&c, "postProcessing/surface/surface_000002.ply"));
    CHECK(tc_case_log_contains(&c, "warm start"));
    tc_case_destroy(&c);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_levelset_cli MPSFLOW TUTORIAL_DAMBREAK3D\n");
        return 2;
    }
    test_command(argv[1]);
    test_function_object(argv[1], argv[2]);
    return mf_test_summary("levelset_cli");
}
