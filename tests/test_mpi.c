/* test_mpi.c: one case on several MPI ranks (`mpirun -np N mpsflow
 * -parallel`) against the serial run, through the mpsflow executable.
 *
 * part "cases": 50 steps at a fixed time step of hydrostatic2D, damBreak2D,
 *   damBreak3D (coarse), scalarAdvection (MPS-MAFL with an inlet and an
 *   outlet), squareDroplet (multiFluid with surface tension), directedSplash
 *   with the three control forces, sloshingTank (an oscillating tank) and
 *   couette2D (a moving lid, the periodic axis, explicit viscosity), serial
 *   and on 2 and 3 ranks. The final snapshots hold the same particles: the same
 *   count of each kind, every id once, and matched by id the same
 *   positions, velocities and pressures within what the pressure solve's
 *   tolerance leaves open (the ranks sum in other orders and hypre's PCG
 *   stops at the tolerance from other rounding: see the bounds below).
 * part "restart": the dam break written on 2 ranks at step 25 and restarted
 *   on 1 and on 3 ends where the straight run on 2 ends, within the same
 *   bounds.
 * part "bodies": rigid bodies moved by the fluid (floatingBox on 1, 2 and 3
 *   ranks and restarted from 2 onto 1 and 3; the corrected gradient's pair
 *   reaction, contact between bodies and with the floor, a disk entering
 *   water, a 3-D box and sphere, each on 2 and 3 ranks): the particles and
 *   every body's trajectory as the serial run's, within the same bounds.
 * part "balance": a start that leaves all the fluid on one rank (system/
 *   decomposeParDict firstPartition none: each rank keeps its share of the
 *   scene in the order it was built, the fluid block first) is rebalanced at
 *   the first step: the log prints the imbalance before and after, and the
 *   one after is below the threshold.
 *
 * argv[1]: mpsflow; argv[2]: the tutorials folder; argv[3]: the part. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "body_cases.h"
#include "case_util.h"
#include "mf_test.h"

static const char *exe, *tutorials;

/* The bounds. Positions move by dt^2 |grad p| / rho a step: a relative
 * pressure difference of e over 50 steps moves a particle by about
 * 50 e dt^2 |grad p|/rho, far below 1e-6 l0 for the solve tolerances here
 * (1e-8 to 1e-10). Pressures themselves differ by what the solve's
 * tolerance allows, relative to the largest pressure: tolerance times the
 * condition of the matrix at most; 1e-5 of the largest pressure holds that
 * with room. Velocities are compared against the largest speed. */
#define POS_BOUND 1e-6 /* of l0 */
#define VEL_BOUND 1e-5 /* of the largest speed (or of 1 mm/s at rest) */
#define PRESSURE_BOUND 1e-5 /* of the largest pressure */
#define FIELD_BOUND 1e-5    /* of each field's largest value */

typedef struct case_spec {
    const char *name; /* tutorial folder */
    double l0;        /* spacing (0: the tutorial's) */
    double dt;        /* fixed step */
    const char *extra_control;
    bool emits;       /* particles are added during the run (matched by position) */
    const char *forces; /* replaces the solverDict's forces block (NULL: the tutorial's) */
} case_spec;

/* The three control forces over the column of directedSplash (0.2 by 0.4 m)
 * within the 50 steps: the attraction's target box and the velocity region
 * overlap it, the path-follow box holds its top; the column is split by the
 * cuts of 2 and 3 ranks, so each force's sums over the fluid reduce across
 * ranks. */
#define CONTROL_FORCES                                                                     \
    "forces {\n gravity { g (0 -9.81 0); }\n"                                              \
    " steer { type attraction; shape box; min (0.1 0.2 0); max (0.4 0.5 0);"               \
    " attraction 150; velocityAlignment 5; influenceRadius 10; }\n"                        \
    " push { type velocityRegion; shape sphere; centre (0.1 0.1 0); radius 0.08;"          \
    " velocity (0.5 0 0); }\n"                                                             \
    " drag { type pathFollow; shape box; min (0 0.3 0); max (0.2 0.42 0);"                 \
    " path { table ((0 (0.1 0.36 0)) (1 (0.5 0.36 0))); } }\n}\n"


static const case_spec cases[] = {
    {"hydrostatic2D", 0.02, 2e-3, "", false, NULL},
    {"damBreak2D", 0.02, 1e-3, "", false, NULL},
    {"damBreak3D", 0.04, 2e-3, "", false, NULL},
    {"scalarAdvection", 0, 2e-3, "", false, NULL},
    {"squareDroplet", 0, 1e-4, "", false, NULL},
    /* The control forces (attraction, velocityRegion, pathFollow). */
    {"directedSplash", 0.02, 1e-3, "", false, CONTROL_FORCES},
    /* Moving walls: the oscillating tank, and the lid of the periodic
     * Couette channel (explicit viscosity: nu dt / l0^2 = 0.1), whose work
     * the watch allows for as 1/2 M u_w^2 summed over the ranks. */
    {"sloshingTank", 0.02, 1e-3, "", false, NULL},
    {"couette2D", 0.01, 1e-5, "", false, NULL},
};

/* The rest of the tutorials (part "more", not in CI: a few minutes): the
 * periodic axis with implicit viscosity, the iterative two-fluid pressure,
 * nozzles, MAFL's inflow with new points, mesh walls with inlets. */
static const case_spec more_cases[] = {
    {"poiseuille2D", 0, 1e-2, "", false, NULL},
    {"waterAirDamBreak", 0, 5e-4, "", false, NULL},
    {"rayleighTaylor", 0, 1e-3, "", false, NULL},
    {"mixingFluids", 0, 1e-3, "", true, NULL},
    {"channelInflow", 0, 2e-3, "", true, NULL},
    {"corridorFlood", 0.14, 2e-3, "", true, NULL},
    {"boxFilling", 0.08, 2e-3, "", true, NULL},
};

/* controlDict: steps fixed steps of dt, a snapshot every write_every. */
static int write_control(const tc_case *c, double dt, long steps, long write_every,
                         const char *extra)
{
    char control[1024];
    snprintf(control, sizeof control,
             "endTime %.17g;\nadjustTimeStep no;\ndeltaT %.17g;\nwriteControl timeStep;\n"
             "writeInterval %ld;\n%s",
             steps * dt, dt, write_every, extra ? extra : "");
    return tc_case_write(c, TC_CONTROL, control);
}

static int make_case(tc_case *c, const case_spec *cs, const char *tag, long steps,
                     long write_every)
{
    char src[1024];
    snprintf(src, sizeof src, "%s/%s", tutorials, cs->name);
    if (tc_case_from_dir(c, exe, tag, src) != 0)
        return -1;
    if (write_control(c, cs->dt, steps, write_every, cs->extra_control) != 0)
        return -1;
    if (!cs->forces)
        return 0;
    char path[1100];
    snprintf(path, sizeof path, "%s/system/solverDict", src);
    char *text = tc_read_text(path), *solver = tc_with_forces(text, cs->forces);
    const int rc = solver ? tc_case_write(c, TC_SOLVER, solver) : -1;
    if (!solver)
        fprintf(stderr, "%s: no forces block to replace\n", path);
    free(text);
    free(solver);
    return rc;
}

static int run(tc_case *c, int np, const case_spec *cs, const char *extra)
{
    char l0[32];
    snprintf(l0, sizeof l0, "%g", cs->l0);
    const char *args[8];
    int n = 0;
    args[n++] = extra && !strcmp(extra, "-verbose") ? "-verbose" : "-quiet";
    if (cs->l0 > 0) {
        args[n++] = "-l0";
        args[n++] = l0;
    }
    if (extra && strcmp(extra, "-verbose") != 0)
        args[n++] = extra;
    args[n] = NULL;
    int status = tc_case_run_np(c, np, NULL, args);
    if (status != 0) {
        fprintf(stderr, "%s on %d ranks: exit status %d\n", cs->name, np, status);
        tc_case_log_tail(c, 30);
    }
    return status;
}

static int load_last(const tc_case *c, mf_sim *sim)
{
    tc_snapshots s;
    if (tc_snapshots_list(c->dir, &s) != 0 || s.n == 0)
        return -1;
    int rc = tc_snapshot_load(c->dir, s.index[s.n - 1], sim, NULL);
    tc_snapshots_free(&s);
    return rc;
}

/* Sort the indices of p's particles by id. */
static const mf_particles *sort_p;
static int cmp_id(const void *a, const void *b)
{
    int64_t x = sort_p->id[*(const size_t *)a], y = sort_p->id[*(const size_t *)b];
    return (x > y) - (x < y);
}

static size_t *order_by_id(const mf_particles *p)
{
    size_t *o = malloc((p->n + 1) * sizeof *o);
    for (size_t i = 0; i < p->n; i++)
        o[i] = i;
    sort_p = p;
    qsort(o, p->n, sizeof *o, cmp_id);
    return o;
}

/* partner[i]: the particle of b that is particle i of a. Ids below
 * id_limit match by id (a scene's particles have the same ids on any number
 * of ranks); particles added during the run (inlets, nozzles, MAFL's new
 * points: each rank hands out its own ids) match the nearest unmatched one
 * of the same kind. SIZE_MAX: no partner. */
static size_t *match(const mf_particles *a, const mf_particles *b, int64_t id_limit,
                     size_t *twice)
{
    size_t *partner = malloc((a->n + 1) * sizeof *partner);
    uint8_t *taken = calloc(b->n + 1, 1);
    size_t *oa = order_by_id(a), *ob = order_by_id(b);
    *twice = 0;
    for (size_t k = 1; k < b->n; k++)
        *twice += b->id[ob[k]] == b->id[ob[k - 1]];
    for (size_t i = 0; i < a->n; i++)
        partner[i] = SIZE_MAX;
    for (size_t ia = 0, ib = 0; ia < a->n && ib < b->n;) {
        const size_t i = oa[ia], j = ob[ib];
        if (a->id[i] >= id_limit || b->id[j] >= id_limit)
            break;
        if (a->id[i] != b->id[j]) {
            a->id[i] < b->id[j] ? ia++ : ib++;
            continue;
        }
        partner[i] = j;
        taken[j] = 1;
        ia++;
        ib++;
    }
    for (size_t i = 0; i < a->n; i++) {
        if (partner[i] != SIZE_MAX || a->id[i] < id_limit)
            continue;
        double best = INFINITY;
        for (size_t j = 0; j < b->n; j++) {
            if (taken[j] || b->kind[j] != a->kind[i] || b->id[j] < id_limit)
                continue;
            double d2 = 0;
            for (int c = 0; c < 3; c++)
                d2 += (a->pos[3 * i + c] - b->pos[3 * j + c]) * (a->pos[3 * i + c] - b->pos[3 * j + c]);
            if (d2 < best) {
                best = d2;
                partner[i] = j;
            }
        }
        if (partner[i] != SIZE_MAX)
            taken[partner[i]] = 1;
    }
    free(oa);
    free(ob);
    free(taken);
    return partner;
}

/* The same particles: counts of each kind, ids once each, and within the
 * bounds the same positions, velocities, pressures and other fields. */
static void compare(const char *what, const mf_sim *ref, const mf_sim *got, double l0,
                    int64_t id_limit)
{
    const mf_particles *a = ref->p, *b = got->p;
    size_t ka[MF_NKINDS], kb[MF_NKINDS];
    mf_particles_count_kinds(a, ka);
    mf_particles_count_kinds(b, kb);
    for (int k = 0; k < MF_NKINDS; k++)
        CHECK_MSG(ka[k] == kb[k], "%s: %zu %s particles, %zu in the serial run", what, kb[k],
                  mf_particle_kind_name(k), ka[k]);
    size_t twice = 0;
    size_t *partner = match(a, b, id_limit, &twice);
    CHECK_MSG(twice == 0, "%s: %zu ids appear twice", what, twice);
    const double *pa = tc_field_d(a, "Pressure"), *pb = tc_field_d(b, "Pressure");
    /* A case at rest or in a uniform flow has (almost) no pressure: then
     * 1 Pa is the scale. */
    double pmax = 1.0, umax = 1e-3;
    for (size_t i = 0; i < a->n; i++) {
        if (pa)
            pmax = fmax(pmax, fabs(pa[i]));
        const double *v = &a->vel[3 * i];
        umax = fmax(umax, sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    }
    double dx = 0, du = 0, dp = 0;
    size_t missing = 0, by_position = 0, worst = SIZE_MAX, worst_p = SIZE_MAX;
    for (size_t i = 0; i < a->n; i++) {
        const size_t j = partner[i];
        if (j == SIZE_MAX) {
            missing++;
            continue;
        }
        by_position += a->id[i] >= id_limit;
        for (int c = 0; c < 3; c++) {
            if (fabs(a->pos[3 * i + c] - b->pos[3 * j + c]) > dx)
                worst = i;
            dx = fmax(dx, fabs(a->pos[3 * i + c] - b->pos[3 * j + c]));
            du = fmax(du, fabs(a->vel[3 * i + c] - b->vel[3 * j + c]));
        }
        if (pa && pb && fabs(pa[i] - pb[j]) > dp) {
            dp = fabs(pa[i] - pb[j]);
            worst_p = i;
        }
    }
    missing += b->n > a->n ? b->n - a->n : 0;
    /* Every other stored field (number density, curvature, transported
     * scalars, ...), against its largest value. */
    double worst_field = 0;
    const char *worst_name = "";
    for (int f = 0; f < a->nfields; f++) {
        const mf_field *fa = &a->field[f];
        int g = mf_particles_field_index(b, fa->name);
        if (fa->type != MF_FIELD_DOUBLE || g < 0 || b->field[g].ncomp != fa->ncomp ||
            !strcmp(fa->name, "Pressure"))
            continue;
        const double *va = fa->data, *vb = b->field[g].data;
        const int nc = fa->ncomp;
        double scale = 0, diff = 0;
        for (size_t i = 0; i < a->n * (size_t)nc; i++)
            scale = fmax(scale, fabs(va[i]));
        for (size_t i = 0; i < a->n; i++)
            if (partner[i] != SIZE_MAX)
                for (int c = 0; c < nc; c++)
                    diff = fmax(diff, fabs(va[(size_t)nc * i + c] -
                                           vb[(size_t)nc * partner[i] + c]));
        const double rel = scale > 0 ? diff / scale : diff;
        if (rel > worst_field) {
            worst_field = rel;
            worst_name = fa->name;
        }
    }
    /* Flags (the free surface of eq. 18): a particle whose n* sits on the
     * threshold beta n0 within rounding may flip between the runs. */
    size_t flipped = 0;
    const int32_t *fa = tc_field_i(a, "Flags"), *fb = tc_field_i(b, "Flags");
    for (size_t i = 0; fa && fb && i < a->n; i++)
        flipped += partner[i] != SIZE_MAX && fa[i] != fb[partner[i]];
    if (flipped)
        printf("    %zu particle(s) with other Flags (free surface) than the serial run\n",
               flipped);
    printf("%s: %zu particles (%zu added during the run, matched by position); max |dx| = "
           "%.3g l0, max |du| = %.3g of %.3g m/s, max |dp| = %.3g of %.3g Pa; other fields "
           "within %.3g (%s)\n",
           what, b->n, by_position, dx / l0, du / umax, umax, dp / pmax, pmax, worst_field,
           worst_name);
    if (dx > POS_BOUND * l0 && worst != SIZE_MAX) {
        const double *x = &a->pos[3 * worst], *y = &b->pos[3 * partner[worst]];
        printf("    farthest apart: %s particle id %lld at (%g %g %g), (%g %g %g) on ranks\n",
               mf_particle_kind_name(a->kind[worst]), (long long)a->id[worst], x[0], x[1], x[2],
               y[0], y[1], y[2]);
    }
    if (dp > PRESSURE_BOUND * pmax && worst_p != SIZE_MAX) {
        const double *na = tc_field_d(a, "NumberDensity"), *nb = tc_field_d(b, "NumberDensity");
        printf("    largest pressure difference: %s particle id %lld at (%g %g %g): %g and %g "
               "Pa, number density %.15g and %.15g\n",
               mf_particle_kind_name(a->kind[worst_p]), (long long)a->id[worst_p],
               a->pos[3 * worst_p], a->pos[3 * worst_p + 1], a->pos[3 * worst_p + 2],
               pa[worst_p], pb[partner[worst_p]], na ? na[worst_p] : 0,
               nb ? nb[partner[worst_p]] : 0);
    }
    CHECK_MSG(missing == 0, "%s: %zu particles in one run only", what, missing);
    CHECK_MSG(dx <= POS_BOUND * l0, "%s: positions differ by %g l0", what, dx / l0);
    CHECK_MSG(du <= VEL_BOUND * umax, "%s: velocities differ by %g of the largest", what,
              du / umax);
    CHECK_MSG(dp <= PRESSURE_BOUND * pmax, "%s: pressures differ by %g of the largest", what,
              dp / pmax);
    CHECK_MSG(worst_field <= FIELD_BOUND, "%s: field %s differs by %g of its largest value", what,
              worst_name, worst_field);
    free(partner);
}

static long nsteps = 50;

static void part_cases(const case_spec *list, size_t ncases)
{
    for (size_t k = 0; k < ncases; k++) {
        const case_spec *cs = &list[k];
        const char *only = getenv("MF_TEST_CASE");
        if (only && strcmp(only, cs->name) != 0)
            continue;
        mf_sim ref;
        memset(&ref, 0, sizeof ref);
        tc_case c;
        if (make_case(&c, cs, cs->name, nsteps, nsteps) != 0 || run(&c, 0, cs, NULL) != 0 ||
            load_last(&c, &ref) != 0) {
            CHECK_MSG(0, "%s: the serial run", cs->name);
            tc_case_destroy(&c);
            continue;
        }
        const double l0 = ref.l0;
        /* The ids the scene handed out: anything at or above was added. */
        int64_t ref_next_id = INT64_MAX;
        tc_snapshots first;
        if (tc_snapshots_list(c.dir, &first) == 0 && first.n > 0) {
            mf_sim s0;
            mf_hdf5_header h0;
            if (tc_snapshot_load(c.dir, first.index[0], &s0, &h0) == 0)
                ref_next_id = h0.next_id;
            tc_sim_free(&s0);
        }
        tc_snapshots_free(&first);
        tc_case_destroy(&c);
        for (int np = 2; np <= 3; np++) {
            char tag[64], what[96];
            snprintf(tag, sizeof tag, "%s-np%d", cs->name, np);
            snprintf(what, sizeof what, "%s on %d ranks", cs->name, np);
            mf_sim got;
            memset(&got, 0, sizeof got);
            if (make_case(&c, cs, tag, nsteps, nsteps) == 0 && run(&c, np, cs, NULL) == 0 &&
                load_last(&c, &got) == 0) {
                char banner[32];
                snprintf(banner, sizeof banner, "nProcs : %d", np);
                CHECK(tc_case_log_contains(&c, banner));
                compare(what, &ref, &got, l0, cs->emits ? ref_next_id : INT64_MAX);
            } else {
                CHECK_MSG(0, "%s: the run", what);
            }
            tc_sim_free(&got);
            tc_case_destroy(&c);
        }
        tc_sim_free(&ref);
    }
}

static void part_restart(void)
{
    const case_spec *cs = &cases[1]; /* damBreak2D */
    tc_case straight, half;
    mf_sim ref;
    memset(&ref, 0, sizeof ref);
    if (make_case(&straight, cs, "restart-straight", 50, 50) != 0 ||
        run(&straight, 2, cs, NULL) != 0 || load_last(&straight, &ref) != 0) {
        CHECK_MSG(0, "the straight run on 2 ranks");
        tc_case_destroy(&straight);
        return;
    }
    tc_case_destroy(&straight);
    for (int np = 1; np <= 3; np += 2) {
        char tag[64], what[96];
        snprintf(tag, sizeof tag, "restart-np%d", np);
        snprintf(what, sizeof what, "written on 2 ranks, restarted on %d", np);
        mf_sim got;
        memset(&got, 0, sizeof got);
        /* 25 steps on 2 ranks (a snapshot at step 25), then to step 50. */
        if (make_case(&half, cs, tag, 25, 25) == 0) {
            int ok = run(&half, 2, cs, NULL) == 0;
            write_control(&half, cs->dt, 50, 25, NULL);
            ok = ok && run(&half, np == 1 ? 0 : np, cs, "-latestTime") == 0 &&
                 load_last(&half, &got) == 0;
            CHECK_MSG(ok, "%s: the runs", what);
            if (ok) {
                /* The second run went on from step 25 (a fresh run would
                 * refuse the output of the first): snapshots 0, 25 and 50. */
                tc_snapshots sn;
                CHECK(tc_snapshots_list(half.dir, &sn) == 0 && sn.n == 3);
                tc_snapshots_free(&sn);
                CHECK(got.step == 50);
                compare(what, &ref, &got, ref.l0, INT64_MAX);
            }
        }
        tc_sim_free(&got);
        tc_case_destroy(&half);
    }
    tc_sim_free(&ref);
}

/* Rigid bodies (issue 18) on 1, 2 and 3 ranks: floatingBox at twice its
 * spacing, 50 steps of 1 ms from the box's release on the water. */
static const case_spec body_case = {"floatingBox", 0.02, 1e-3, "", false, NULL};

#define BODY_COLS 20 /* time, centre, quaternion, velocity, omega, force, torque */

typedef struct body_rows {
    int n;
    double (*r)[BODY_COLS];
} body_rows;

/* The rows of postProcessing/<body>/bodyState.csv (-1: no file). */
static int read_body_rows(const tc_case *c, const char *body, body_rows *out)
{
    char path[700], line[1024];
    snprintf(path, sizeof path, "%s/postProcessing/%s/bodyState.csv", c->dir, body);
    out->n = 0;
    out->r = NULL;
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    int cap = 0;
    while (fgets(line, sizeof line, f)) {
        if (out->n == cap) {
            cap = cap ? 2 * cap : 64;
            void *grown = realloc(out->r, (size_t)cap * sizeof *out->r);
            if (!grown)
                break;
            out->r = grown;
        }
        char *at = line, *end;
        int k = 0;
        for (; k < BODY_COLS; k++, at = end + (*end == ',')) {
            out->r[out->n][k] = strtod(at, &end);
            if (end == at)
                break;
        }
        out->n += k == BODY_COLS; /* the comment and the column names are not rows */
    }
    fclose(f);
    return out->n;
}

/* Body `body`'s trajectory of run b against run a: the same times, and the
 * centre and velocity within the particles' bounds (POS_BOUND of l0,
 * VEL_BOUND of the largest speed) at every step. */
static void compare_body(const char *what, const tc_case *a, const tc_case *b, const char *body,
                         double l0, int expect_rows)
{
    body_rows ra, rb;
    const int na = read_body_rows(a, body, &ra), nb = read_body_rows(b, body, &rb);
    CHECK_MSG(na == expect_rows && nb == expect_rows,
              "%s: %s's bodyState.csv has %d and %d rows, %d expected", what, body, na, nb,
              expect_rows);
    double dx = 0, dv = 0, vmax = 1e-3, dt = 0;
    for (int r = 0; r < na && r < nb; r++) {
        dt = fmax(dt, fabs(ra.r[r][0] - rb.r[r][0]));
        for (int c = 0; c < 3; c++) {
            dx = fmax(dx, fabs(ra.r[r][1 + c] - rb.r[r][1 + c]));
            dv = fmax(dv, fabs(ra.r[r][8 + c] - rb.r[r][8 + c]));
            vmax = fmax(vmax, fabs(ra.r[r][8 + c]));
        }
    }
    const double *end = nb > 0 ? rb.r[nb - 1] : NULL;
    printf("%s: body '%s' over %d rows: max |dx| = %.3g l0, max |dv| = %.3g of %.3g m/s "
           "(centre at the end %.9g %.9g %.9g, velocity %.9g %.9g %.9g)\n",
           what, body, nb, dx / l0, dv / vmax, vmax, end ? end[1] : 0, end ? end[2] : 0,
           end ? end[3] : 0, end ? end[8] : 0, end ? end[9] : 0, end ? end[10] : 0);
    CHECK_MSG(dt <= 1e-9, "%s: the rows' times differ by %g s", what, dt);
    CHECK_MSG(dx <= POS_BOUND * l0, "%s: body %s's centre differs by %g l0", what, body, dx / l0);
    CHECK_MSG(dv <= VEL_BOUND * vmax, "%s: body %s's velocity differs by %g of the largest",
              what, body, dv / vmax);
    free(ra.r);
    free(rb.r);
}

/* The rows of the body's file at the end: the initial state and one a step. */
#define BODY_STEPS 50

static void part_floating_box(void)
{
    const case_spec *cs = &body_case;
    tc_case ref_case;
    mf_sim ref;
    memset(&ref, 0, sizeof ref);
    if (make_case(&ref_case, cs, "bodies-serial", BODY_STEPS, BODY_STEPS) != 0 ||
        run(&ref_case, 0, cs, NULL) != 0 || load_last(&ref_case, &ref) != 0) {
        CHECK_MSG(0, "floatingBox: the serial run");
        tc_case_destroy(&ref_case);
        return;
    }
    const double l0 = ref.l0;
    /* The box moved: a comparison of bodies at rest would prove nothing. */
    body_rows rows;
    const int nr = read_body_rows(&ref_case, "box", &rows);
    CHECK_MSG(nr == BODY_STEPS + 1 && fabs(rows.r[nr - 1][9]) > 0.1,
              "floatingBox serial: %d rows, the box's speed %g m/s at the end", nr,
              nr > 0 ? rows.r[nr - 1][9] : 0);
    free(rows.r);
    for (int np = 1; np <= 3; np++) {
        char tag[64], what[96];
        snprintf(tag, sizeof tag, "bodies-np%d", np);
        snprintf(what, sizeof what, "floatingBox on %d rank%s", np, np > 1 ? "s" : "");
        tc_case c;
        mf_sim got;
        memset(&got, 0, sizeof got);
        if (make_case(&c, cs, tag, BODY_STEPS, BODY_STEPS) == 0 && run(&c, np, cs, NULL) == 0 &&
            load_last(&c, &got) == 0) {
            compare(what, &ref, &got, l0, INT64_MAX);
            compare_body(what, &ref_case, &c, "box", l0, BODY_STEPS + 1);
        } else {
            CHECK_MSG(0, "%s: the run", what);
        }
        tc_sim_free(&got);
        tc_case_destroy(&c);
    }
    /* Written on 2 ranks at step 25, restarted on 1 (serially) and on 3 to
     * step 50: the serial run's particles and trajectory, and the file's rows
     * once each. */
    for (int np = 0; np <= 3; np += 3) {
        char tag[64], what[96];
        snprintf(tag, sizeof tag, "bodies-restart-np%d", np);
        snprintf(what, sizeof what, "floatingBox written on 2 ranks, restarted on %d",
                 np ? np : 1);
        tc_case half;
        mf_sim got;
        memset(&got, 0, sizeof got);
        if (make_case(&half, cs, tag, BODY_STEPS / 2, BODY_STEPS / 2) == 0) {
            int ok = run(&half, 2, cs, NULL) == 0;
            write_control(&half, cs->dt, BODY_STEPS, BODY_STEPS / 2, NULL);
            ok = ok && run(&half, np, cs, "-latestTime") == 0 && load_last(&half, &got) == 0;
            CHECK_MSG(ok, "%s: the runs", what);
            if (ok) {
                CHECK(got.step == BODY_STEPS);
                compare(what, &ref, &got, l0, INT64_MAX);
                compare_body(what, &ref_case, &half, "box", l0, BODY_STEPS + 1);
            }
        }
        tc_sim_free(&got);
        tc_case_destroy(&half);
    }
    tc_sim_free(&ref);
    tc_case_destroy(&ref_case);
}

/* The other paths of the bodies' coupling on N ranks, each case on 2 and
 * 3 ranks against its serial run (particles by id, every body's every
 * row):
 *   momentum   test_bodies' closed box without gravity, the body set moving
 *              in a free blob: the corrected gradient's pair reaction (CMPS)
 *              and the eq. 7 Laplacian's, whose pair terms read the halo
 *              copies' p^ and WallId;
 *   contact    two boxes dropped on the floor of a dry tank, the upper
 *              landing on the lower (0.14 and 0.2 s): body-wall and body-body
 *              contact. Gravity acts on the bodies only (motion g): a puddle
 *              under gravity in a corner, as test_bodies has, amplifies
 *              rounding over the 250 steps (a serial run that only reorders
 *              its particles: 3.8e-6 l0) where the bodies agree to the last
 *              digit; this one stays at rest. Decomposed by load alone
 *              (multiCriteria no), so that the cuts run through both bodies
 *              (measured: 2 ranks hold 21 and 65 of the lower box's 86 outer
 *              particles and 11 and 35 of the upper's 46; 3 ranks 47 and 39,
 *              37 and 9);
 *   waterEntry the tutorial's disk at l0 0.011 m entering the water at
 *              2.955 m/s, 0.03 s: the surface pressure of a round body.
 *              Pressure tolerance 1e-12: at the tutorial's 1e-8 the impact
 *              amplifies the solve's tolerance (hypre's PCG on N ranks,
 *              mpsflow's V-cycle serially) to 2.6e-6 l0 in 0.03 s, beyond
 *              POS_BOUND, as it amplifies a serial run's rounding (the
 *              particles only reordered: 2.1e-6 l0); at 1e-12, 2e-10 l0;
 *   floating3D a box and a sphere (3-D, l0 0.02 m) released half in the
 *              water: the faces of a 3-D box, a sphere's surface.
 * The serial run first shows the physics each comparison is of: the body
 * ends within l0/4 of rest_y where given, and at a speed below max_speed
 * (what the fluid or the contact took off a free body's). */
typedef struct body_check {
    const char *name;
    double rest_y;    /* NAN: not checked */
    double max_speed; /* m/s, at the end */
} body_check;

typedef struct body_spec {
    case_spec cs;     /* name: the tutorial copied, or NULL: from the strings */
    const char *tag;
    long steps;
    const char *solver, *fluids, *geometry, *decompose; /* NULL: the tutorial's, none */
    void (*make_geometry)(char *out, size_t len); /* when geometry is NULL */
    body_check bodies[2];
} body_spec;

/* test_bodies' momentum case, moving at 0.05 m/s (tests/body_cases.h). */
static void momentum_geometry(char *out, size_t len)
{
    tc_momentum_geometry(out, len, 0.01, 0.05);
}

static const char *const water_fluids = "water { rho 1000; nu 1e-4; }\n";

static const body_spec body_specs[] = {
    {{NULL, 0, 1e-3, "", false, NULL}, "momentum", 100, TC_MOMENTUM_SOLVER, NULL, NULL, NULL,
     momentum_geometry, {{"body", NAN, 0.045}, {NULL, 0, 0}}},
    {{NULL, 0, 1e-3, "", false, NULL}, "contact", 250,
     "solver MPS;\npressure { solver PCG_BoomerAMG; tolerance 1e-8; }\n",
     NULL,
     "dimension 2;\nparticleSpacing 0.01;\n"
     "fluidBlocks { water { type box; min (0 0 0); max (0.1 0.05 0); fluid water; } }\n"
     "walls { tank { type box; min (0 0 0); max (0.6 0.5 0); open (ymax); } }\n"
     "obstacles {\n"
     " lower { type box; min (0.15 0.1 0); max (0.55 0.15 0);\n"
     "  motion { type rigid; density 500; g (0 -9.81 0); } }\n"
     " upper { type box; min (0.2 0.25 0); max (0.4 0.3 0);\n"
     "  motion { type rigid; density 500; g (0 -9.81 0); } } }\n",
     "multiCriteria no;\n", NULL,
     {{"lower", 0.025, 0.05}, {"upper", 0.075, 0.05}}},
    {{"waterEntry", 0.011, 2.5e-4, "", false, NULL}, "waterEntry", 120,
     "solver MPS;\npressure { solver PCG_BoomerAMG; tolerance 1e-12; }\n"
     "forces { gravity { g (0 -9.81 0); } }\n",
     NULL, NULL, NULL, NULL,
     {{"cylinder", NAN, 1.5}, {NULL, 0, 0}}},
    {{NULL, 0, 1e-3, "", false, NULL}, "floating3D", 50,
     "solver MPS;\npressure { solver PCG_BoomerAMG; tolerance 1e-8; }\n"
     "forces { gravity { g (0 -9.81 0); } }\n",
     "water { rho 1000; nu 1e-6; }\n",
     "dimension 3;\nparticleSpacing 0.02;\n"
     "fluidBlocks { water { type box; min (0 0 0); max (0.3 0.1 0.2); fluid water; } }\n"
     "walls { tank { type box; min (0 0 0); max (0.3 0.3 0.2); open (ymax); } }\n"
     "obstacles {\n"
     " box { type box; min (0.04 0.1 0.04); max (0.14 0.16 0.16);\n"
     "  motion { type rigid; density 500; g (0 -9.81 0); } }\n"
     " ball { type sphere; centre (0.22 0.14 0.1); radius 0.04;\n"
     "  motion { type rigid; density 500; g (0 -9.81 0); } } }\n",
     NULL, NULL,
     {{"box", NAN, 0.4}, {"ball", NAN, 0.4}}},
};

static int make_body_case(tc_case *c, const body_spec *bs, const char *tag)
{
    int rc;
    if (bs->cs.name) {
        rc = make_case(c, &bs->cs, tag, bs->steps, bs->steps);
    } else {
        char geometry[2048];
        if (!bs->geometry)
            bs->make_geometry(geometry, sizeof geometry);
        rc = tc_case_from_strings(c, exe, tag, NULL, NULL, water_fluids,
                                  bs->geometry ? bs->geometry : geometry);
        rc = rc != 0 ? rc : write_control(c, bs->cs.dt, bs->steps, bs->steps, NULL);
    }
    if (rc == 0 && bs->solver)
        rc = tc_case_write(c, TC_SOLVER, bs->solver);
    if (rc == 0 && bs->fluids)
        rc = tc_case_write(c, TC_FLUIDS, bs->fluids);
    if (rc == 0 && bs->decompose)
        rc = tc_case_write(c, "system/decomposeParDict", bs->decompose);
    return rc;
}

/* The serial run's physics (body_check). */
static void check_serial_bodies(const body_spec *bs, const tc_case *c, double l0)
{
    for (int k = 0; k < 2 && bs->bodies[k].name; k++) {
        const body_check *b = &bs->bodies[k];
        body_rows rows;
        const int n = read_body_rows(c, b->name, &rows);
        CHECK_MSG(n == bs->steps + 1, "%s serial: body %s: %d rows", bs->tag, b->name, n);
        if (n > 0) {
            const double *e = rows.r[n - 1];
            const double speed = sqrt(e[8] * e[8] + e[9] * e[9] + e[10] * e[10]);
            printf("%s serial: body '%s' at t = %g: y = %.5f m, speed %.4g m/s\n", bs->tag,
                   b->name, e[0], e[2], speed);
            CHECK_MSG(speed < b->max_speed, "%s serial: body %s at %g m/s, %g expected below",
                      bs->tag, b->name, speed, b->max_speed);
            if (!isnan(b->rest_y))
                CHECK_MSG(fabs(e[2] - b->rest_y) < 0.25 * l0,
                          "%s serial: body %s at y = %g, resting at %g expected", bs->tag,
                          b->name, e[2], b->rest_y);
        }
        free(rows.r);
    }
}

static void part_body_paths(void)
{
    for (size_t k = 0; k < sizeof body_specs / sizeof body_specs[0]; k++) {
        const body_spec *bs = &body_specs[k];
        const char *only = getenv("MF_TEST_CASE");
        if (only && strcmp(only, bs->tag) != 0)
            continue;
        tc_case ref_case;
        mf_sim ref;
        memset(&ref, 0, sizeof ref);
        char tag[64];
        snprintf(tag, sizeof tag, "bodies-%s", bs->tag);
        if (make_body_case(&ref_case, bs, tag) != 0 || run(&ref_case, 0, &bs->cs, NULL) != 0 ||
            load_last(&ref_case, &ref) != 0) {
            CHECK_MSG(0, "%s: the serial run", bs->tag);
            tc_case_destroy(&ref_case);
            continue;
        }
        const double l0 = ref.l0;
        check_serial_bodies(bs, &ref_case, l0);
        for (int np = 2; np <= 3; np++) {
            char what[96];
            snprintf(tag, sizeof tag, "bodies-%s-np%d", bs->tag, np);
            snprintf(what, sizeof what, "%s on %d ranks", bs->tag, np);
            tc_case c;
            mf_sim got;
            memset(&got, 0, sizeof got);
            if (make_body_case(&c, bs, tag) == 0 && run(&c, np, &bs->cs, NULL) == 0 &&
                load_last(&c, &got) == 0) {
                compare(what, &ref, &got, l0, INT64_MAX);
                for (int b = 0; b < 2 && bs->bodies[b].name; b++)
                    compare_body(what, &ref_case, &c, bs->bodies[b].name, l0,
                                 (int)bs->steps + 1);
            } else {
                CHECK_MSG(0, "%s: the run", what);
            }
            tc_sim_free(&got);
            tc_case_destroy(&c);
        }
        tc_sim_free(&ref);
        tc_case_destroy(&ref_case);
    }
}

static void part_bodies(void)
{
    part_floating_box();
    part_body_paths();
}

/* "Load imbalance X, after rebalancing Y" from the log. */
static bool read_rebalance(const tc_case *c, double *before, double *after)
{
    char path[700], line[1024];
    snprintf(path, sizeof path, "%s/log", c->dir);
    FILE *f = fopen(path, "r");
    bool found = false;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "Rebalanced: load imbalance %lf, now %lf", before, after) == 2) {
            found = true;
            break;
        }
    if (f)
        fclose(f);
    return found;
}

static void part_balance(void)
{
    const case_spec *cs = &cases[1]; /* damBreak2D: the column is one corner of the tank */
    tc_case c;
    if (make_case(&c, cs, "balance", 5, 5) != 0) {
        CHECK(!"case made");
        return;
    }
    tc_case_write(&c, "system/decomposeParDict",
                  "firstPartition none;\nimbalanceThreshold 1.1;\n"
                  "weights { fluid 1; wall 0.1; dummy 0.1; }\n");
    double before = 0, after = 0;
    int status = run(&c, 3, cs, "-verbose");
    CHECK(status == 0);
    CHECK_MSG(read_rebalance(&c, &before, &after), "no rebalancing in the log");
    printf("unbalanced start on 3 ranks: load imbalance %.3f, after rebalancing %.3f\n", before,
           after);
    CHECK_MSG(before > 1.5, "the start was not unbalanced (imbalance %g)", before);
    CHECK_MSG(after <= 1.1, "imbalance %g after rebalancing", after);
    tc_case_destroy(&c);
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: test_mpi MPSFLOW TUTORIALS cases|restart|balance|bodies\n");
        return 2;
    }
    exe = argv[1];
    tutorials = argv[2];
    if (getenv("MF_TEST_STEPS")) /* a shorter or longer comparison, by hand */
        nsteps = atol(getenv("MF_TEST_STEPS"));
    if (!strcmp(argv[3], "cases"))
        part_cases(cases, sizeof cases / sizeof cases[0]);
    else if (!strcmp(argv[3], "more"))
        part_cases(more_cases, sizeof more_cases / sizeof more_cases[0]);
    else if (!strcmp(argv[3], "dirs") && argc == 6) {
        /* By hand: the last snapshots of two case folders, compared as the
         * parts do (emitted particles by position). */
        tc_case a, b;
        memset(&a, 0, sizeof a);
        memset(&b, 0, sizeof b);
        snprintf(a.dir, sizeof a.dir, "%s", argv[4]);
        snprintf(b.dir, sizeof b.dir, "%s", argv[5]);
        mf_sim sa, sb;
        memset(&sa, 0, sizeof sa);
        memset(&sb, 0, sizeof sb);
        if (load_last(&a, &sa) == 0 && load_last(&b, &sb) == 0)
            compare("dirs", &sa, &sb, sa.l0, 0);
        tc_sim_free(&sa);
        tc_sim_free(&sb);
    } else if (!strcmp(argv[3], "restart"))
        part_restart();
    else if (!strcmp(argv[3], "balance"))
        part_balance();
    else if (!strcmp(argv[3], "bodies"))
        part_bodies();
    else
        return 2;
    return mf_test_summary(argv[3]);
}
