/* test_force_conformance.c: what every registered force must do (the
 * built-ins and the test plugin faultInjection, so a plugin force is among
 * them), each created with its defaults except where a part says:
 *
 *   (i)   side-effect free: on a 2-D and a 3-D particle set (a jittered
 *         fluid blob on a wall strip, random velocities, two fluids), two
 *         calls of accumulate give the same accelerations bit for bit, and
 *         nothing in the sim changes (its fields, the particles and their
 *         fields, byte for byte);
 *   (ii)  internal forces (MF_FORCE_INTERNAL) add no momentum: on fluid
 *         particles alone (jittered, off-centre drops of radius 10 l0 in
 *         2-D and 6 l0 in 3-D; a free surface, and an interface between two
 *         fluids around a core of 6 l0), |sum m a| is at most MOMENTUM_TOL
 *         of sum m |a|;
 *   (iii) its dt limit is respected by every solver: each force with a
 *         stable_dt, in a closed box under gravity run by mpsflow with
 *         -solver MPS, MAFL and multiFluid (adjustTimeStep yes), never gets
 *         a step above its limit, and the limit is reached (it binds); with a
 *         fixed deltaT above it the run says so.
 *
 * argv[1]: mpsflow; argv[2]: the folder holding libfaultInjection.so. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_util.h"
#include "mf_dictio.h"
#include "mf_modules.h"
#include "mf_solvers.h"
#include "mf_test.h"

#define L0 0.01
/* (ii): surfaceTension, eq. 33, is a continuum surface force, not a sum of
 * equal and opposite pair forces: its momentum vanishes because the
 * integral of sigma kappa n over a closed interface is zero, and on
 * particles only up to the error of kappa and n. On lattice drops it is
 * zero to rounding (1e-16); jittered by 0.1 l0 it is 0.5-3% of sum m |a|
 * (docs/validation-and-performance.md has the table), and it does not fall with
 * resolution, since the jitter is noise at the particle scale. The bound
 * catches what breaks the closure (a wrong curvature sign on part of an
 * interface gives tens of per cent), not the discretisation's noise. */
#define MOMENTUM_TOL 0.05
/* (iii): the log prints deltaT with 6 significant digits. */
#define LOG_ROUNDING 1e-5

/* Settings that make a force's dt limit the one that binds in (iii). */
static const char *dt_settings(const char *force)
{
    if (strcmp(force, "surfaceTension") == 0)
        return "dtFactor 0.01;"; /* 4.8e-4 s with water's sigma at l0 = 0.01 m */
    if (strcmp(force, "fault") == 0)
        return "stableDt 4e-4;";
    /* the control forces: 1 / rate = 5e-4 s */
    if (strcmp(force, "attraction") == 0)
        return "velocityAlignment 2000;";
    if (strcmp(force, "velocityRegion") == 0 || strcmp(force, "pathFollow") == 0)
        return "rate 2000;";
    return "";
}

/* ---- particle sets --------------------------------------------------------- */

static unsigned long long rng_state = 12345;
static double uniform(void) /* in [0, 1) */
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

typedef struct world {
    mf_registry *reg;
    mf_log log;
    mf_sim sim;
    int f_fluid;
} world;

/* Fluids: 0 water (sigma 0.07), 1 oil (sigma 0, so the pair's tension is
 * Antonow's 0.07 and the oil's own free surface has none). */
static void world_init(world *w, mf_registry *reg, int dim)
{
    memset(w, 0, sizeof *w);
    w->reg = reg;
    mf_log_init(&w->log, stdout, MF_LOG_QUIET);
    w->sim.dim = dim;
    w->sim.l0 = L0;
    w->sim.reg = reg;
    w->sim.log = &w->log;
    w->sim.nfluids = 2;
    const char *names[2] = {"water", "oil"};
    const double rho[2] = {1000, 800}, sigma[2] = {0.07, 0};
    for (int k = 0; k < 2; k++) {
        snprintf(w->sim.fluid[k].name, sizeof w->sim.fluid[k].name, "%s", names[k]);
        w->sim.fluid[k].rho = rho[k];
        w->sim.fluid[k].nu = 1e-6;
        w->sim.fluid[k].sigma = sigma[k];
    }
    CHECK_OK(mf_particles_create(dim, 4096, &w->sim.p));
    CHECK_OK(mf_neighbours_create(&w->sim.neighbours));
    CHECK_OK(mf_particles_request_field(w->sim.p, "FluidId", 1, MF_FIELD_INT32, true,
                                        &w->f_fluid));
}

static void world_free(world *w)
{
    mf_particles_destroy(w->sim.p);
    w->sim.p = NULL;
    mf_neighbours_destroy(w->sim.neighbours);
    w->sim.neighbours = NULL;
}

static void add(world *w, int kind, int fluid, const double x[3], double speed)
{
    double v[3] = {0, 0, 0};
    if (kind == MF_FLUID)
        for (int c = 0; c < w->sim.dim; c++)
            v[c] = speed * (2 * uniform() - 1);
    CHECK_OK(mf_particles_add(w->sim.p, kind, x, v, NULL));
    mf_particles_fi(w->sim.p, w->f_fluid)[w->sim.p->n - 1] = fluid;
}

/* A blob of fluid particles: the lattice points within the ellipsoid of
 * semi-axes (a, b, b) about c, jittered by up to `jitter` l0; those within
 * the inner ellipsoid (scaled by `core`) are of fluid 1 (core 0: none). */
static void add_blob(world *w, const double c[3], double a, double b, double core, double jitter,
                     double speed)
{
    const int dim = w->sim.dim;
    const int m = (int)ceil(fmax(a, b) / L0) + 1, mz = dim == 3 ? m : 0;
    for (int k = -mz; k <= mz; k++)
        for (int j = -m; j <= m; j++)
            for (int i = -m; i <= m; i++) {
                double x[3] = {i * L0, j * L0, dim == 3 ? k * L0 : 0};
                double q = x[0] * x[0] / (a * a) + (x[1] * x[1] + x[2] * x[2]) / (b * b);
                if (q >= 1)
                    continue;
                for (int d = 0; d < dim; d++)
                    x[d] = c[d] + x[d] + jitter * L0 * (2 * uniform() - 1);
                add(w, MF_FLUID, q < core * core ? 1 : 0, x, speed);
            }
}

/* Two rows of wall particles under the blob and a row of dummies. */
static void add_floor(world *w, double y0, double half)
{
    const int m = (int)ceil(half / L0), mz = w->sim.dim == 3 ? m : 0;
    for (int layer = 0; layer < 3; layer++)
        for (int k = -mz; k <= mz; k++)
            for (int i = -m; i <= m; i++) {
                const double x[3] = {i * L0, y0 - layer * L0, w->sim.dim == 3 ? k * L0 : 0};
                add(w, layer == 0 ? MF_WALL : MF_DUMMY, 0, x, 0);
            }
}

/* ---- a force on a world ------------------------------------------------------ */

static bool create_force(world *w, const mf_module_info *info, const char *text, mf_module *m)
{
    mf_dict *d = NULL;
    if (text && text[0])
        CHECK_OK(mf_dict_parse_string(text, strlen(text), "test", &d));
    int rc = mf_module_prepare(w->reg, MF_KIND_FORCE, info->name, d, NULL, NULL, m);
    const mf_force_ops *ops = (const mf_force_ops *)info;
    if (rc == 0)
        rc = ops->create(m->settings, &w->sim, &m->data);
    mf_dict_free(d);
    CHECK_MSG(rc == 0, "force %s: create failed: %s", info->name, mf_error_message());
    if (rc != 0) {
        mf_error_clear();
        mf_module_release(m);
        return false;
    }
    /* A force that acts through the free-surface pressure runs claimed, as
     * a solver that applies it would have it. */
    if (ops->claim_surface_pressure)
        ops->claim_surface_pressure(m->data);
    return true;
}

static void destroy_force(mf_module *m)
{
    ((const mf_force_ops *)m->info)->destroy(m->data);
    mf_module_release(m);
}

/* A byte copy of everything a force could change in the sim. */
typedef struct snapshot {
    mf_sim sim;
    mf_particles p;
    double *pos, *vel;
    uint8_t *kind;
    int64_t *id;
    void *field[MF_MAX_FIELDS];
} snapshot;

static size_t field_bytes(const mf_field *f, size_t n)
{
    return n * (size_t)f->ncomp * (f->type == MF_FIELD_DOUBLE ? sizeof(double) : sizeof(int32_t));
}

static void *dup(const void *src, size_t n)
{
    void *d = malloc(n ? n : 1);
    if (d)
        memcpy(d, src, n);
    return d;
}

static void take(snapshot *s, const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    s->sim = *sim;
    s->p = *p;
    s->pos = dup(p->pos, 3 * p->n * sizeof *p->pos);
    s->vel = dup(p->vel, 3 * p->n * sizeof *p->vel);
    s->kind = dup(p->kind, p->n);
    s->id = dup(p->id, p->n * sizeof *p->id);
    for (int f = 0; f < p->nfields; f++)
        s->field[f] = dup(p->field[f].data, field_bytes(&p->field[f], p->n));
}

/* Empty when the sim is as the snapshot has it, else what changed. */
static const char *changed(const snapshot *s, const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    if (memcmp(&s->sim, sim, sizeof *sim) != 0)
        return "the mf_sim struct";
    if (memcmp(&s->p, p, sizeof *p) != 0)
        return "the mf_particles struct (counts, fields)";
    if (memcmp(s->pos, p->pos, 3 * p->n * sizeof *p->pos) != 0)
        return "positions";
    if (memcmp(s->vel, p->vel, 3 * p->n * sizeof *p->vel) != 0)
        return "velocities";
    if (memcmp(s->kind, p->kind, p->n) != 0 || memcmp(s->id, p->id, p->n * sizeof *p->id))
        return "kinds or ids";
    for (int f = 0; f < p->nfields; f++)
        if (memcmp(s->field[f], p->field[f].data, field_bytes(&p->field[f], p->n)) != 0)
            return p->field[f].name;
    return "";
}

static void release(snapshot *s)
{
    free(s->pos);
    free(s->vel);
    free(s->kind);
    free(s->id);
    for (int f = 0; f < MF_MAX_FIELDS; f++)
        free(s->field[f]);
    memset(s, 0, sizeof *s);
}

/* ---- (i) side-effect free -------------------------------------------------- */

static void check_pure(mf_registry *reg, const mf_module_info *info, int dim)
{
    world w;
    world_init(&w, reg, dim);
    const double c[3] = {0.003, 0.12, 0};
    add_blob(&w, c, 0.1, 0.07, 0.5, 0.2, 0.3);
    add_floor(&w, 0.04, 0.12);
    mf_module m;
    if (!create_force(&w, info, "", &m)) {
        world_free(&w);
        return;
    }
    const mf_force_ops *ops = (const mf_force_ops *)info;
    const size_t n = w.sim.p->n;
    double *a1 = calloc(3 * n, sizeof *a1), *a2 = calloc(3 * n, sizeof *a2);
    snapshot s;
    memset(&s, 0, sizeof s);
    take(&s, &w.sim);
    CHECK_OK(ops->accumulate(m.data, &w.sim, a1));
    const char *what1 = changed(&s, &w.sim);
    CHECK_OK(ops->accumulate(m.data, &w.sim, a2));
    const char *what2 = changed(&s, &w.sim);
    size_t nonzero = 0;
    for (size_t i = 0; i < 3 * n; i++)
        nonzero += a1[i] != 0;
    const bool same = memcmp(a1, a2, 3 * n * sizeof *a1) == 0;
    printf("  %-16s %d-D, %zu particles: %zu non-zero components; two calls %s; sim %s\n",
           info->name, dim, n, nonzero, same ? "identical" : "DIFFER",
           what1[0] || what2[0] ? "CHANGED" : "unchanged");
    CHECK_MSG(same, "force %s (%d-D): two calls of accumulate differ", info->name, dim);
    CHECK_MSG(!what1[0] && !what2[0], "force %s (%d-D): accumulate changed %s", info->name, dim,
              what1[0] ? what1 : what2);
    release(&s);
    free(a1);
    free(a2);
    destroy_force(&m);
    world_free(&w);
}

/* ---- (ii) internal forces add no momentum -------------------------------------- */

static void check_momentum(mf_registry *reg, const mf_module_info *info, int dim, double core,
                           const char *what)
{
    world w;
    world_init(&w, reg, dim);
    const double c[3] = {0.0037, -0.0021, dim == 3 ? 0.0013 : 0};
    const double R = dim == 3 ? 0.06 : 0.1;
    add_blob(&w, c, R, R, core, 0.1, 0.1);
    mf_module m;
    if (!create_force(&w, info, "", &m)) {
        world_free(&w);
        return;
    }
    const size_t n = w.sim.p->n;
    double *a = calloc(3 * n, sizeof *a), total[3] = {0, 0, 0}, magnitude = 0;
    CHECK_OK(((const mf_force_ops *)info)->accumulate(m.data, &w.sim, a));
    for (size_t i = 0; i < n; i++) {
        const double mass = mf_sim_particle_mass(&w.sim, w.f_fluid, i);
        for (int k = 0; k < 3; k++)
            total[k] += mass * a[3 * i + k];
        magnitude += mass * sqrt(a[3 * i] * a[3 * i] + a[3 * i + 1] * a[3 * i + 1] +
                                 a[3 * i + 2] * a[3 * i + 2]);
    }
    const double net = sqrt(total[0] * total[0] + total[1] * total[1] + total[2] * total[2]);
    printf("  %-16s %d-D %s, %zu fluid particles: |sum m a| = %.3g N, sum m |a| = %.3g N "
           "(ratio %.2e)\n",
           info->name, dim, what, n, net, magnitude, magnitude > 0 ? net / magnitude : 0.0);
    CHECK_MSG(magnitude > 0, "force %s: no force on %s, nothing to check", info->name, what);
    CHECK_MSG(net <= MOMENTUM_TOL * magnitude,
              "internal force %s (%d-D, %s) adds momentum: |sum m a| = %g of sum m |a|",
              info->name, dim, what, net / magnitude);
    free(a);
    destroy_force(&m);
    world_free(&w);
}

/* ---- (iii) the dt limit under every solver ------------------------------------ */

/* The force's limit for the case of (iii): water, l0, the dt settings. */
static double force_limit(mf_registry *reg, const mf_module_info *info)
{
    world w;
    world_init(&w, reg, 2);
    w.sim.nfluids = 1;
    const double x[3] = {0, 0, 0};
    add(&w, MF_FLUID, 0, x, 0);
    mf_module m;
    double dt = INFINITY;
    if (create_force(&w, info, dt_settings(info->name), &m)) {
        CHECK_OK(((const mf_force_ops *)info)->stable_dt(m.data, &w.sim, &dt));
        destroy_force(&m);
    }
    world_free(&w);
    return dt;
}

/* The steps of a run, from its log's `deltaT = ` lines. */
static size_t read_steps(const tc_case *c, double *dt, size_t cap)
{
    char path[600], line[512];
    snprintf(path, sizeof path, "%s/log", c->dir);
    FILE *f = fopen(path, "r");
    size_t n = 0;
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "deltaT = ", 9) == 0 && n < cap)
            dt[n++] = atof(line + 9);
    if (f)
        fclose(f);
    return n;
}

static void check_dt_limit(const char *exe, const char *plugin_dir, mf_registry *reg,
                           const mf_module_info *info, const char *solver, bool fixed)
{
    const double limit = force_limit(reg, info);
    char control[512], solv[1024], tag[64];
    if (fixed)
        snprintf(control, sizeof control,
                 "endTime %.17g;\nadjustTimeStep no;\ndeltaT %.17g;\nwriteInterval 1;\n"
                 "libs (\"libfaultInjection.so\");\n",
                 5 * 2 * limit, 2 * limit);
    else /* starts at a tenth of the limit, grows 20% a step: there by step 13 */
        snprintf(control, sizeof control,
                 "endTime %.17g;\nadjustTimeStep yes;\ndeltaT %.17g;\nmaxCo 1;\nmaxDeltaT 1;\n"
                 "writeInterval 1;\nlibs (\"libfaultInjection.so\");\n",
                 25 * limit, 0.1 * limit);
    snprintf(solv, sizeof solv,
             "solver %s;\nforces { gravity { g (0 -9.81 0); } %s { %s } }\n", solver, info->name,
             dt_settings(info->name));
    static const char *const geometry =
        "dimension 2;\nparticleSpacing 0.01;\n"
        "fluidBlocks { water { type box; min (0 0 0); max (0.15 0.1 0); fluid water; } }\n"
        "walls { box { type box; min (0 0 0); max (0.2 0.2 0); } }\n";
    snprintf(tag, sizeof tag, "dt-%s-%s", info->name, solver);
    tc_case c;
    if (tc_case_from_strings(&c, exe, tag, control, solv,
                             "water { rho 1000; nu 1e-6; sigma 0.07; }\n", geometry) != 0) {
        CHECK(!"case created");
        return;
    }
    setenv("MPSFLOW_PLUGIN_PATH", plugin_dir, 1);
    int status = tc_case_run(&c, NULL, NULL);
    CHECK_MSG(status == 0, "force %s, solver %s: mpsflow exited with %d", info->name, solver,
              status);
    if (status != 0) {
        tc_case_log_tail(&c, 20);
        tc_case_destroy(&c);
        return;
    }
    if (fixed) {
        bool warned = tc_case_log_contains(&c, "above the stable step of");
        printf("  %-16s %-10s fixed deltaT = 2 x its limit: %s\n", info->name, solver,
               warned ? "warned" : "NOT warned");
        CHECK_MSG(warned, "force %s, solver %s: a fixed deltaT above the limit passes silently",
                  info->name, solver);
        tc_case_destroy(&c);
        return;
    }
    static double dt[100000];
    const size_t n = read_steps(&c, dt, sizeof dt / sizeof *dt);
    double dmax = 0;
    for (size_t k = 0; k < n; k++)
        dmax = fmax(dmax, dt[k]);
    printf("  %-16s %-10s %zu steps: largest %.6g s, the force's limit %.6g s\n", info->name,
           solver, n, dmax, limit);
    CHECK_MSG(n >= 15, "force %s, solver %s: only %zu steps logged", info->name, solver, n);
    CHECK_MSG(dmax <= limit * (1 + LOG_ROUNDING), "force %s, solver %s: a step of %g s above its limit "
              "%g s", info->name, solver, dmax, limit);
    CHECK_MSG(dmax >= limit * (1 - LOG_ROUNDING), "force %s, solver %s: the limit %g s never bound "
              "(largest step %g s): the check proves nothing", info->name, solver, limit, dmax);
    tc_case_destroy(&c);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_force_conformance MPSFLOW PLUGIN_DIR\n");
        return 2;
    }
    mf_registry *reg = NULL;
    CHECK_OK(mf_registry_create(&reg));
    CHECK_OK(mf_solvers_register_all(reg));
    mf_registry_set_plugin_dir(reg, argv[2]);
    CHECK_OK(mf_registry_load_plugin(reg, "libfaultInjection.so"));
    const size_t nforces = mf_registry_count(reg, MF_KIND_FORCE);
    printf("%zu registered forces\n", nforces);
    CHECK(nforces >= 4);
    static const char *const solvers[] = {"MPS", "MAFL", "multiFluid"};
    for (size_t k = 0; k < nforces; k++) {
        const mf_module_info *info = mf_registry_at(reg, MF_KIND_FORCE, k);
        const mf_force_ops *ops = (const mf_force_ops *)info;
        printf("force %s%s%s\n", info->name, ops->flags & MF_FORCE_INTERNAL ? " (internal)" : "",
               ops->stable_dt ? " (limits dt)" : "");
        printf(" (i) side-effect free\n");
        check_pure(reg, info, 2);
        check_pure(reg, info, 3);
        if (ops->flags & MF_FORCE_INTERNAL) {
            printf(" (ii) no net momentum\n");
            check_momentum(reg, info, 2, 0, "free surface");
            check_momentum(reg, info, 2, 0.6, "free surface and interface");
            check_momentum(reg, info, 3, 0, "free surface");
        }
        if (ops->stable_dt) {
            printf(" (iii) its dt limit under every solver\n");
            for (size_t s = 0; s < sizeof solvers / sizeof *solvers; s++)
                check_dt_limit(argv[1], argv[2], reg, info, solvers[s], false);
            check_dt_limit(argv[1], argv[2], reg, info, "MPS", true);
        }
    }
    mf_registry_destroy(reg);
    return mf_test_summary("force_conformance");
}
