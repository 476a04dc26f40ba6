/* watch_available.c: the container's floor and the level-layer potential
 * energy of the availableEnergy criterion (mf_watch.h).
 *
 * The bound: a fluid in a closed tank under gravity g has kinetic energy
 * KE <= KE0 + (PE0 - PE) + (work of everything else), and PE >= PE_level,
 * the potential energy of the same volumes laid in flat layers on the floor,
 * the densest lowest (nothing in the tank can put fluid lower: obstacles
 * take volume and raise the layers). So KE0 + PE0 - PE_level bounds what
 * gravity can give. It needs a floor the fluid cannot pass or leave round:
 * one tank box, its floor (the face g points at) and its sides closed, the
 * tank at rest or translating (a rotating floor tilts the layers), g along
 * one axis, and no inlet, outlet or nozzle changing the fluid. A periodic
 * axis is one with open sides (couette2D, poiseuille2D), so excluded. */
#include "watch_available.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "mf_emitter.h"
#include "mf_parallel.h"
#include "mf_walls.h"

static bool rotates(const mf_motion *m)
{
    switch (m->kind) {
    case MF_MOTION_NONE:
    case MF_MOTION_CONSTANT:
        return false;
    case MF_MOTION_OSCILLATING:
        return m->angle_amplitude != 0;
    case MF_MOTION_TABLE:
        return m->angle.n > 0;
    default: /* rotation, external, rigid */
        return true;
    }
}

void mf_watch_floor_find(const mf_sim *sim, mf_watch_floor *f, char *why, size_t n)
{
    *f = (mf_watch_floor){0};
    const double *g = sim->gravity;
    const double gm = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(gm > 0)) {
        snprintf(why, n, "no gravity");
        return;
    }
    int axis = -1;
    for (int c = 0; c < 3; c++)
        if (fabs(g[c]) > 1e-12 * gm) {
            if (axis >= 0 || c >= sim->dim) {
                snprintf(why, n, "gravity (%g %g %g) is not along an axis of the case", g[0],
                         g[1], g[2]);
                return;
            }
            axis = c;
        }
    if (sim->emitters && (sim->emitters->ninlets || sim->emitters->noutlets ||
                          sim->emitters->nnozzles)) {
        snprintf(why, n, "inlets, outlets or nozzles change the fluid");
        return;
    }
    const mf_walls *ws = sim->walls;
    size_t tank = SIZE_MAX;
    for (size_t k = 0; ws && k < ws->n; k++) {
        if (ws->w[k].obstacle)
            continue;
        if (ws->w[k].shape != MF_SOLID_TANK || tank != SIZE_MAX) {
            snprintf(why, n, "the container is not one tank box");
            return;
        }
        tank = k;
    }
    if (tank == SIZE_MAX) {
        snprintf(why, n, "no tank box holds the fluid");
        return;
    }
    const mf_wall *w = &ws->w[tank];
    static const char *const faces[3][2] = {{"xmin", "xmax"}, {"ymin", "ymax"}, {"zmin", "zmax"}};
    const int floor_side = g[axis] < 0 ? 0 : 1;
    if (w->open[axis][floor_side]) {
        snprintf(why, n, "the tank's floor (%s) is open", faces[axis][floor_side]);
        return;
    }
    double area = 1;
    for (int c = 0; c < sim->dim; c++) {
        if (c == axis)
            continue;
        if (w->open[c][0] || w->open[c][1]) {
            snprintf(why, n, "the tank's side %s is open (or periodic)",
                     faces[c][w->open[c][0] ? 0 : 1]);
            return;
        }
        area *= w->max[c] - w->min[c];
    }
    if (rotates(&w->motion)) {
        snprintf(why, n, "the tank rotates");
        return;
    }
    if (!(area > 0)) {
        snprintf(why, n, "the tank's floor has no area");
        return;
    }
    *f = (mf_watch_floor){.applies = true, .axis = axis, .up = g[axis] < 0 ? 1 : -1,
                          .g = gm, .tank = tank, .area = area};
}

double mf_watch_fluid_pe(const mf_sim *sim, const mf_watch_floor *f)
{
    const mf_particles *p = sim->p;
    const int ff = mf_particles_field_index(p, "FluidId");
    double pe = 0;
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->kind[i] == MF_FLUID)
            pe += mf_sim_particle_mass(sim, ff, i) * f->g * f->up * p->pos[3 * i + f->axis];
    mf_parallel_sum(sim->par, &pe, 1);
    return pe;
}

/* Fluid indices by density, densest first (insertion sort of <= 16). */
static void by_density(const mf_sim *sim, int *order)
{
    for (int k = 0; k < sim->nfluids; k++) {
        int j = k;
        for (; j > 0 && sim->fluid[order[j - 1]].rho < sim->fluid[k].rho; j--)
            order[j] = order[j - 1];
        order[j] = k;
    }
}

double mf_watch_level_pe(const mf_sim *sim, const mf_watch_floor *f, double *above_floor)
{
    const mf_particles *p = sim->p;
    const int ff = mf_particles_field_index(p, "FluidId");
    double count[MF_MAX_FLUIDS] = {0};
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->kind[i] == MF_FLUID)
            count[ff >= 0 ? mf_particles_fi(p, ff)[i] : 0] += 1;
    mf_parallel_sum(sim->par, count, sim->nfluids);
    const mf_wall *w = &sim->walls->w[f->tank];
    /* The floor's height now: the face g points at, moved with the tank. */
    const double face = f->up > 0 ? w->min[f->axis] : w->max[f->axis];
    const double z_floor = f->up * (face + w->state.d[f->axis]);
    double z = z_floor, mass = 0;
    const double vol = sim->dim == 3 ? sim->l0 * sim->l0 * sim->l0 : sim->l0 * sim->l0;
    int order[MF_MAX_FLUIDS];
    by_density(sim, order);
    double pe = 0;
    for (int k = 0; k < sim->nfluids; k++) {
        const int fl = order[k];
        const double thick = count[fl] * vol / f->area;
        pe += count[fl] * vol * sim->fluid[fl].rho * f->g * (z + 0.5 * thick);
        mass += count[fl] * vol * sim->fluid[fl].rho;
        z += thick;
    }
    if (above_floor)
        *above_floor = pe - mass * f->g * z_floor;
    return pe;
}
