/* surface.c: `mpsflow surface`, the free surface of a case's snapshots.
 *
 *   mpsflow surface [-case DIR] [-time T | -latestTime] [-method levelSet|blobby]
 *
 * Reads system/surfaceDict if the case has one (method, levelSetCoeffs {...},
 * blobbyCoeffs {...}, writePLY, writeOBJ; every key checked against the
 * modules' parameter tables), reconstructs the selected snapshots in time
 * order (the level set warm-starts each from the one before) and writes
 * postProcessing/surface/surface_NNNNNN.{ply,obj,h5} (NNNNNN: the snapshot's
 * index) with the index postProcessing/surface/surface.xdmf, and the
 * parameters used in postProcessing/surface/resolvedParameters.
 *
 * -time takes OpenFOAM's forms: a time (the nearest snapshot), a list
 * "0.1,0.2", or a range "0.1:0.5", ":0.5", "0.5:". Without -time or
 * -latestTime every snapshot is done.
 *
 * `mpirun -np N mpsflow surface -parallel ...` spreads the frames over the
 * ranks: rank r takes the r-th of N consecutive runs of frames (each run
 * warm-starts from its own previous frame, its first frame starts cold),
 * and rank 0 writes the index once every frame is written. */
#include <errno.h>
#include <math.h>
#include <mpi.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "surface/levelset/levelset.h"
#include "mf_app.h"
#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_fs.h"
#include "mf_hdf5.h"
#include "mf_mesh_writer.h"
#include "mf_post.h"
#include "mf_run.h"

int mf_main_surface(int argc, char **argv, int first);

typedef struct surface_opts {
    const char *case_dir;
    const char *time;     /* -time text */
    bool latest;
    const char *method;
    const char *libs;
    int log_level;
    bool parallel;
} surface_opts;

static void surface_usage(FILE *f)
{
    fprintf(f,
            "Usage: mpsflow surface [-case DIR] [-time T | -latestTime] [-method levelSet|blobby]\n"
            "\n"
            "Reconstructs the free surface of the fluid particles in DIR/output/snapshot_*.h5\n"
            "and writes DIR/postProcessing/surface/surface_NNNNNN.{ply,obj,h5} and surface.xdmf\n"
            "(open it in ParaView next to output/particles.xdmf). Parameters: DIR/system/\n"
            "surfaceDict (optional): method; levelSetCoeffs {...}; blobbyCoeffs {...};\n"
            "writePLY yes; writeOBJ yes; (see mpsflow modules levelSet, mpsflow modules blobby).\n"
            "\n"
            "Options:\n"
            "  -case DIR         case directory (default: the current folder)\n"
            "  -time T           a time (nearest snapshot), a list 0.1,0.2 or a range 0.1:0.5\n"
            "  -latestTime       only the newest snapshot\n"
            "  -method NAME      levelSet (eqs. 29-32) or blobby (fast preview), overriding\n"
            "                    system/surfaceDict\n"
            "  -libs '(...)'     plugin libraries to load\n"
            "  -parallel         under mpirun -np N: the frames spread over the N ranks\n"
            "  -quiet, -verbose  less or more log\n"
            "  -help             this text\n");
}

static int parse(int argc, char **argv, int first, surface_opts *o)
{
    static const char *const known[] = {"-case", "-time", "-latestTime", "-method", "-libs",
                                        "-quiet", "-verbose", "-help", "-parallel"};
    for (int i = first; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-help") || !strcmp(a, "--help") || !strcmp(a, "-h"))
            return 1;
        if (!strcmp(a, "-latestTime")) {
            o->latest = true;
        } else if (!strcmp(a, "-parallel")) {
            o->parallel = true;
        } else if (!strcmp(a, "-quiet")) {
            o->log_level = MF_LOG_QUIET;
        } else if (!strcmp(a, "-verbose")) {
            o->log_level = MF_LOG_VERBOSE;
        } else if (!strcmp(a, "-case") || !strcmp(a, "-time") || !strcmp(a, "-method") ||
                   !strcmp(a, "-libs")) {
            if (i + 1 >= argc)
                return MF_ERROR(MF_ERR_INPUT, "option %s needs a value (see mpsflow surface -help)",
                                a);
            const char *v = argv[++i];
            if (!strcmp(a, "-case"))
                o->case_dir = v;
            else if (!strcmp(a, "-time"))
                o->time = v;
            else if (!strcmp(a, "-method"))
                o->method = v;
            else
                o->libs = v;
        } else {
            const char *hint = mf_did_you_mean(a, known, sizeof known / sizeof known[0]);
            return MF_ERROR(MF_ERR_INPUT, "unknown option '%s'%s%s%s (see mpsflow surface -help)",
                            a, hint ? "; did you mean '" : "", hint ? hint : "",
                            hint ? "'?" : "");
        }
    }
    if (o->latest && o->time)
        return MF_ERROR(MF_ERR_INPUT, "-time and -latestTime exclude each other");
    return 0;
}

static int write_resolved(const char *dir, const mf_dict *resolved)
{
    char path[4500];
    snprintf(path, sizeof path, "%s/resolvedParameters", dir);
    mf_replace out;
    MF_CALL(mf_replace_open(&out, path, "w"));
    fprintf(out.f, "// the parameters `mpsflow surface` used, defaults included\n");
    MF_CALL(mf_replace_commit(&out, mf_dict_write(resolved, out.f, 0)));
    return 0;
}

static int run_surface(const surface_opts *o, mf_registry *reg, mf_log *log)
{
    const char *cd = o->case_dir;
    char path[4400], out_dir[4400];
    /* the case's surfaceDict, if any */
    mf_dict *dict = NULL, *resolved = mf_dict_new("", NULL);
    if (!resolved)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    snprintf(path, sizeof path, "%s/system/surfaceDict", cd);
    struct stat st;
    int rc = 0;
    if (stat(path, &st) == 0)
        rc = mf_dict_parse_file(path, &dict);
    int *idx = NULL;
    size_t n = 0;
    double *times = NULL;
    bool *sel = NULL;
    mf_module m = {0};
    surface_settings s;
    mf_mesh mesh;
    mf_mesh_init(&mesh);
    static const char *const extra[] = {"FoamFile", NULL};
    if (rc == 0)
        rc = surface_open(reg, dict, o->method, extra, resolved, &s, &m);
    if (rc == 0)
        rc = mf_snapshot_times(cd, &idx, &times, &n);
    if (rc == 0 && !(sel = calloc(n, sizeof *sel)))
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    if (rc == 0) {
        if (o->latest)
            sel[n - 1] = true;
        else if (o->time)
            rc = mf_select_times(o->time, times, n, sel);
        else
            for (size_t k = 0; k < n; k++)
                sel[k] = true;
    }
    snprintf(out_dir, sizeof out_dir, "%s/postProcessing", cd);
    if (rc == 0)
        rc = mf_mkdir(out_dir);
    snprintf(out_dir, sizeof out_dir, "%s/postProcessing/surface", cd);
    if (rc == 0)
        rc = mf_mkdir(out_dir);
    /* This rank's run of the selected frames: [first, last) of the nsel. */
    int rank = 0, nranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &nranks);
    size_t nsel = 0;
    for (size_t k = 0; k < n; k++)
        nsel += sel && sel[k];
    const size_t first = nsel * (size_t)rank / (size_t)nranks,
                 last = nsel * (size_t)(rank + 1) / (size_t)nranks;
    if (rc == 0 && rank == 0)
        rc = write_resolved(out_dir, resolved);
    const mf_surface_ops *ops = rc == 0 ? (const mf_surface_ops *)m.info : NULL;
    int frames = 0, skipped = 0;
    double t_all = mf_wall_seconds();
    for (size_t k = 0, kth = 0; k < n && rc == 0; k++) {
        if (!sel[k])
            continue;
        if (kth++ < first || kth > last)
            continue;
        mf_snapshot_path(cd, idx[k], path, sizeof path);
        mf_sim sim;
        memset(&sim, 0, sizeof sim);
        sim.log = log;
        sim.reg = reg;
        double t0 = mf_wall_seconds();
        rc = mf_hdf5_read_snapshot(path, &sim);
        size_t counts[MF_NKINDS] = {0};
        if (rc == 0)
            mf_particles_count_kinds(sim.p, counts);
        if (rc == 0 && counts[MF_FLUID] == 0) {
            /* A scene that fills over time starts empty: nothing to mesh yet. */
            mf_log_printf(log, MF_LOG_QUIET, "surface: time %g (%s): no fluid yet, skipped\n",
                          sim.time, path);
            skipped++;
            mf_particles_destroy(sim.p);
            continue;
        }
        if (rc == 0) {
            mf_log_printf(log, MF_LOG_NORMAL, "\nTime = %g  (%s)\n", sim.time, path);
            rc = ops->reconstruct(m.data, &sim, &mesh);
            if (rc != 0)
                rc = MF_ERROR(rc, "%s: %s", path, mf_error_message());
        }
        if (rc == 0)
            rc = mf_mesh_write_frame_files(out_dir, "surface", idx[k], &mesh, s.write_ply,
                                           s.write_obj);
        if (rc == 0 && nranks == 1)
            rc = mf_mesh_write_xdmf_index(out_dir, "surface");
        if (rc == 0) {
            frames++;
            mf_log_printf(log, MF_LOG_NORMAL,
                          "surface: %s/surface_%06d (%zu vertices, %zu triangles), %.2f s\n",
                          out_dir, idx[k], mesh.nverts, mesh.ntris, mf_wall_seconds() - t0);
        }
        mf_particles_destroy(sim.p);
    }
    if (nranks > 1) {
        /* Every rank's frames are written: rank 0 indexes them. */
        int any = rc != 0;
        MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
        MPI_Allreduce(MPI_IN_PLACE, &frames, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
        if (any && rc == 0)
            rc = MF_ERROR(MF_ERR_INPUT, "surface: another rank failed (see its message)");
        if (rc == 0 && rank == 0)
            rc = mf_mesh_write_xdmf_index(out_dir, "surface");
    }
    if (rc == 0)
        mf_log_printf(log, MF_LOG_QUIET,
                      "\nsurface (%s): %d frames (%d snapshot(s) without fluid skipped) in "
                      "%.2f s%s, peak memory %.1f MB; ParaView: open %s/surface.xdmf\nEnd\n",
                      s.method, frames, skipped, mf_wall_seconds() - t_all,
                      nranks > 1 ? " (spread over the ranks)" : "",
                      mf_peak_memory() / 1048576.0, out_dir);
    surface_close(&m);
    mf_mesh_free(&mesh);
    free(idx);
    free(times);
    free(sel);
    mf_dict_free(dict);
    mf_dict_free(resolved);
    return rc;
}

int mf_main_surface(int argc, char **argv, int first)
{
    surface_opts o = {.case_dir = ".", .log_level = MF_LOG_NORMAL};
    int rc = parse(argc, argv, first, &o);
    if (rc == 1) {
        surface_usage(stdout);
        return 0;
    }
    if (rc != 0) {
        mf_error_print(stderr);
        return 2;
    }
    /* HDF5 is Debian's MPI build: start MPI as the other commands do. */
    MPI_Init(&argc, &argv);
    mf_options mo = {.parallel = o.parallel};
    rc = mf_app_check_parallel(&mo, argc, argv);
    if (rc != 0) {
        if (mf_parallel_world_rank() == 0)
            mf_error_print(stderr);
        MPI_Finalize();
        return 2;
    }
    mf_log log;
    mf_log_init(&log, stdout, o.log_level);
    log.progress = false;
    if (mf_parallel_world_rank() != 0)
        log.out = NULL; /* rank 0 writes the log */
    mf_registry *reg = NULL;
    rc = mf_registry_create(&reg);
    if (rc == 0)
        rc = mf_register_builtins(reg);
    if (rc == 0 && o.libs)
        rc = mf_app_load_libs_text(reg, o.libs);
    if (rc == 0)
        rc = run_surface(&o, reg, &log);
    if (rc != 0)
        mf_error_print(stderr);
    mf_registry_destroy(reg);
    MPI_Finalize();
    return rc == 0 ? 0 : 1;
}
