/* surface_tension.c: the surface tension force of the paper's Appendix A
 * (after Nomura et al. 2001), eq. 33's sigma kappa delta n per unit volume,
 * returned as the acceleration f_st / rho_x of eq. 27 (and written to the
 * SurfaceTension field; the curvature to Curvature).
 *
 * Interface particles. A fluid particle of fluid x is on an interface when a
 * particle of another fluid lies within r_st, or (a free surface, where
 * sigma_x > 0) when fewer than beta N_full particles of any kind lie within
 * r_st, N_full the count of a full neighbourhood in the current packing.
 * Walls and dummies count as the particle's own fluid (no contact-angle
 * model).
 *
 * Counts (eqs. 34-37). n^st1_i counts the own-fluid particles within r_st
 * (w = 1 inside r_st); n^st2_i only those deeper inside than i,
 * n^st1_j > n^st1_i, a tie counting one half (the particle's own layer is
 * neither in nor out whatever the disorder); walls count as deeper. n0^st
 * is n^st2 at a flat interface (kappa = 0): on the lattice it is N_full / 2,
 * and N_full is measured on the deep particles of the current packing
 * (disorder changes it by a particle or two). Where the probe is full (an
 * interface between fluids) the particle's own count of every particle
 * stands for N_full.
 *
 * Curvature, with f = n^st2 / (2 n0^st) the fraction of the r_st disk
 * (ball) the fluid fills:
 *   paper:  eqs. 38-39, 2 theta = pi n^st2 / n0^st, kappa = 2 cos(theta)/r_st.
 *           They take the fluid's part of the disk as the sector of angle
 *           2 theta and leave out the two segments between the chords and
 *           the arc: f = 1/2 - r_st/(3 pi R) where the sector gives
 *           1/2 - r_st/(2 pi R), so kappa comes out 2/3 of 1/R.
 *   exact:  f inverted through the exact area of a disk of radius r_st
 *           centred on a circle of radius R (2-D), or the volume of a ball
 *           centred on a sphere (3-D, f = 1/2 - 3 r_st/(16 R), kappa = 2/R,
 *           the sum of the principal curvatures: dp = sigma kappa is
 *           Laplace's 2 sigma/R). Right on a lattice drop, but the counts
 *           follow the particle density: in motion a few per cent of
 *           compression at the interface reads as a curvature of 1/R.
 *   normal: (default) kappa = div n, n the outward unit normal of the colour
 *           gradient (Brackbill et al. 1992): insensitive to the density.
 * (README, "Multi-fluid", has the measurements.)
 *
 * delta n (eq. 33). The colour C_x (1 in fluid x, 0 elsewhere) has the
 * gradient g^y_i = -C sum_{j in y} phi(r_ij) r_hat_ij toward another fluid
 * y and g^0_i = C sum_{j present} phi r_hat (the missing neighbours' share)
 * toward the void, phi = (1 - r/r_st)^2, C = d / sum_lattice r phi(r): across
 * a flat interface the sum of g over a column of particles is half the jump
 * of C on each side. So each side of a fluid/fluid interface takes
 * sigma_xy kappa g^y (kappa the pair's mean curvature: the two sides carry
 * equal shares) and a free surface, which has one side, 2 sigma_x kappa g^0.
 * The force per unit volume integrated across the interface is sigma kappa.
 *
 * Free surfaces, freeSurface:
 *   force:    (default) the paper's form above. The free-surface particles of
 *             the solver (eq. 18: n* < beta n0, p = 0) are the outer layers of
 *             the band: they take their share of the force with no pressure,
 *             and the pressure inside a drop comes out about 0.6-0.7 sigma/R.
 *   pressure: the Laplace pressure sigma kappa is the Dirichlet value of the
 *             solver's free-surface particles instead of 0 (the usual
 *             free-surface treatment of surface tension), and no force acts on
 *             free surfaces (it would count the jump twice); the curvature is
 *             computed as above. A solver applies it through
 *             mf_forces_surface_pressure (forces.h): multiFluid, one solve.
 *
 * Tension of a pair: sigma_xy of an `interfaces` entry, else Antonow's rule
 * |sigma_x - sigma_y| (a fluid against one with sigma 0 keeps its own
 * sigma); a free surface of fluid x: sigma_x.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "forces.h"
#include "mf_error.h"
#include "mf_halo.h"
#include "mf_kernel.h"
#include "mf_pairs.h"
#include "mf_scene.h"

typedef struct st_settings {
    double radius;          /* r_st in l0 */
    const char *curvature;  /* exact | paper */
    double beta;            /* free surface below beta N_full */
    double dt_factor;       /* capillary time step factor */
    long smoothing;         /* passes of curvature smoothing */
    const char *free_surface; /* force | pressure */
    const mf_dict *interfaces;
} st_settings;

static const char *const curvature_models[] = {"exact", "paper", "normal", NULL};
static const char *const free_surface_models[] = {"force", "pressure", NULL};

static const mf_param st_params[] = {
    {"radius", MF_PARAM_SCALAR, "4.1", 1.5, 10, NULL, offsetof(st_settings, radius),
     "r_st, the radius of the surface-tension number densities (eqs. 34-37), in l0"},
    {"curvature", MF_PARAM_WORD, "normal", MF_NO_RANGE, curvature_models,
     offsetof(st_settings, curvature),
     "kappa from n^st2: exact (disk/ball intersection) or paper (eqs. 38-39, 2/3 of it); "
     "or normal: the divergence of the interface normal (Brackbill et al. 1992)"},
    {"beta", MF_PARAM_SCALAR, "0.85", 0.5, 1, NULL, offsetof(st_settings, beta),
     "free-surface interface where fewer than beta N_full particles lie within r_st"},
    {"dtFactor", MF_PARAM_SCALAR, "1", 0.01, 10, NULL, offsetof(st_settings, dt_factor),
     "dt <= dtFactor sqrt(rho l0^3 / (2 pi sigma)) (Brackbill et al. 1992); rho: the pair's "
     "mean density"},
    {"smoothing", MF_PARAM_INT, "1", 0, 10, NULL, offsetof(st_settings, smoothing),
     "passes of curvature averaging over the free-surface particles within r_st (0: none)"},
    {"freeSurface", MF_PARAM_WORD, "force", MF_NO_RANGE, free_surface_models,
     offsetof(st_settings, free_surface),
     "a free surface of a fluid with sigma > 0: force (eq. 33 on its interface band; its "
     "free-surface particles keep p = 0, eq. 18) or pressure (they hold the Laplace "
     "pressure sigma kappa instead, and no force acts there; needs solver multiFluid with "
     "one pressure solve per step)"},
    {"interfaces", MF_PARAM_DICT, NULL, MF_NO_RANGE, NULL, offsetof(st_settings, interfaces),
     "tension of fluid pairs: name { fluids (a b); sigma 0.03; } (else |sigma_a - sigma_b|)"},
};
#define ST_NPARAMS (sizeof st_params / sizeof st_params[0])

#define EXACT_TABLE 2001 /* the 2-D area fraction F(eps), eps = r_st / R in [0, 2] */

typedef struct st_data {
    st_settings s;
    bool paper, normal;
    bool pressure_mode;        /* freeSurface pressure: p = sigma kappa, no force there */
    bool claimed;              /* a solver applies the surface pressure */
    double g_ref;              /* |delta n| of the outer layer of a flat lattice surface */
    int dim;
    double l0, r;              /* r = r_st in m */
    int nfluids;
    double sigma[MF_MAX_FLUIDS][MF_MAX_FLUIDS]; /* fluid pairs; [x][x]: free surface of x */
    bool any;                  /* some tension is > 0 */
    double n_full, n0st;       /* eqs. 34-39 on the lattice */
    double g_coef;             /* d / sum_lattice r phi(r): the colour gradient's constant */
    double table_f[EXACT_TABLE];
    int f_curvature;           /* Curvature field */
    int f_accel;               /* SurfaceTension field: f_st / rho_x, m/s^2 */
    int pairs;                 /* neighbour request within r_st (sim->neighbours) */
    size_t cap;
    int32_t *n1, *nall;
    double *kappa, *kappa_s, *fdir;
    double *nrm;               /* outward unit normal of the particle's own fluid; 0: none */
    double *p_surface;         /* freeSurface pressure: sigma kappa near a free surface; NAN */
    size_t p_surface_n;        /* particles p_surface holds (this step's) */
    /* The last accumulate's curvature and acceleration, for write_fields
     * (accumulate itself leaves the fields alone: forces are side-effect free). */
    double *kappa_out, *accel_out;
    size_t out_n;              /* particles they hold */
} st_data;

/* ---- curvature from the filled fraction f of the r_st disk (ball) --------- */

/* 2-D: the part of a disk of radius r centred on a circle of radius R that
 * lies inside the circle, as a fraction of the disk; eps = r / R in (0, 2]. */
static double disk_fraction(double eps)
{
    if (eps <= 0)
        return 0.5;
    return (acos(eps / 2) + acos(1 - eps * eps / 2) / (eps * eps) -
            sqrt(4 - eps * eps) / (2 * eps)) /
           M_PI;
}

/* eps >= 0 with disk_fraction(eps) = f, f in [1/4, 1/2] (clamped). */
static double invert_disk_fraction(const st_data *d, double f)
{
    const double *t = d->table_f; /* decreasing from 1/2 to 1/4 */
    if (f >= t[0])
        return 0;
    if (f <= t[EXACT_TABLE - 1])
        return 2;
    size_t lo = 0, hi = EXACT_TABLE - 1;
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (t[mid] > f)
            lo = mid;
        else
            hi = mid;
    }
    double a = t[lo], b = t[hi], s = (a - f) / (a - b);
    return 2.0 * ((double)lo + s) / (EXACT_TABLE - 1);
}

/* kappa (1/m) of a particle whose fluid fills the fraction f of its probe. */
static double curvature(const st_data *d, double f)
{
    if (d->paper) { /* eqs. 38-39: 2 theta = pi n^st2 / n0^st = 2 pi f */
        double theta = M_PI * f;
        return 2 * cos(theta) / d->r;
    }
    double sign = f <= 0.5 ? 1.0 : -1.0; /* concave: the other side's convex fraction */
    double g = f <= 0.5 ? f : 1 - f, eps;
    if (d->dim == 2) {
        eps = invert_disk_fraction(d, g);
        return sign * eps / d->r;
    }
    eps = fmin(2.0, 16.0 / 3.0 * (0.5 - g)); /* ball on a sphere: f = 1/2 - 3 eps / 16 */
    return sign * 2 * eps / d->r;             /* 2/R */
}

/* ---- lattice constants ---------------------------------------------------- */

/* The weight of the colour gradient (delta n): the gradient of the smooth
 * number density sum_j phi(r_ij), phi = (1 - r/r_st)^2. Not the MPS weight
 * re/r - 1: its 1/r singularity lets the nearest neighbour decide the
 * normal, and when the outer layer is pressed onto the next one, that
 * layer's normal turns outward and the force pushes it out (measured on a
 * 2-D drop: the integrated force fell from sigma/R to 0.2 sigma/R within
 * 0.1 s). */
static inline double colour_weight(double r, double rst)
{
    return r < rst ? (1 - r / rst) * (1 - r / rst) : 0.0;
}

/* N_full: lattice points within r_st; n0^st: n^st2 of a particle on a flat
 * lattice surface (deeper layers count 1, its own layer one half). */
static void lattice_counts(st_data *d)
{
    int m = (int)ceil(d->s.radius), mz = d->dim == 3 ? m : 0;
    double full = 0, flat = 0, rphi = 0, gy = 0;
    const double r2 = d->s.radius * d->s.radius;
    for (int i = -m; i <= m; i++)
        for (int j = -m; j <= m; j++)
            for (int k = -mz; k <= mz; k++) {
                double q = (double)(i * i + j * j + k * k);
                if (q == 0 || q >= r2)
                    continue;
                full += 1;
                double r = sqrt(q) * d->l0;
                rphi += r * colour_weight(r, d->r);
                if (j <= 0) /* the outer particle of a flat surface: colour gradient */
                    gy += colour_weight(r, d->r) * (j * d->l0) / r;
                /* the interface is normal to y; fluid at y <= 0 */
                if (j < 0)
                    flat += 1;
                else if (j == 0)
                    flat += 0.5;
            }
    d->n_full = full;
    d->n0st = flat;
    d->g_coef = d->dim / rphi;
    d->g_ref = fabs(d->g_coef * gy);
}

/* ---- pair tensions --------------------------------------------------------- */

typedef struct pair_settings {
    double sigma;
} pair_settings;

static const mf_param pair_params[] = {
    {"sigma", MF_PARAM_SCALAR, NULL, 0, 1e6, NULL, offsetof(pair_settings, sigma),
     "tension of the interface, N/m"},
};
static const char *const pair_extra[] = {"fluids", NULL};

static int read_interface(st_data *d, const mf_sim *sim, const mf_entry *e)
{
    char where[512];
    if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: interface '%s' must be a sub-dictionary { fluids (a b); sigma s; }",
                        mf_loc_str(e->loc, where, sizeof where), e->key);
    const mf_dict *id = e->items[0]->dict;
    pair_settings ps;
    MF_CALL(mf_params_apply(pair_params, 1, id, pair_extra, &ps, NULL));
    mf_entry *fe = mf_dict_find(id, "fluids");
    if (!fe || fe->n != 1 || fe->items[0]->kind != MF_VAL_LIST || fe->items[0]->n != 2)
        return MF_ERROR(MF_ERR_INPUT, "%s: interface '%s': 'fluids' takes two fluid names, e.g. "
                        "fluids (oil water);",
                        mf_loc_str(fe ? fe->loc : id->loc, where, sizeof where), e->key);
    fe->used = true;
    int k[2];
    for (int q = 0; q < 2; q++) {
        const mf_value *v = fe->items[0]->items[q];
        if (v->kind != MF_VAL_WORD && v->kind != MF_VAL_STRING)
            return MF_ERROR(MF_ERR_INPUT, "%s: interface '%s': a fluid name is expected",
                            mf_loc_str(v->loc, where, sizeof where), e->key);
        if (mf_scene_fluid_index(sim, v->text, &k[q]) != 0)
            return MF_ERROR(MF_ERR_INPUT, "%s: interface '%s': %s",
                            mf_loc_str(v->loc, where, sizeof where), e->key,
                            mf_error_message());
    }
    if (k[0] == k[1])
        return MF_ERROR(MF_ERR_INPUT, "%s: interface '%s' names fluid '%s' twice (its free "
                        "surface takes sigma from constant/fluids)",
                        mf_loc_str(fe->loc, where, sizeof where), e->key,
                        sim->fluid[k[0]].name);
    d->sigma[k[0]][k[1]] = d->sigma[k[1]][k[0]] = ps.sigma;
    return 0;
}

static int setup_tensions(st_data *d, const mf_sim *sim)
{
    d->nfluids = sim->nfluids;
    for (int x = 0; x < sim->nfluids; x++)
        for (int y = 0; y < sim->nfluids; y++)
            d->sigma[x][y] = x == y ? sim->fluid[x].sigma
                                    : fabs(sim->fluid[x].sigma - sim->fluid[y].sigma);
    for (size_t k = 0; d->s.interfaces && k < d->s.interfaces->n; k++) {
        mf_entry *e = d->s.interfaces->entries[k];
        e->used = true;
        MF_CALL(read_interface(d, sim, e));
    }
    d->any = false;
    for (int x = 0; x < sim->nfluids; x++)
        for (int y = 0; y < sim->nfluids; y++)
            d->any = d->any || d->sigma[x][y] > 0;
    return 0;
}

/* ---- the module -------------------------------------------------------------- */

static void st_destroy(void *data)
{
    st_data *d = data;
    if (!d)
        return;
    free(d->n1);
    free(d->nall);
    free(d->kappa);
    free(d->kappa_s);
    free(d->fdir);
    free(d->nrm);
    free(d->p_surface);
    free(d->kappa_out);
    free(d->accel_out);
    free(d);
}

static int st_create_data(const st_settings *s, mf_sim *sim, st_data *d)
{
    d->s = *s;
    d->paper = strcmp(s->curvature, "paper") == 0;
    d->normal = strcmp(s->curvature, "normal") == 0;
    d->pressure_mode = strcmp(s->free_surface, "pressure") == 0;
    d->dim = sim->dim;
    d->l0 = sim->l0;
    d->r = s->radius * sim->l0;
    /* Shared: the solver's lists where they reach r_st (their order, too). */
    MF_CALL(mf_neighbours_request(sim->neighbours, d->r, 0, &d->pairs));
    lattice_counts(d);
    for (int i = 0; i < EXACT_TABLE; i++)
        d->table_f[i] = disk_fraction(2.0 * i / (EXACT_TABLE - 1));
    MF_CALL(setup_tensions(d, sim));
    MF_CALL(mf_particles_request_field(sim->p, "Curvature", 1, MF_FIELD_DOUBLE, true,
                                       &d->f_curvature));
    MF_CALL(mf_particles_request_field(sim->p, "SurfaceTension", 3, MF_FIELD_DOUBLE, true,
                                       &d->f_accel));
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "surfaceTension: r_st = %g l0, N_full = %g, n0^st = %g (flat interface), "
                  "curvature %s, free surfaces by %s\n",
                  s->radius, d->n_full, d->n0st, s->curvature,
                  d->pressure_mode ? "pressure (p = sigma kappa, eq. 18; no force there)"
                                   : "force (eq. 33)");
    for (int x = 0; x < sim->nfluids; x++)
        for (int y = x; y < sim->nfluids; y++)
            if (d->sigma[x][y] > 0) {
                if (x == y)
                    mf_log_printf(sim->log, MF_LOG_NORMAL,
                                  "surfaceTension: free surface of %s: sigma = %g N/m\n",
                                  sim->fluid[x].name, d->sigma[x][y]);
                else
                    mf_log_printf(sim->log, MF_LOG_NORMAL,
                                  "surfaceTension: interface %s/%s: sigma = %g N/m\n",
                                  sim->fluid[x].name, sim->fluid[y].name, d->sigma[x][y]);
            }
    if (!d->any)
        mf_log_printf(sim->log, MF_LOG_NORMAL,
                      "surfaceTension: every sigma is 0 (constant/fluids): no force\n");
    return 0;
}

static int st_create(const void *settings, mf_sim *sim, void **data)
{
    st_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    int rc = st_create_data(settings, sim, d);
    if (rc != 0) {
        st_destroy(d);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    *data = d;
    return 0;
}

/* The copies [n_owned, n) of what a pass computed on the owned particles
 * (other ranks' particles, periodic images), for the next pass, which reads
 * its neighbours' values: nothing without copies. */
static int sync(const mf_sim *sim, void *values, size_t size)
{
    MF_CALL(mf_halo_update(sim->halo, sim->par, sim->p, values, size));
    return 0;
}

static inline int fluid_of(const int32_t *fid, size_t i) { return fid ? fid[i] : 0; }

/* Same fluid as x (walls and dummies count as every fluid's own). */
static inline bool own(const mf_particles *p, const int32_t *fid, size_t j, int x)
{
    return p->kind[j] != MF_FLUID || fluid_of(fid, j) == x;
}

/* Work arrays, one entry per particle. */
static int reserve(st_data *d, size_t n)
{
    if (n <= d->cap)
        return 0;
    size_t cap = n + n / 4 + 64;
    int32_t *n1 = realloc(d->n1, cap * sizeof *n1);
    if (n1)
        d->n1 = n1;
    int32_t *nall = realloc(d->nall, cap * sizeof *nall);
    if (nall)
        d->nall = nall;
    double *k = realloc(d->kappa, cap * sizeof *k);
    if (k)
        d->kappa = k;
    double *ks = realloc(d->kappa_s, cap * sizeof *ks);
    if (ks)
        d->kappa_s = ks;
    double *f = realloc(d->fdir, 3 * cap * sizeof *f);
    if (f)
        d->fdir = f;
    double *nr = realloc(d->nrm, 3 * cap * sizeof *nr);
    if (nr)
        d->nrm = nr;
    double *ps = realloc(d->p_surface, cap * sizeof *ps);
    if (ps)
        d->p_surface = ps;
    double *ko = realloc(d->kappa_out, cap * sizeof *ko);
    if (ko)
        d->kappa_out = ko;
    double *ao = realloc(d->accel_out, 3 * cap * sizeof *ao);
    if (ao)
        d->accel_out = ao;
    if (!n1 || !nall || !k || !ks || !f || !nr || !ps || !ko || !ao)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particles", n);
    d->cap = cap;
    return 0;
}

/* What the loops below share: the pairs within r_st and the fields. */
typedef struct st_ctx {
    st_data *d;
    const mf_particles *p;
    const int32_t *fid;
    const mf_pairs *v;
    double n_full, thr;
    const double *kin; /* curvature smoothing: the pass's input */
    double *kout;
    const double *kap; /* the force and the surface pressure: the curvature */
    double *acc, *accel_out, *kappa_out;
    const mf_sim *sim;
} st_ctx;

/* eqs. 34-35: n^st1 (own fluid, walls included) and the count of every
 * particle within r_st. */
typedef struct count_acc {
    int x;
    int32_t own_count, all;
} count_acc;

static inline bool count_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    count_acc *a = acc;
    if (pr->len >= c->d->r)
        return true;
    a->all++;
    a->own_count += own(c->p, c->fid, pr->j, a->x);
    return true;
}

static void count_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    count_acc a = {0, 0, 0};
    if (c->p->kind[i] == MF_FLUID) {
        a.x = fluid_of(c->fid, i);
        mf_pairs_row(c->v, i, NULL, count_pair, c, &a);
    }
    c->d->n1[i] = a.own_count;
    c->d->nall[i] = a.all;
}

static void count_neighbours(const st_ctx *c)
{
    mf_pairs_each(c->v, NULL, count_row, c);
}

/* A neighbour within r_st that misses neighbours (ends the row). */
static inline bool deep_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    bool *deep = acc;
    *deep = !(c->p->kind[pr->j] == MF_FLUID && c->d->nall[pr->j] < c->thr && pr->len < c->d->r);
    return *deep;
}

/* The full count of the current packing: the mean count of the fluid
 * particles deeper than r_st inside (no particle within r_st that misses
 * neighbours); the lattice's N_full until there are such particles.
 * Disorder changes the count by a particle or two out of 30, which the
 * curvature of eqs. 38-39 would read as 0.05 / l0; a count-based choice of
 * the particles (count above a threshold) would be biased the same way. */
static double measured_full_count(st_ctx *c)
{
    const st_data *d = c->d;
    const mf_particles *p = c->p;
    c->thr = d->s.beta * d->n_full;
    double sum = 0;
    size_t count = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID || d->nall[i] < c->thr)
            continue;
        bool deep = true;
        mf_pairs_row(c->v, i, NULL, deep_pair, c, &deep);
        if (deep) {
            sum += d->nall[i];
            count++;
        }
    }
    double v[2] = {sum, (double)count}; /* over the ranks */
    mf_parallel_sum(c->sim->par, v, 2);
    return v[1] > 0 ? v[0] / v[1] : d->n_full;
}

static void copy_mark_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    c->d->kappa_s[i] = c->d->fdir[3 * i];
}

typedef struct normal_acc {
    int x;
    double m[3];
} normal_acc;

static inline bool normal_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    normal_acc *a = acc;
    const size_t j = pr->j;
    if (c->p->kind[j] != MF_FLUID)
        return true;
    const double len = pr->len, rst = c->d->r;
    if (len >= rst || len <= 0)
        return true;
    double w = colour_weight(len, rst) * (fluid_of(c->fid, j) == a->x ? 1.0 : -1.0);
    for (int q = 0; q < 3; q++)
        a->m[q] += w * c->d->nrm[3 * j + q];
    return true;
}

static void normal_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    st_data *d = c->d;
    const double *ni = &d->nrm[3 * i];
    normal_acc a = {0, {ni[0], ni[1], ni[2]}};
    if (a.m[0] != 0 || a.m[1] != 0 || a.m[2] != 0) {
        a.x = fluid_of(c->fid, i);
        mf_pairs_row(c->v, i, NULL, normal_pair, c, &a);
        double len = sqrt(a.m[0] * a.m[0] + a.m[1] * a.m[1] + a.m[2] * a.m[2]);
        for (int q = 0; q < 3; q++)
            a.m[q] = len > 0 ? a.m[q] / len : 0.0;
    }
    for (int q = 0; q < 3; q++)
        d->fdir[3 * i + q] = a.m[q];
}

/* The normals averaged over the interface particles within r_st (weight
 * psi, another fluid's normal reversed) and renormalised: on a lattice the
 * raw normals follow the staircase of the particle rows, whose divergence
 * is noise of the order of 1 / l0. kappa_s is the scratch copy. */
static void smooth_normals(const st_ctx *c)
{
    st_data *d = c->d;
    const long np = (long)c->p->n_owned;
    double *out = d->fdir; /* fdir[3i] (free-surface mark) is saved below */
    double *mark = d->kappa_s;
    mf_pairs_each(c->v, NULL, copy_mark_row, c);
    mf_pairs_each(c->v, NULL, normal_row, c);
    for (long i = 0; i < np; i++) {
        for (int q = 0; q < 3; q++) {
            double t = d->nrm[3 * i + q];
            d->nrm[3 * i + q] = out[3 * i + q];
            out[3 * i + q] = t;
        }
        out[3 * i] = mark[i];
    }
}

/* Inverse of a symmetric 2x2 or 3x3 matrix; false when nearly singular. */
static bool invert_sym(int dim, const double m[3][3], double inv[3][3])
{
    if (dim == 2) {
        double det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        double scale = m[0][0] * m[1][1];
        if (!(fabs(det) > 1e-6 * fabs(scale)) || det == 0)
            return false;
        memset(inv, 0, 9 * sizeof(double));
        inv[0][0] = m[1][1] / det;
        inv[1][1] = m[0][0] / det;
        inv[0][1] = inv[1][0] = -m[0][1] / det;
        return true;
    }
    double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1], c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2],
           c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    double scale = m[0][0] * m[1][1] * m[2][2];
    if (!(fabs(det) > 1e-6 * fabs(scale)) || det == 0)
        return false;
    inv[0][0] = c00 / det;
    inv[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
    inv[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
    inv[1][0] = c01 / det;
    inv[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
    inv[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
    inv[2][0] = c02 / det;
    inv[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
    inv[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
    return true;
}

typedef struct div_acc {
    int x;
    const double *ni;
    double A[3][3], M[3][3];
} div_acc;

static inline bool div_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    div_acc *a = acc;
    const size_t j = pr->j;
    if (c->p->kind[j] != MF_FLUID)
        return true;
    const double *nj = &c->d->nrm[3 * j];
    if (nj[0] == 0 && nj[1] == 0 && nj[2] == 0)
        return true;
    const double len = pr->len, rst = c->d->r, *r = pr->r;
    if (len >= rst || len <= 0)
        return true;
    double sign = fluid_of(c->fid, j) == a->x ? 1.0 : -1.0;
    double w = colour_weight(len, rst) / (len * len);
    const int dim = c->d->dim;
    for (int q = 0; q < dim; q++)
        for (int b = 0; b < dim; b++) {
            a->A[q][b] += w * (sign * nj[q] - a->ni[q]) * r[b];
            a->M[q][b] += w * r[q] * r[b];
        }
    return true;
}

static void div_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    st_data *d = c->d;
    if (isnan(d->kappa[i]))
        return;
    const double *ni = &d->nrm[3 * i];
    if (ni[0] == 0 && ni[1] == 0 && ni[2] == 0) {
        d->kappa[i] = 0;
        return;
    }
    div_acc a = {fluid_of(c->fid, i), ni, {{0}}, {{0}}};
    mf_pairs_row(c->v, i, NULL, div_pair, c, &a);
    const int dim = d->dim;
    const double rst = d->r;
    double inv[3][3];
    double kappa = 0;
    if (invert_sym(dim, a.M, inv))
        for (int q = 0; q < dim; q++)
            for (int b = 0; b < dim; b++)
                kappa += a.A[q][b] * inv[b][q];
    /* A particle cannot resolve a radius below r_st / 2 (the count
     * models' limit too): a corner's normals would ask for more. */
    const double kmax = (dim == 3 ? 4.0 : 2.0) / rst;
    d->kappa[i] = fmax(-kmax, fmin(kmax, kappa));
}

/* curvature normal: kappa = div n (n the outward unit normal; Brackbill et
 * al. 1992) from the MPS gradient (eq. 5) of n over the neighbours that
 * have a normal, corrected by the moment matrix of those neighbours,
 *   grad n = [sum_j psi (n_j - n_i) r_ij^T / r^2] [sum_j psi r_ij r_ij^T / r^2]^-1,
 * psi = (1 - r/r_st)^2, exact for a linear field whatever the neighbours (the
 * interface band is one-sided: the plain MPS divergence reads twice the
 * curvature there). A particle of another fluid contributes minus its normal
 * (the same interface seen from the other side). Insensitive to a change of
 * the particle density, which moves the counts of eq. 39. */
static void normal_divergence(const st_ctx *c)
{
    mf_pairs_each(c->v, NULL, div_row, c);
}

typedef struct mean_kappa_acc {
    int x;
    double sw, sk;
} mean_kappa_acc;

static inline bool surface_kappa_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    mean_kappa_acc *a = acc;
    const size_t j = pr->j;
    const st_data *d = c->d;
    if (c->p->kind[j] != MF_FLUID || d->fdir[3 * j] == 0 || isnan(c->kap[j]) ||
        fluid_of(c->fid, j) != a->x)
        return true;
    const double len = pr->len, rst = d->r;
    if (len >= rst)
        return true;
    a->sw += 1 - len / rst;
    a->sk += (1 - len / rst) * c->kap[j];
    return true;
}

static void surface_pressure_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    st_data *d = c->d;
    d->p_surface[i] = NAN;
    if (c->p->kind[i] != MF_FLUID)
        return;
    const int x = fluid_of(c->fid, i);
    const double sig = d->sigma[x][x];
    if (!(sig > 0))
        return;
    if (d->fdir[3 * i] != 0 && !isnan(c->kap[i])) {
        d->p_surface[i] = sig * c->kap[i];
        return;
    }
    mean_kappa_acc a = {x, 0, 0};
    mf_pairs_row(c->v, i, NULL, surface_kappa_pair, c, &a);
    if (a.sw > 0)
        d->p_surface[i] = sig * a.sk / a.sw;
}

/* freeSurface pressure: the Laplace pressure sigma_x kappa of every fluid
 * particle near a free surface of a fluid with sigma_x > 0, for the solver
 * to hold on its free-surface (Dirichlet) particles of eq. 18 at r*. A
 * free-surface interface particle takes its own (smoothed) curvature; any
 * other particle the mean of those within r_st (weight 1 - r/r_st): the
 * solver's free surface (n* < beta n0 at r*) is not exactly the one found
 * here (a count within r_st at r^n). NAN where there is none. */
static void surface_pressure(const st_ctx *c)
{
    mf_pairs_each(c->v, NULL, surface_pressure_row, c);
    c->d->p_surface_n = c->p->n_owned;
}

/* Interface particles and their curvature (eqs. 36-39); kappa = NAN off the
 * interface. fdir[3i] = 1 marks a free surface. */
typedef struct iface_acc {
    int x;
    double n2, g[3];
    bool other;
} iface_acc;

static inline bool iface_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    iface_acc *a = acc;
    const st_data *d = c->d;
    const size_t i = pr->i, j = pr->j;
    const double len = pr->len, rst = d->r;
    if (len >= rst || len <= 0)
        return true;
    /* colour gradient of the own fluid: toward own, away from others */
    const bool mine = own(c->p, c->fid, j, a->x);
    double s = (mine ? 1.0 : -1.0) * colour_weight(len, rst) / len;
    for (int q = 0; q < 3; q++)
        a->g[q] += s * pr->r[q];
    if (mine) {
        if (c->p->kind[j] != MF_FLUID || d->n1[j] > d->n1[i])
            a->n2 += 1; /* eq. 37: deeper inside than i */
        else if (d->n1[j] == d->n1[i])
            a->n2 += 0.5;
    } else if (d->sigma[a->x][fluid_of(c->fid, j)] > 0) {
        a->other = true;
    }
    return true;
}

static void iface_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    st_data *d = c->d;
    d->kappa[i] = NAN;
    d->nrm[3 * i] = d->nrm[3 * i + 1] = d->nrm[3 * i + 2] = 0;
    if (c->p->kind[i] != MF_FLUID)
        return;
    iface_acc a = {fluid_of(c->fid, i), 0, {0, 0, 0}, false};
    mf_pairs_row(c->v, i, NULL, iface_pair, c, &a);
    const int x = a.x;
    const double *g = a.g;
    bool free_surface = d->nall[i] < d->s.beta * c->n_full && d->sigma[x][x] > 0;
    d->fdir[3 * i] = free_surface;
    double gm = d->g_coef * sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    bool interface = a.other || free_surface;
    for (int q = 0; q < 3; q++) /* outward: against the colour gradient */
        d->nrm[3 * i + q] = interface && gm >= 0.1 * d->g_ref ? -d->g_coef * g[q] / gm : 0.0;
    if (!interface)
        return;
    /* eq. 39: n^st2 against its flat-interface value n0^st, half the full
     * count. Where the probe is full (an interface between fluids), the
     * particle's own count of every particle is that full count. */
    double full = free_surface ? c->n_full : (double)d->nall[i];
    d->kappa[i] = d->normal ? 0.0 : curvature(d, a.n2 / full);
}

/* One smoothing pass over the free-surface particles (see st_accumulate). */
typedef struct smooth_acc {
    int x;
    double sw, sk;
} smooth_acc;

static inline bool smooth_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    smooth_acc *a = acc;
    const size_t j = pr->j;
    const st_data *d = c->d;
    if (isnan(c->kin[j]) || d->fdir[3 * j] == 0 || c->p->kind[j] != MF_FLUID ||
        fluid_of(c->fid, j) != a->x)
        return true;
    const double len = pr->len, rst = d->r;
    if (len >= rst)
        return true;
    double w = 1 - len / rst;
    a->sw += w;
    a->sk += w * c->kin[j];
    return true;
}

static void smooth_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    c->kout[i] = c->kin[i];
    if (isnan(c->kin[i]) || c->d->fdir[3 * i] == 0) /* free-surface particles only */
        return;
    smooth_acc a = {fluid_of(c->fid, i), 1, c->kin[i]};
    mf_pairs_row(c->v, i, NULL, smooth_pair, c, &a);
    c->kout[i] = a.sk / a.sw;
}

/* sigma kappa delta n of one particle (see st_accumulate). */
typedef struct force_acc {
    int x;
    bool free_surface;
    double f[3];
} force_acc;

static inline bool force_pair(void *acc, const void *ctx, const mf_pair *pr)
{
    const st_ctx *c = ctx;
    force_acc *a = acc;
    const st_data *d = c->d;
    const size_t i = pr->i, j = pr->j;
    const double len = pr->len, rst = d->r;
    if (len >= rst || len <= 0)
        return true;
    const int x = a->x;
    double s = colour_weight(len, rst) / len; /* phi(r) r_hat */
    double coef = a->free_surface && !d->pressure_mode ? 2 * d->sigma[x][x] * c->kap[i] : 0.0;
    if (!own(c->p, c->fid, j, x)) {
        double kj = isnan(c->kap[j]) ? -c->kap[i] : c->kap[j];
        coef -= d->sigma[x][fluid_of(c->fid, j)] * 0.5 * (c->kap[i] - kj);
    }
    for (int q = 0; q < 3; q++)
        a->f[q] += coef * s * pr->r[q];
    return true;
}

static void force_row(const void *ctx, size_t i)
{
    const st_ctx *c = ctx;
    const st_data *d = c->d;
    if (isnan(c->kap[i]))
        return;
    force_acc a = {fluid_of(c->fid, i), d->fdir[3 * i] != 0, {0, 0, 0}};
    mf_pairs_row(c->v, i, NULL, force_pair, c, &a);
    const double rho = c->sim->fluid[a.x].rho;
    for (int q = 0; q < 3; q++) {
        c->accel_out[3 * i + q] = d->g_coef * a.f[q] / rho;
        c->acc[3 * i + q] += c->accel_out[3 * i + q];
    }
    c->kappa_out[i] = c->kap[i];
}

static int st_accumulate(void *data, const mf_sim *sim, double *acc)
{
    st_data *d = data;
    const mf_particles *p = sim->p;
    d->p_surface_n = 0;
    d->out_n = 0;
    if (!d->any)
        return 0;
    if (d->pressure_mode && !d->claimed)
        return MF_ERROR(MF_ERR_INPUT, "system/solverDict: forces { surfaceTension { "
                        "freeSurface pressure; } } makes the Laplace pressure the free "
                        "surface's Dirichlet value, which this solver does not apply (use "
                        "solver multiFluid with one pressure solve per step, or freeSurface "
                        "force)");
    mf_pairs v;
    MF_CALL(mf_neighbours_pairs(sim->neighbours, p, d->pairs, &v));
    MF_CALL(reserve(d, p->n));
    double *kappa_out = d->kappa_out, *accel_out = d->accel_out;
    memset(kappa_out, 0, p->n * sizeof *kappa_out);
    memset(accel_out, 0, 3 * p->n * sizeof *accel_out);
    d->out_n = p->n;
    int ff = mf_particles_field_index(p, "FluidId");
    st_ctx c = {.d = d, .p = p, .fid = ff >= 0 ? mf_particles_fi(p, ff) : NULL, .v = &v,
                .acc = acc, .accel_out = accel_out, .kappa_out = kappa_out, .sim = sim};
    count_neighbours(&c);
    MF_CALL(sync(sim, d->n1, sizeof *d->n1));
    MF_CALL(sync(sim, d->nall, sizeof *d->nall));
    c.n_full = measured_full_count(&c);
    mf_pairs_each(&v, NULL, iface_row, &c);
    MF_CALL(sync(sim, d->nrm, 3 * sizeof *d->nrm));
    MF_CALL(sync(sim, d->fdir, 3 * sizeof *d->fdir));
    MF_CALL(sync(sim, d->kappa, sizeof *d->kappa));
    if (d->normal) {
        smooth_normals(&c);
        MF_CALL(sync(sim, d->nrm, 3 * sizeof *d->nrm));
        MF_CALL(sync(sim, d->fdir, 3 * sizeof *d->fdir));
        normal_divergence(&c);
        MF_CALL(sync(sim, d->kappa, sizeof *d->kappa));
    }
    /* Smoothing (free surfaces): the mean of kappa over the free-surface
     * particles of the same fluid within r_st, weight 1 - r/r_st. A free
     * surface is picked by a count and its normal is one-sided: in motion its
     * curvature is noisy, and the noise, multiplied by delta n, does not
     * average out (a 2-D drop: the force jump 1.26 sigma/R unsmoothed, 1.02
     * smoothed). An interface between fluids is not smoothed: there the
     * average over its band of 2 r_st would pull kappa down (0.87 of 1/R on
     * a lattice drop). */
    double *kin = d->kappa, *kout = d->kappa_s;
    for (long pass = 0; pass < d->s.smoothing; pass++) {
        c.kin = kin;
        c.kout = kout;
        mf_pairs_each(&v, NULL, smooth_row, &c);
        MF_CALL(sync(sim, kout, sizeof *kout));
        double *t = kin;
        kin = kout;
        kout = t;
    }
    /* sigma kappa delta n. An unlike pair (i in x, j in y) adds
     * -sigma_xy kappa_ij C phi r_hat_ij to both i and j, kappa_ij the mean of
     * the curvature seen from x and minus the one seen from y: the two sides
     * of an interface carry the same force, half the jump each (unequal
     * shares pull one side off the other and open a gap). A free surface
     * adds 2 sigma_x kappa_i C sum phi r_hat over the particles present. */
    c.kap = kin;
    mf_pairs_each(&v, NULL, force_row, &c);
    if (d->pressure_mode)
        surface_pressure(&c);
    return 0;
}

/* The Curvature and SurfaceTension fields from the last accumulate. */
static int st_write_fields(void *data, mf_sim *sim)
{
    const st_data *d = data;
    const mf_particles *p = sim->p;
    double *kappa = mf_particles_fd(p, d->f_curvature);
    double *accel = mf_particles_fd(p, d->f_accel);
    const size_t n = d->out_n <= p->n ? d->out_n : 0;
    if (n)
        memcpy(kappa, d->kappa_out, n * sizeof *kappa);
    if (n)
        memcpy(accel, d->accel_out, 3 * n * sizeof *accel);
    memset(kappa + n, 0, (p->n - n) * sizeof *kappa);
    memset(accel + 3 * n, 0, 3 * (p->n - n) * sizeof *accel);
    return 0;
}

/* Brackbill et al. (1992): a capillary wave must not cross a particle in a
 * step, dt <= sqrt(rho_bar l0^3 / (2 pi sigma)). */
static int st_stable_dt(void *data, const mf_sim *sim, double *out)
{
    const st_data *d = data;
    double dt = INFINITY;
    for (int x = 0; x < d->nfluids; x++)
        for (int y = x; y < d->nfluids; y++) {
            double sig = d->sigma[x][y];
            if (!(sig > 0))
                continue;
            double rho = x == y ? sim->fluid[x].rho : 0.5 * (sim->fluid[x].rho + sim->fluid[y].rho);
            double lim = d->s.dt_factor * sqrt(rho * pow(d->l0, 3) / (2 * M_PI * sig));
            if (lim < dt)
                dt = lim;
        }
    *out = dt;
    return 0;
}

static bool st_claim_surface_pressure(void *data)
{
    st_data *d = data;
    if (!(d->pressure_mode && d->any))
        return false;
    d->claimed = true;
    return true;
}

static int st_surface_pressure(void *data, const mf_sim *sim, const uint8_t *dirichlet,
                               double *p)
{
    const st_data *d = data;
    const mf_particles *ps = sim->p;
    if (!d->pressure_mode)
        return 0;
    for (size_t i = 0; i < d->p_surface_n && i < ps->n_owned; i++)
        if (dirichlet[i] && ps->kind[i] == MF_FLUID && !isnan(d->p_surface[i]))
            p[i] += d->p_surface[i];
    return 0;
}

const mf_force_ops mf_force_surfaceTension = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "surfaceTension",
             "surface tension sigma kappa delta n, curvature from particle counts (Appendix A, "
             "Nomura et al. 2001)",
             st_params, ST_NPARAMS, sizeof(st_settings)},
    .create = st_create,
    .accumulate = st_accumulate,
    .destroy = st_destroy,
    .flags = MF_FORCE_INTERNAL,
    .stable_dt = st_stable_dt,
    .write_fields = st_write_fields,
    .claim_surface_pressure = st_claim_surface_pressure,
    .surface_pressure = st_surface_pressure,
};
