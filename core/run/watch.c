/* watch.c: the checks of mf_watch.h. */
#include "mf_watch.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_modules.h"
#include "mf_scene.h"
#include "mf_walls.h"
#include "watch_available.h"

const mf_param mf_watch_params[] = {
    {"enabled", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL, offsetof(mf_watch_settings, enabled),
     "check every step for the signs of instability"},
    {"energyTolerance", MF_PARAM_SCALAR, "0.02", 1e-6, 1e6, NULL,
     offsetof(mf_watch_settings, energy_tolerance),
     "kinetic energy gained without a source (beyond the work of the forces, moving walls "
     "and surface energy), as a fraction of the run's energy scale"},
    {"densityCollapse", MF_PARAM_SCALAR, "0.5", 0, 1, NULL,
     offsetof(mf_watch_settings, density_collapse),
     "mean fluid number density below this fraction of n0 means the fluid blew apart"},
    {"availableEnergy", MF_PARAM_BOOL, "yes", MF_NO_RANGE, NULL,
     offsetof(mf_watch_settings, available_energy),
     "check that the fluid's kinetic energy stays below its start plus the potential energy "
     "available to it (above the fluid laid level on the tank's floor) and the work of moving "
     "walls, surface tension and the forces other than gravity"},
    {"availableEnergyTolerance", MF_PARAM_SCALAR, "0.05", 1e-6, 1e6, NULL,
     offsetof(mf_watch_settings, available_tolerance),
     "kinetic energy above the available energy, as a fraction of it plus the energy of the "
     "fluid laid level (its layers' weight times their mid-height above the floor)"},
};
const size_t mf_watch_nparams = sizeof mf_watch_params / sizeof mf_watch_params[0];

int mf_watch_init(mf_watch *w, const mf_dict *dict, mf_dict *resolved)
{
    memset(w, 0, sizeof *w);
    w->n_start = -1;
    w->peak_available = -INFINITY;
    static const char *const extra[] = {NULL};
    MF_CALL(mf_params_apply(mf_watch_params, mf_watch_nparams, dict, extra, &w->s, resolved));
    return 0;
}

/* Are x[0 .. n) all finite? x - x is +0 for a finite x and NaN for an
 * infinite or NaN one, and a NaN stays in a sum: the sums are 0 exactly
 * when all are finite. Two lanes (GCC/clang vector extensions, SSE2 or
 * NEON): the common case, nothing wrong, costs about two instructions a
 * value. */
typedef double finite_v2 __attribute__((vector_size(2 * sizeof(double))));

static bool all_finite(const double *x, size_t n)
{
    finite_v2 s = {0.0, 0.0};
    size_t k = 0;
    for (; k + 2 <= n; k += 2) {
        finite_v2 v;
        memcpy(&v, x + k, sizeof v);
        s += v - v;
    }
    double t = s[0] + s[1];
    if (k < n)
        t += x[k] - x[k];
    return t == 0.0;
}

/* Is every double the particles carry finite (the cheap test first)? */
static bool state_finite(const mf_particles *p)
{
    const size_t n = p->n_owned;
    if (!all_finite(p->pos, 3 * n) || !all_finite(p->vel, 3 * n))
        return false;
    for (int f = 0; f < p->nfields; f++) {
        const mf_field *fd = &p->field[f];
        if (fd->type == MF_FIELD_DOUBLE && !all_finite(fd->data, (size_t)fd->ncomp * n))
            return false;
    }
    return true;
}

static int check_non_finite(const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    if (state_finite(p))
        return 0;
    for (size_t i = 0; i < p->n_owned; i++) { /* the first particle that is not, named */
        const char *what = NULL;
        for (int c = 0; c < 3 && !what; c++) {
            if (!isfinite(p->pos[3 * i + c])) what = "position";
            else if (!isfinite(p->vel[3 * i + c])) what = "velocity";
        }
        for (int f = 0; f < p->nfields && !what; f++) {
            const mf_field *fd = &p->field[f];
            if (fd->type != MF_FIELD_DOUBLE)
                continue;
            for (int c = 0; c < fd->ncomp; c++)
                if (!isfinite(((const double *)fd->data)[fd->ncomp * i + c]))
                    what = fd->name;
        }
        if (what)
            return MF_ERROR(MF_ERR_NUMERIC,
                            "unstable (nonFinite) at time %g, step %ld: %s particle id %lld has a "
                            "non-finite %s",
                            sim->time, sim->step, mf_particle_kind_name(p->kind[i]),
                            (long long)p->id[i], what);
    }
    return 0;
}

/* The box of a tank at rest inside which no point is past any of its faces
 * (mf_wall_passed would say no). At rest (R = I and d = 0 exactly),
 * mf_wall_to_body gives xb = o + (x - o) (the other terms are zeros), within
 * 2 eps (|x| + |o|) of x; a point farther than h inside every face, by a
 * margin of 1e-9 of the magnitudes involved (far above that rounding), is
 * one mf_wall_passed answers no for, so it need not be asked: the same
 * decisions, without the transform and the face loop for nearly every
 * particle. */
typedef struct quiet_box {
    bool on;
    double lo[3], hi[3];
} quiet_box;

#define QUIET_BOXES 16

static quiet_box quiet_box_of(const mf_wall *w, double l0, int dim)
{
    quiet_box q = {false, {0, 0, 0}, {0, 0, 0}};
    static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (w->shape != MF_SOLID_TANK || memcmp(w->state.R, identity, sizeof identity) != 0)
        return q;
    const double h = 0.5 * l0;
    for (int a = 0; a < 3; a++)
        if (w->state.d[a] != 0.0)
            return q;
    for (int a = 0; a < dim; a++) {
        const double margin =
            1e-9 * (fabs(w->motion.origin[a]) + fabs(w->min[a]) + fabs(w->max[a]) + h);
        q.lo[a] = w->min[a] - h + margin;
        q.hi[a] = w->max[a] + h - margin;
        if (!(q.lo[a] < q.hi[a]))
            return q;
    }
    q.on = true;
    return q;
}

static bool inside_quiet(const quiet_box *q, const double *x, int dim)
{
    if (!q->on)
        return false;
    for (int a = 0; a < dim; a++)
        if (!(x[a] > q->lo[a] && x[a] < q->hi[a]))
            return false;
    return true;
}

/* mf_scene_past_wall, asking only the walls whose quiet box does not hold
 * the particle. */
static bool past_a_wall(const mf_sim *sim, const quiet_box *quiet, size_t i, size_t *box,
                        int *axis, int *side)
{
    const double *x = &sim->p->pos[3 * i];
    for (size_t b = 0; sim->walls && b < sim->walls->n; b++) {
        if (b < QUIET_BOXES && inside_quiet(&quiet[b], x, sim->dim))
            continue;
        if (mf_wall_passed(&sim->walls->w[b], sim->l0, sim->dim, x, axis, side)) {
            *box = b;
            return true;
        }
    }
    return false;
}

/* A fluid centre past the wall-particle line (l0/2 outside the enclosed
 * region) of a closed face, within that face's extent, or inside an
 * obstacle by more than l0/2, went through it (mf_scene_past_wall: the dry
 * run refuses a scene that starts so). One beyond the face's layers that
 * was past the face's line before its step as well came over the wall's
 * top and is outside the tank (mf_wall_spilled: at l0 0.00365 the splash
 * of damBreakObstacle goes over the 0.584 m far wall at t = 0.535 s): not
 * a sign of instability. */
static int check_walls(const mf_sim *sim, double dt)
{
    const mf_particles *p = sim->p;
    static const char *const faces[3][2] = {{"xmin", "xmax"}, {"ymin", "ymax"}, {"zmin", "zmax"}};
    quiet_box quiet[QUIET_BOXES];
    for (size_t b = 0; b < QUIET_BOXES; b++)
        quiet[b] = sim->walls && b < sim->walls->n
                       ? quiet_box_of(&sim->walls->w[b], sim->l0, sim->dim)
                       : (quiet_box){false, {0, 0, 0}, {0, 0, 0}};
    for (size_t i = 0; i < p->n_owned; i++) {
        size_t b;
        int a, side;
        if (p->kind[i] != MF_FLUID || !past_a_wall(sim, quiet, i, &b, &a, &side))
            continue;
        const double *x = &p->pos[3 * i];
        const mf_wall *w = &sim->walls->w[b];
        const double *u = &p->vel[3 * i];
        const double step[3] = {dt * u[0], dt * u[1], dt * u[2]};
        if (mf_wall_spilled(w, sim->l0, x, step, a, side))
            continue;
        char what[160];
        if (w->shape == MF_SOLID_TANK)
            snprintf(what, sizeof what, "past the %s wall of wall box %zu", faces[a][side],
                     mf_scene_tank_number(sim, b));
        else
            snprintf(what, sizeof what, "inside obstacle '%s'", w->name);
        return MF_ERROR(MF_ERR_NUMERIC,
                        "unstable (throughWall) at time %g, step %ld: fluid particle "
                        "id %lld at (%g %g %g) is %s, moving at (%g %g %g) m/s",
                        sim->time, sim->step, (long long)p->id[i], x[0], x[1], x[2], what,
                        p->vel[3 * i], p->vel[3 * i + 1], p->vel[3 * i + 2]);
    }
    return 0;
}

static int check_density(mf_watch *w, const mf_sim *sim)
{
    int fn = mf_particles_field_index(sim->p, "NumberDensity");
    if (sim->n0 <= 0 || fn < 0 || w->s.density_collapse <= 0)
        return 0;
    const double *n = mf_particles_fd(sim->p, fn);
    double sum = 0;
    size_t count = 0, thinnest = SIZE_MAX;
    for (size_t i = 0; i < sim->p->n_owned; i++)
        if (sim->p->kind[i] == MF_FLUID) {
            if (count == 0 || n[i] < n[thinnest])
                thinnest = i;
            sum += n[i];
            count++;
        }
    double totals[2] = {sum, (double)count}; /* over the ranks */
    mf_parallel_sum(sim->par, totals, 2);
    if (totals[1] == 0)
        return 0;
    const double mean = totals[0] / totals[1];
    if (w->n_start < 0)
        w->n_start = mean; /* the fluid as the run starts */
    /* The reference: n0, or the start's mean when lower (a sheet, a single
     * particle: n = 0 and nothing to blow apart). */
    const double ref = fmin(sim->n0, w->n_start);
    if (mean >= w->s.density_collapse * ref)
        return 0;
    double minus_n = thinnest != SIZE_MAX ? -n[thinnest] : -INFINITY;
    mf_particle_info t; /* the most isolated over the ranks */
    mf_parallel_argmax(sim->par, &minus_n, sim->p, thinnest, &t);
    const double *x = t.x;
    return MF_ERROR(MF_ERR_NUMERIC,
                    "unstable (densityCollapse) at time %g, step %ld: the mean number density "
                    "of the fluid is %.3g n0, below densityCollapse %g of %.3g n0 (%s): the "
                    "fluid has blown apart; most isolated: fluid particle id %lld at (%g %g %g)",
                    sim->time, sim->step, mean / sim->n0, w->s.density_collapse,
                    ref / sim->n0, ref < sim->n0 ? "its mean at the start" : "n0",
                    (long long)t.id, x[0], x[1], x[2]);
}

/* Kinetic energy; the power of the step's force accelerations a^n (what
 * mf_force_accumulate recorded, carried with the particles in the
 * ForceAcceleration field) at the end of the step, sum m a^n.u^{n+1}, and at
 * its start (the record's power, sum m a^n.u^n); and sum m |a^n|. A step
 * whose forces did not run (no forces) has none. */
static void energy(const mf_sim *sim, double *ke, double *power_start, double *power_end,
                   double *mass_acc)
{
    const mf_particles *p = sim->p;
    const int ff = mf_particles_field_index(p, "FluidId");
    const int fa = sim->forces_record.valid ? mf_particles_field_index(p, MF_FORCE_FIELD) : -1;
    const double *acc = fa >= 0 ? mf_particles_fd(p, fa) : NULL;
    *ke = *power_end = *mass_acc = 0;
    *power_start = acc ? sim->forces_record.power : 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double m = mf_sim_particle_mass(sim, ff, i), *v = &p->vel[3 * i];
        *ke += 0.5 * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (!acc)
            continue;
        const double *a = &acc[3 * i];
        *power_end += m * (a[0] * v[0] + a[1] * v[1] + a[2] * v[2]);
        *mass_acc += m * sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    }
    double sums[4] = {*ke, *power_start, *power_end, *mass_acc}; /* over the ranks */
    mf_parallel_sum(sim->par, sums, 4);
    *ke = sums[0];
    *power_start = sums[1];
    *power_end = sums[2];
    *mass_acc = sums[3];
}

static double fluid_extent(const mf_sim *sim)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < sim->p->n_owned; i++)
        for (int c = 0; c < 3; c++) {
            lo[c] = fmin(lo[c], sim->p->pos[3 * i + c]);
            hi[c] = fmax(hi[c], sim->p->pos[3 * i + c]);
        }
    mf_parallel_min(sim->par, lo, 3);
    mf_parallel_max(sim->par, hi, 3);
    double L = 0;
    for (int c = 0; c < sim->dim; c++)
        L = fmax(L, hi[c] - lo[c]);
    return L;
}

/* Surface energy the fluid can release: the largest sigma times the surface
 * of the fluid's bounding box (2-D: its perimeter, per unit depth). Surface
 * tension applied as a pressure condition (not a force module) does work the
 * force power does not see; a square drop releases part of this as it
 * rounds. 0 without surface tension. */
static double surface_energy(const mf_sim *sim)
{
    double sigma = 0;
    for (int k = 0; k < sim->nfluids; k++)
        sigma = fmax(sigma, sim->fluid[k].sigma);
    if (!(sigma > 0))
        return 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < sim->p->n_owned; i++)
        if (sim->p->kind[i] == MF_FLUID)
            for (int c = 0; c < 3; c++) {
                lo[c] = fmin(lo[c], sim->p->pos[3 * i + c] - 0.5 * sim->l0);
                hi[c] = fmax(hi[c], sim->p->pos[3 * i + c] + 0.5 * sim->l0);
            }
    mf_parallel_min(sim->par, lo, 3);
    mf_parallel_max(sim->par, hi, 3);
    if (!(hi[0] > lo[0]))
        return 0;
    const double a = hi[0] - lo[0], b = hi[1] - lo[1], c = hi[2] - lo[2];
    return sigma * (sim->dim == 3 ? 2 * (a * b + b * c + a * c) : 2 * (a + b));
}

/* The fastest fluid particle of this rank. */
static size_t fastest_fluid(const mf_sim *sim, double *speed)
{
    const mf_particles *p = sim->p;
    size_t best = SIZE_MAX;
    double u2max = -1;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *v = &p->vel[3 * i];
        double u2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if (u2 > u2max) {
            u2max = u2;
            best = i;
        }
    }
    *speed = sqrt(fmax(u2max, 0));
    return best;
}

/* The fastest fluid particle over the ranks, for the messages (collective). */
static double fastest_over_ranks(const mf_sim *sim, mf_particle_info *f)
{
    double speed = 0;
    const size_t i = fastest_fluid(sim, &speed);
    mf_parallel_argmax(sim->par, &speed, sim->p, i, f);
    return speed;
}

/* The kinetic energy the fluid would have moving as fast as the fastest
 * wall particle (a moving wall's, or a sliding lid's surface velocity): a
 * moving wall does work on the fluid that no force module records (viscous
 * drag of a lid, the push of a paddle), which a fluid set in motion by its
 * walls may gain; 0 with walls at rest. */
static double wall_energy(const mf_sim *sim)
{
    const mf_particles *p = sim->p;
    const int ff = mf_particles_field_index(p, "FluidId");
    double u2 = 0, mass = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        const double *v = &p->vel[3 * i];
        if (p->kind[i] == MF_FLUID)
            mass += mf_sim_particle_mass(sim, ff, i);
        else
            u2 = fmax(u2, v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    }
    if (sim->walls && !sim->walls->particles) { /* wall weight: the solids themselves */
        const double u = mf_walls_max_speed(sim->walls, p);
        u2 = u * u;
    }
    /* Over the ranks, as the other energies: a rank without the lid's
     * particles would otherwise see no wall energy and fire alone. */
    mf_parallel_sum(sim->par, &mass, 1);
    mf_parallel_max(sim->par, &u2, 1);
    return 0.5 * mass * u2;
}

static int check_energy(mf_watch *w, const mf_sim *sim, double dt, double *ke_out)
{
    double ke = 0, power_start = 0, power_end = 0, mass_acc = 0;
    energy(sim, &ke, &power_start, &power_end, &mass_acc);
    *ke_out = ke;
    w->wall_scale = fmax(w->wall_scale, wall_energy(sim));
    if (!w->started) { /* the state the run starts from (after its first step) */
        w->started = true;
        w->ke0 = ke;
        w->pot_scale = mass_acc * fluid_extent(sim);
        w->surface_scale = surface_energy(sim);
        w->next_work = 0;
        w->next_excess = 0;
        return 0;
    }
    /* The work of the step's forces, a^n held over the step while u goes
     * from u^n to u^{n+1}: the trapezoidal rule in u. */
    w->next_work = w->work + 0.5 * (power_start + power_end) * dt;
    const double unreported = w->wall_scale + w->surface_scale; /* A of mf_watch.h */
    double excess = ke - w->ke0 - w->next_work - unreported;
    double scale = w->ke0 + fabs(w->next_work) + w->pot_scale + unreported;
    w->next_excess = scale > 0 ? excess / scale : 0;
    w->next_time = sim->time;
    if (!(scale > 0 && excess > w->s.energy_tolerance * scale))
        return 0;
    mf_particle_info f;
    const double speed = fastest_over_ranks(sim, &f);
    const double *x = f.x;
    return MF_ERROR(MF_ERR_NUMERIC,
                    "unstable (energy) at time %g, step %ld: the fluid's kinetic energy %g J "
                    "exceeds its start %g J plus the work of the forces %g J (and %g J that "
                    "moving walls and surface tension may give) by %g J, more "
                    "than energyTolerance %g of the energy scale %g J; fastest: fluid particle "
                    "id %lld at (%g %g %g), %g m/s",
                    sim->time, sim->step, ke, w->ke0, w->next_work, unreported, excess,
                    w->s.energy_tolerance, scale, (long long)f.id, x[0], x[1], x[2], speed);
}

/* The fluid's momentum sum m u over the ranks: gravity's power is g . it. */
static void momentum(const mf_sim *sim, double out[3])
{
    const mf_particles *p = sim->p;
    const int ff = mf_particles_field_index(p, "FluidId");
    out[0] = out[1] = out[2] = 0;
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->kind[i] == MF_FLUID) {
            const double m = mf_sim_particle_mass(sim, ff, i);
            for (int c = 0; c < 3; c++)
                out[c] += m * p->vel[3 * i + c];
        }
    mf_parallel_sum(sim->par, out, 3);
}

/* The availableEnergy criterion at the watch's start: the floor (or why
 * there is none, said once), the fluid's potential energy and momentum. */
static void available_start(mf_watch *w, const mf_sim *sim)
{
    w->floor = (mf_watch_floor){0};
    if (!w->s.available_energy)
        return;
    char why[160];
    mf_watch_floor_find(sim, &w->floor, why, sizeof why);
    if (!w->floor.applies) {
        mf_log_printf(sim->log, MF_LOG_NORMAL, "Watch: no availableEnergy check: %s\n", why);
        return;
    }
    w->pe0 = mf_watch_fluid_pe(sim, &w->floor);
    mf_watch_level_pe(sim, &w->floor, &w->rest_energy);
    momentum(sim, w->momentum);
    w->gravity_work = 0;
}

/* KE <= KE0 + P + A + max(W_o, 0) (mf_watch.h): P = PE0 - min(PE_level, PE), W_o
 * the forces' work W less gravity's, g . sum m u integrated as W is (the
 * trapezoidal rule in u; none in a step whose forces did not run). ke is
 * check_energy's, w->next_work this step's W (first: the start, no work). */
static int check_available(mf_watch *w, const mf_sim *sim, double dt, double ke, bool first)
{
    if (!w->floor.applies)
        return 0;
    const double *g = sim->gravity;
    momentum(sim, w->next_momentum);
    const double *p0 = w->momentum, *p1 = w->next_momentum;
    const double gp0 = g[0] * p0[0] + g[1] * p0[1] + g[2] * p0[2];
    const double gp1 = g[0] * p1[0] + g[1] * p1[1] + g[2] * p1[2];
    w->next_gravity_work = first || !sim->forces_record.valid
                               ? w->gravity_work
                               : w->gravity_work + 0.5 * (gp0 + gp1) * dt;
    const double other = w->next_work - w->next_gravity_work;
    /* The least potential energy the fluid can reach: the level layers, or
     * where it is when it has settled below them (a fluid that compacts,
     * particles closer than l0 at the bottom of a resting tank, releases
     * that part too: energy conservation, KE <= KE0 + PE0 - PE). */
    const double lowest =
        fmin(mf_watch_level_pe(sim, &w->floor, NULL), mf_watch_fluid_pe(sim, &w->floor));
    const double potential = fmax(w->pe0 - lowest, 0);
    const double unreported = w->wall_scale + w->surface_scale; /* A */
    const double budget = w->ke0 + potential + unreported + fmax(other, 0);
    const double scale = budget + w->rest_energy;
    const double excess = ke - budget;
    w->next_available = excess / scale;
    w->next_time = sim->time;
    if (!(excess > w->s.available_tolerance * scale))
        return 0;
    mf_particle_info f;
    const double speed = fastest_over_ranks(sim, &f);
    const double *x = f.x;
    return MF_ERROR(MF_ERR_NUMERIC,
                    "unstable (availableEnergy) at time %g, step %ld: the fluid's kinetic energy "
                    "%g J exceeds all it can have, its start %g J plus the potential energy "
                    "available to it %g J (above the fluid laid level on the floor of wall box "
                    "%zu) plus %g J that moving walls and surface tension and %g J that the "
                    "forces other than gravity may give, by %g J, more than "
                    "availableEnergyTolerance %g of %g J (that plus the level fluid's own %g J); "
                    "fastest: fluid particle id %lld at (%g %g %g), %g m/s",
                    sim->time, sim->step, ke, w->ke0, potential,
                    mf_scene_tank_number(sim, w->floor.tank), unreported, fmax(other, 0), excess,
                    w->s.available_tolerance, scale, w->rest_energy, (long long)f.id, x[0], x[1],
                    x[2], speed);
}

/* On several ranks the local checks (nonFinite, throughWall) are agreed on
 * once, so that every rank reports the same criterion and particle and none
 * goes on to the collective checks alone; those (densityCollapse, energy,
 * availableEnergy) decide from sums over the ranks, the same on every rank,
 * and name the particle on every rank. */
int mf_watch_check(mf_watch *w, const mf_sim *sim, double dt)
{
    int rc = check_non_finite(sim);
    if (rc == 0 && w->s.enabled)
        rc = check_walls(sim, dt);
    MF_CALL(mf_parallel_agree(sim->par, rc));
    if (!w->s.enabled)
        return 0;
    MF_CALL(check_density(w, sim));
    const bool first = !w->started;
    double ke = 0;
    MF_CALL(check_energy(w, sim, dt, &ke));
    if (first)
        available_start(w, sim);
    MF_CALL(check_available(w, sim, dt, ke, first));
    return 0;
}

void mf_watch_accept(mf_watch *w)
{
    w->work = w->next_work;
    if (w->next_excess > w->peak_excess) {
        w->peak_excess = w->next_excess;
        w->peak_excess_time = w->next_time;
    }
    if (w->floor.applies) {
        w->gravity_work = w->next_gravity_work;
        memcpy(w->momentum, w->next_momentum, sizeof w->momentum);
        if (w->next_available > w->peak_available) {
            w->peak_available = w->next_available;
            w->peak_available_time = w->next_time;
        }
    }
}

void mf_watch_report(const mf_watch *w, mf_log *log)
{
    if (w->s.enabled && w->started && isfinite(w->s.energy_tolerance))
        mf_log_printf(log, MF_LOG_QUIET,
                      "Watch: kinetic energy above its start and the forces' work by at most "
                      "%.3g of the energy scale (t = %g; energyTolerance %g)\n",
                      w->peak_excess, w->peak_excess_time, w->s.energy_tolerance);
    if (w->s.enabled && w->floor.applies && isfinite(w->peak_available))
        mf_log_printf(log, MF_LOG_QUIET,
                      "Watch: availableEnergy: kinetic energy above its start, the available "
                      "potential energy and the other work by at most %.3g of them and "
                      "the level fluid's energy (t = %g; availableEnergyTolerance %g)\n",
                      w->peak_available, w->peak_available_time, w->s.available_tolerance);
}
