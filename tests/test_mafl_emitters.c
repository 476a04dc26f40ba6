/* test_mafl_emitters.c: inlets, outlets, nozzles and transported scalars
 * (core/scene/mf_emitter.h) on scenes built from geometry text, with the solver
 * replaced by "fluid moves with its velocity" (what a uniform flow does).
 *
 *   - scalar profiles: values, declared fields, reserved names refused;
 *   - a nozzle adds exactly rate t / l0^dim particles by time t, the same
 *     whatever the steps (a retried step or a restart adds the same);
 *   - moving buffers (the mode of MPS): with inflow equal to outflow the
 *     fluid count stays within one column of its start over five passes
 *     through the channel, every id stays unique, nothing crosses a wall;
 *   - fixed buffers (the mode of MPS-MAFL): inlet points get the inlet's
 *     values, fluid that enters an outlet box is removed;
 *   - bad input names the file, line and key. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_dictio.h"
#include "mf_emitter.h"
#include "mf_scene.h"
#include "mf_walls.h"
#include "mf_test.h"

typedef struct scene {
    mf_sim sim;
    mf_dict *fluids, *geometry;
} scene;

static int build(scene *s, const char *geometry)
{
    memset(s, 0, sizeof *s);
    static const char fluids[] = "water { rho 1000; nu 1e-6; }\n";
    MF_CALL(mf_dict_parse_string(fluids, strlen(fluids), "fluids", &s->fluids));
    MF_CALL(mf_scene_read_fluids(s->fluids, &s->sim));
    MF_CALL(mf_dict_parse_string(geometry, strlen(geometry), "geometry", &s->geometry));
    MF_CALL(mf_scene_build(s->geometry, 0, &s->sim, NULL));
    return 0;
}

static void destroy(scene *s)
{
    mf_emitters_destroy(s->sim.emitters);
    mf_particles_destroy(s->sim.p);
    mf_walls_destroy(s->sim.walls);
    mf_dict_free(s->fluids);
    mf_dict_free(s->geometry);
}

static size_t count_kind(const mf_particles *p, int kind)
{
    size_t c = 0;
    for (size_t i = 0; i < p->n; i++)
        c += p->kind[i] == kind;
    return c;
}

static int by_id(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

static bool ids_unique(const mf_particles *p)
{
    int64_t *ids = malloc((p->n ? p->n : 1) * sizeof *ids);
    if (!ids)
        return false;
    memcpy(ids, p->id, p->n * sizeof *ids);
    qsort(ids, p->n, sizeof *ids, by_id);
    bool ok = true;
    for (size_t i = 1; i < p->n; i++)
        ok = ok && ids[i] != ids[i - 1];
    free(ids);
    return ok;
}

/* The stand-in solver: fluid particles move with their velocity. */
static void move_fluid(mf_sim *sim, double dt)
{
    mf_particles *p = sim->p;
    for (size_t i = 0; i < p->n; i++)
        if (p->kind[i] == MF_FLUID)
            for (int a = 0; a < 3; a++)
                p->pos[3 * i + a] += dt * p->vel[3 * i + a];
}

static void test_scalars(void)
{
    scene s;
    static const char geo[] =
        "dimension 2; particleSpacing 0.01;\n"
        "fluidBlocks { b { min (0 0 0); max (1 0.1 0); fluid water;\n"
        "  scalars { dye { type gaussian; centre (0.3 0 0); direction (1 0 0); width 0.05; }\n"
        "            tracer { type box; min (0.1 -1 0); max (0.2 1 0); inside 2; outside -1; }\n"
        "            heat 20;\n"
        "            front { type step; origin (0.5 0 0); normal (1 0 0); below 1; above 0; } } } }\n";
    CHECK_OK(build(&s, geo));
    CHECK(s.sim.nscalars == 4);
    const mf_particles *p = s.sim.p;
    int dye = mf_particles_field_index(p, "dye"), tracer = mf_particles_field_index(p, "tracer"),
        heat = mf_particles_field_index(p, "heat"), front = mf_particles_field_index(p, "front");
    CHECK(dye >= 0 && tracer >= 0 && heat >= 0 && front >= 0);
    double worst = 0;
    for (size_t i = 0; dye >= 0 && tracer >= 0 && heat >= 0 && front >= 0 && i < p->n; i++) {
        const double x = p->pos[3 * i];
        double e = fabs(mf_particles_fd(p, dye)[i] - exp(-(x - 0.3) * (x - 0.3) / (2 * 0.0025)));
        worst = e > worst ? e : worst;
        CHECK(mf_particles_fd(p, tracer)[i] == ((x >= 0.1 && x <= 0.2) ? 2.0 : -1.0));
        CHECK(mf_particles_fd(p, heat)[i] == 20.0);
        CHECK(mf_particles_fd(p, front)[i] == (x < 0.5 ? 1.0 : 0.0));
    }
    CHECK(worst < 1e-15);
    int f = -1;
    CHECK(mf_scalar_declare(&s.sim, "Pressure", &f) == MF_ERR_INPUT);
    mf_error_clear();
    destroy(&s);
}

/* 2-D nozzle: 4 particles a layer (diameter 4 l0), speed 1: a layer every
 * l0 / 1 = 0.01 s from t = 0.02 to 0.1. */
static const char nozzle_geo[] =
    "dimension 2; particleSpacing 0.01;\n"
    "walls { box { min (0 0 0); max (1 1 0); } }\n"
    "emitters { tap { type nozzle; centre (0.5 0.8 0); velocity (0 -1 0); diameter 0.04;\n"
    "                 start 0.02; end 0.1; scalars { dye 1; } } }\n";

static size_t nozzle_run(double dt, int *steps_out)
{
    scene s;
    if (build(&s, nozzle_geo) != 0) {
        mf_error_print(stderr);
        return 0;
    }
    size_t total = 0;
    int steps = 0;
    while (s.sim.time < 0.2 - 1e-12) {
        size_t added = 0, removed = 0;
        CHECK_OK(mf_emitters_apply(s.sim.emitters, &s.sim, dt, &added, &removed));
        move_fluid(&s.sim, dt);
        s.sim.time += dt;
        total += added;
        steps++;
    }
    size_t fluid = count_kind(s.sim.p, MF_FLUID);
    CHECK(fluid == total);
    CHECK(ids_unique(s.sim.p));
    int dye = mf_particles_field_index(s.sim.p, "dye");
    for (size_t i = 0; dye >= 0 && i < s.sim.p->n; i++)
        if (s.sim.p->kind[i] == MF_FLUID)
            CHECK(mf_particles_fd(s.sim.p, dye)[i] == 1.0);
    *steps_out = steps;
    destroy(&s);
    return total;
}

static void test_nozzle(void)
{
    int steps_a = 0, steps_b = 0, steps_c = 0;
    size_t a = nozzle_run(1e-3, &steps_a), b = nozzle_run(3.7e-3, &steps_b),
           c = nozzle_run(0.05, &steps_c);
    printf("nozzle: %zu particles with dt = 1e-3 (%d steps), %zu with 3.7e-3, %zu with 0.05\n", a,
           steps_a, b, c);
    CHECK(a == 4 * 8); /* layers at 0.02, 0.03, ..., 0.09 */
    CHECK(b == a);
    CHECK(c == a);
}

/* A channel with an inlet and an outlet; uniform velocity 1. */
static const char channel_geo[] =
    "dimension 2; particleSpacing 0.01;\n"
    "fluidBlocks { c { min (0 0 0); max (0.5 0.05 0); fluid water; velocity (1 0 0); } }\n"
    "walls { w { min (-0.04 0 0); max (0.54 0.05 0); open (xmin xmax); } }\n"
    "inlets { in { min (-0.04 0 0); max (0 0.05 0); velocity (1 0 0); scalars { dye 3; } } }\n"
    "outlets { out { min (0.5 0 0); max (0.54 0.05 0); direction (1 0 0); velocity (1 0 0); } }\n";

static void test_moving_buffers(void)
{
    scene s;
    CHECK_OK(build(&s, channel_geo));
    if (!s.sim.emitters) {
        CHECK(!"emitters created");
        return;
    }
    const size_t fluid0 = count_kind(s.sim.p, MF_FLUID), inlet0 = count_kind(s.sim.p, MF_INLET);
    CHECK(fluid0 == 250 && inlet0 == 20);
    const double dt = 0.0013; /* not a divisor of l0 / U: crossings at every phase */
    size_t lo = fluid0, hi = fluid0, added = 0, removed = 0, total_in = 0, total_out = 0;
    for (int k = 0; k < 2000; k++) { /* 2.6 s: five times through the channel */
        CHECK_OK(mf_emitters_apply(s.sim.emitters, &s.sim, dt, &added, &removed));
        move_fluid(&s.sim, dt);
        s.sim.time += dt;
        total_in += added;
        total_out += removed;
        size_t f = count_kind(s.sim.p, MF_FLUID);
        lo = f < lo ? f : lo;
        hi = f > hi ? f : hi;
    }
    printf("moving buffers: fluid count in [%zu, %zu] (start %zu); %zu added, %zu removed\n", lo,
           hi, fluid0, total_in, total_out);
    CHECK(fluid0 - lo <= 5 && hi - fluid0 <= 5); /* within a column (5 points) of the start */
    CHECK(total_in > 1000 && total_out > 1000);
    CHECK(count_kind(s.sim.p, MF_INLET) == inlet0);
    CHECK(ids_unique(s.sim.p));
    /* The fluid that came in carries the inlet's dye. */
    int dye = mf_particles_field_index(s.sim.p, "dye");
    size_t with_dye = 0;
    for (size_t i = 0; dye >= 0 && i < s.sim.p->n; i++)
        with_dye += s.sim.p->kind[i] == MF_FLUID && mf_particles_fd(s.sim.p, dye)[i] == 3.0;
    CHECK(with_dye == count_kind(s.sim.p, MF_FLUID));
    /* Nothing beyond the walls' lines. */
    for (size_t i = 0; i < s.sim.p->n; i++)
        if (s.sim.p->kind[i] == MF_FLUID)
            CHECK(s.sim.p->pos[3 * i + 1] > 0 && s.sim.p->pos[3 * i + 1] < 0.05);
    destroy(&s);
}

static void test_fixed_buffers(void)
{
    scene s;
    CHECK_OK(build(&s, channel_geo));
    if (!s.sim.emitters)
        return;
    s.sim.emitters->fixed_buffers = true;
    mf_particles *p = s.sim.p;
    const size_t fluid0 = count_kind(p, MF_FLUID), n0 = p->n;
    /* Spoil the inlet points' values: the step restores them. Push one
     * fluid column into the outlet box. */
    int dye = mf_particles_field_index(p, "dye");
    for (size_t i = 0; i < p->n; i++) {
        if (p->kind[i] == MF_INLET) {
            p->vel[3 * i] = -7;
            mf_particles_fd(p, dye)[i] = 0;
        }
        if (p->kind[i] == MF_FLUID && p->pos[3 * i] > 0.49)
            p->pos[3 * i] += 0.006;
    }
    size_t added = 0, removed = 0;
    CHECK_OK(mf_emitters_apply(s.sim.emitters, &s.sim, 1e-3, &added, &removed));
    CHECK(added == 0 && removed == 5);
    CHECK(count_kind(p, MF_FLUID) == fluid0 - 5 && p->n == n0 - 5);
    for (size_t i = 0; i < p->n; i++)
        if (p->kind[i] == MF_INLET) {
            CHECK(p->vel[3 * i] == 1.0);
            CHECK(mf_particles_fd(p, dye)[i] == 3.0);
        }
    CHECK(ids_unique(p));
    destroy(&s);
}

static void test_bad_input(void)
{
    scene s;
    static const char geo[] =
        "dimension 2; particleSpacing 0.01;\n"
        "fluidBlocks { c { min (0 0 0); max (0.5 0.05 0); fluid water; } }\n"
        "inlets { in { min (-0.04 0 0); max (0 0.05 0);\n"
        "              velocity (1 1 0); } }\n";
    int rc = build(&s, geo);
    CHECK(rc == MF_ERR_INPUT);
    const char *msg = mf_error_message();
    CHECK_MSG(strstr(msg, "geometry:4") && strstr(msg, "velocity"), "message: %s", msg);
    mf_error_clear();
    destroy(&s);
    static const char geo2[] =
        "dimension 2; particleSpacing 0.01;\n"
        "walls { box { min (0 0 0); max (1 1 0); } }\n"
        "emitters { tap { type nozzle; centre (0.5 0.8 0); velocity (0 -1 0); diameter 0.04;\n"
        "                 rate 1; } }\n";
    rc = build(&s, geo2);
    CHECK(rc == MF_ERR_INPUT);
    msg = mf_error_message();
    CHECK_MSG(strstr(msg, "rate"), "message: %s", msg);
    mf_error_clear();
    destroy(&s);
}

int main(void)
{
    test_scalars();
    test_nozzle();
    test_moving_buffers();
    test_fixed_buffers();
    test_bad_input();
    return mf_test_summary("mafl_emitters");
}
