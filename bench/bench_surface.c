/* bench_surface: seconds per frame and peak memory of the surface
 * reconstructions (blobby, level set explicit and IMEX) on a dam break
 * frame of about 100,000 particles, at a grid equivalent to 256^3.
 *
 *   bench_surface                    the synthetic frame below, 100,000 particles
 *   bench_surface -n N               N particles
 *   bench_surface -snapshot FILE     a real frame (output/snapshot_NNNNNN.h5 of a 3-D run)
 *   bench_surface -grid G            grid: the tank's volume holds G^3 cells (default 256)
 *   bench_surface -methods 'blobby levelSet imex'   what to run (default all three)
 *   bench_surface -isotropic         levelSet without eq. 32's stretching
 *
 * The synthetic frame: the Martin & Moyce column of bench/cases/damBreak3D
 * (a = 0.25 m wide, 0.5 m high, 0.3 m deep, in a 0.6 x 0.6 x 0.3 m tank),
 * filled at spacing l0 with +-0.1 l0 jitter (an MPS-like disorder), slumped
 * forward by a volume-preserving shear (the foot 0.4 m out at 2 m/s, as the
 * collapsing column early on) with the matching velocities, so that eq. 32
 * stretches the fast particles. Each method does two frames:
 * the frame and the same frame advanced by 1 ms (the level set's second
 * frame is warm-started). Peak memory is the process's resident peak after
 * each method (they run in the order given; blobby first keeps it honest).
 * The paper needed 10 to 30 minutes per frame; the target is under 10 s on
 * 2 cores. OMP_NUM_THREADS sets the threads. Each frame reports wall time
 * and CPU time (getrusage, all threads), and the load average is printed
 * before and after: on a shared machine the wall time alone says little. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "surface/levelset/levelset.h"
#include "mf_dictio.h"
#include "mf_hdf5.h"
#include "mf_run.h"

/* CPU seconds of the process so far, all threads (user + system). */
static double cpu_seconds(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
           (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

static void print_load(const char *when)
{
    double l[3];
    if (getloadavg(l, 3) == 3)
        printf("bench_surface: load average %s: %.2f %.2f %.2f\n", when, l[0], l[1], l[2]);
}

static void die(const char *what)
{
    fprintf(stderr, "bench_surface: %s failed\n", what);
    mf_error_print(stderr);
    exit(EXIT_FAILURE);
}

static double jitter(unsigned long *s)
{
    *s = *s * 6364136223846793005UL + 1442695040888963407UL;
    return (double)(*s >> 11) / (double)(1UL << 53) * 2 - 1;
}

/* The slumping column at time t (seconds after the synthetic frame's 0.1 s). */
static mf_particles *column(size_t n, double t, double *l0_out)
{
    const double a = 0.25, H = 0.5, D = 0.3, U = 2.0; /* U: toe speed, m/s */
    const double l0 = cbrt(a * H * D / (double)n);
    const int nx = (int)floor(a / l0), ny = (int)floor(H / l0), nz = (int)floor(D / l0);
    mf_particles *p = NULL;
    if (mf_particles_create(3, (size_t)nx * ny * nz, &p))
        die("mf_particles_create");
    unsigned long s = 7;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                double x0 = (i + 0.5) * l0, y0 = (j + 0.5) * l0, z0 = (k + 0.5) * l0;
                double ey = y0 / H, foot = (1 - ey) * (1 - ey);
                /* the collapse as a shear, x += U T (1 - y/H)^2: volume (and so
                 * the particle spacing) is kept, as in an incompressible flow;
                 * the foot moves fastest */
                double v[3] = {U * foot, 0, 0};
                double T = 0.1 + t; /* the frame's time since the gate opened */
                double x[3] = {x0 + v[0] * T + 0.1 * l0 * jitter(&s),
                               y0 + 0.1 * l0 * jitter(&s), z0 + 0.1 * l0 * jitter(&s)};
                if (mf_particles_add(p, MF_FLUID, x, v, NULL))
                    die("mf_particles_add");
            }
    *l0_out = l0;
    return p;
}

typedef struct result {
    double seconds[2], cpu[2];
    size_t tris[2];
    double peak_mb;
    ls_stats st[2];
} result;

static result run(const mf_registry *reg, const char *method, const char *coeffs,
                  mf_particles *frames[2], double l0)
{
    mf_dict *d = NULL;
    if (mf_dict_parse_string(coeffs, strlen(coeffs), "bench", &d))
        die("coefficients");
    mf_module m;
    if (mf_module_prepare(reg, MF_KIND_SURFACE, method, d, NULL, NULL, &m))
        die("mf_module_prepare");
    const mf_surface_ops *ops = (const mf_surface_ops *)m.info;
    if (ops->create(m.settings, &m.data))
        die("create");
    mf_log log;
    mf_log_init(&log, stdout, getenv("BENCH_VERBOSE") ? MF_LOG_NORMAL : MF_LOG_QUIET);
    log.progress = false;
    result r;
    memset(&r, 0, sizeof r);
    mf_mesh mesh;
    mf_mesh_init(&mesh);
    for (int f = 0; f < 2; f++) {
        mf_sim sim;
        memset(&sim, 0, sizeof sim);
        sim.dim = 3;
        sim.l0 = l0;
        sim.p = frames[f];
        sim.time = 0.1 + 0.001 * f;
        sim.log = &log;
        double t0 = mf_wall_seconds(), c0 = cpu_seconds();
        if (ops->reconstruct(m.data, &sim, &mesh))
            die(method);
        r.seconds[f] = mf_wall_seconds() - t0;
        r.cpu[f] = cpu_seconds() - c0;
        r.tris[f] = mesh.ntris;
        if (strcmp(method, "levelSet") == 0)
            r.st[f] = ((ls_data *)m.data)->last;
    }
    r.peak_mb = mf_peak_memory() / 1048576.0;
    ops->destroy(m.data);
    mf_module_release(&m);
    mf_mesh_free(&mesh);
    mf_dict_free(d);
    return r;
}

int main(int argc, char **argv)
{
    size_t n = 100000;
    int grid = 256;
    const char *snapshot = NULL, *methods = "blobby levelSet imex";
    bool iso = false;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-n") && i + 1 < argc)
            n = (size_t)atol(argv[++i]);
        else if (!strcmp(argv[i], "-grid") && i + 1 < argc)
            grid = atoi(argv[++i]);
        else if (!strcmp(argv[i], "-snapshot") && i + 1 < argc)
            snapshot = argv[++i];
        else if (!strcmp(argv[i], "-methods") && i + 1 < argc)
            methods = argv[++i];
        else if (!strcmp(argv[i], "-isotropic"))
            iso = true;
        else {
            fprintf(stderr, "usage: bench_surface [-n N] [-grid G] [-snapshot FILE] [-methods "
                            "'blobby levelSet imex'] [-isotropic]\n");
            return 2;
        }
    }
    mf_particles *frames[2];
    double l0;
    if (snapshot) {
        mf_sim sim;
        memset(&sim, 0, sizeof sim);
        if (mf_hdf5_read_snapshot(snapshot, &sim))
            die(snapshot);
        frames[0] = frames[1] = sim.p;
        l0 = sim.l0;
    } else {
        frames[0] = column(n, 0.0, &l0);
        frames[1] = column(n, 0.001, &l0);
    }
    size_t nf = 0;
    for (size_t i = 0; i < frames[0]->n; i++)
        nf += frames[0]->kind[i] == MF_FLUID;
    /* the tank of bench/cases/damBreak3D holds grid^3 cells */
    const double h = cbrt(0.6 * 0.6 * 0.3) / grid;
    printf("bench_surface: %zu fluid particles, l0 = %.4g m; grid spacing %.4g m (the 0.6 x 0.6 "
           "x 0.3 m tank holds %d^3 cells; l0/h = %.2f); %d threads\n",
           nf, l0, h, grid, l0 / h, omp_get_max_threads());
    mf_registry *reg = NULL;
    if (mf_registry_create(&reg) || mf_registry_add(reg, &mf_surface_levelSet.info) ||
        mf_registry_add(reg, &mf_surface_blobby.info))
        die("registry");
    print_load("before");
    char buf[256];
    snprintf(buf, sizeof buf, "%s", methods);
    for (char *save = NULL, *w = strtok_r(buf, " ", &save); w; w = strtok_r(NULL, " ", &save)) {
        char coeffs[256];
        const char *method = !strcmp(w, "blobby") ? "blobby" : "levelSet";
        snprintf(coeffs, sizeof coeffs, "gridSpacing %.17g; %s%s", h,
                 !strcmp(w, "imex") ? "integrator imex; " : "",
                 iso && strcmp(method, "blobby") ? "anisotropic no;" : "");
        result r = run(reg, method, coeffs, frames, l0);
        printf("%-9s frame 1: %6.2f s wall, %6.2f s CPU, %8zu triangles", w, r.seconds[0],
               r.cpu[0], r.tris[0]);
        if (strcmp(method, "levelSet") == 0)
            printf(" (%ld steps, %ld right-hand sides, pseudo-time %.2f%s)", r.st[0].steps,
                   r.st[0].rhs_explicit + r.st[0].rhs_implicit + r.st[0].rhs_jtimes,
                   r.st[0].pseudo_time, r.st[0].converged ? "" : ", NOT converged");
        printf("\n%-9s frame 2: %6.2f s wall, %6.2f s CPU, %8zu triangles", w, r.seconds[1],
               r.cpu[1], r.tris[1]);
        if (strcmp(method, "levelSet") == 0)
            printf(" (warm start: %ld steps, %ld right-hand sides, pseudo-time %.2f%s)",
                   r.st[1].steps, r.st[1].rhs_explicit + r.st[1].rhs_implicit + r.st[1].rhs_jtimes,
                   r.st[1].pseudo_time, r.st[1].converged ? "" : ", NOT converged");
        printf("\n%-9s peak resident memory of the process so far: %.0f MB\n", w, r.peak_mb);
    }
    print_load("after");
    mf_registry_destroy(reg);
    mf_particles_destroy(frames[0]);
    if (frames[1] != frames[0])
        mf_particles_destroy(frames[1]);
    return 0;
}
