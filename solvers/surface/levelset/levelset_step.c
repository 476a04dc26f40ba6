/* levelset_step.c: one frame of the level set reconstruction (section 4).
 *
 *   1. the field F of eqs. 30-32 from the fluid particles (ls_field.c);
 *   2. the bricks its zero level crosses (ls_detect.c);
 *   3. seeds of the band: the first frame starts from F = 0 (the points next
 *      to its zero level, at their sub-cell distance); a later frame starts
 *      from the previous frame's phi (its evolved points, |phi| <= band
 *      width, keep their values: no re-initialisation, so consecutive
 *      surfaces are continuous; only the rim is marched again). Where the fluid has moved by more than about a brick (8
 *      cells) since the last frame, or has appeared, the old surface has no
 *      F-crossing near it and the new F-crossing no old surface near it: there
 *      the frame starts from F = 0 locally;
 *   4. the band by fast marching from the seeds, F on it (ls_band.c);
 *   5. eq. 29 in pseudo-time until converged (ls_arkode.c, ls_rhs.c);
 *   6. the mesh of phi = 0 (ls_mesh.c).
 * The band is kept for the next frame. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "levelset.h"

/* The bricks of a set and their 26 neighbours. */
static int dilate_bricks(const ls_bricks *in, ls_bricks *out)
{
    ls_bricks_clear(out);
    for (size_t k = 0; k < in->n; k++) {
        const int32_t *c = &in->coord[3 * k];
        for (int dz = -1; dz <= 1; dz++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int32_t idx;
                    MF_CALL(ls_bricks_insert(out, c[0] + dx, c[1] + dy, c[2] + dz, &idx, NULL));
                }
    }
    return 0;
}

static inline bool seed_in(const ls_bricks *set, const ls_seed *s)
{
    return ls_bricks_find(set, ls_brick_of(s->x), ls_brick_of(s->y), ls_brick_of(s->z)) !=
           LS_NONE;
}

/* Seeds of a warm start: the old evolved points (|phi| <= band width) near
 * the new F crossing, plus the F seeds far from any kept old point. Keeping
 * the evolved values, not only the interface's, leaves less to march (the
 * rim only) and starts the band where the last frame's evolution left it. */
static int warm_seeds(const ls_band *old, const ls_crossing *cross, const ls_seed *fs,
                      size_t nfs, ls_seed **out, size_t *nout, size_t *nkept, size_t *nnew)
{
    ls_seed *os = NULL;
    size_t nos = 0;
    MF_CALL(ls_band_within(old, old->width, &os, &nos));
    ls_bricks near_cross, kept_bricks, near_kept;
    ls_bricks_init(&near_cross);
    ls_bricks_init(&kept_bricks);
    ls_bricks_init(&near_kept);
    ls_seed *all = malloc((nos + nfs + 1) * sizeof *all);
    int rc = all ? dilate_bricks(&cross->b, &near_cross)
                 : MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu seeds", nos + nfs);
    size_t n = 0;
    for (size_t k = 0; k < nos && rc == 0; k++)
        if (seed_in(&near_cross, &os[k])) {
            all[n++] = os[k];
            int32_t idx;
            rc = ls_bricks_insert(&kept_bricks, ls_brick_of(os[k].x), ls_brick_of(os[k].y),
                                  ls_brick_of(os[k].z), &idx, NULL);
        }
    *nkept = n;
    if (rc == 0)
        rc = dilate_bricks(&kept_bricks, &near_kept);
    for (size_t k = 0; k < nfs && rc == 0; k++)
        if (!seed_in(&near_kept, &fs[k]))
            all[n++] = fs[k];
    *nnew = n - *nkept;
    free(os);
    ls_bricks_free(&near_cross);
    ls_bricks_free(&kept_bricks);
    ls_bricks_free(&near_kept);
    if (rc != 0) {
        free(all);
        return rc;
    }
    *out = all;
    *nout = n;
    return 0;
}

static void log_frame(const ls_data *d, const mf_sim *sim, double h, const ls_field *f,
                      const ls_crossing *cross, const ls_band *band, bool warm, size_t nkept,
                      size_t nnew, const mf_mesh *out)
{
    mf_log *log = sim->log;
    const ls_stats *st = &d->last;
    mf_log_printf(log, MF_LOG_NORMAL,
                  "levelSet: time %g, %zu fluid particles, grid spacing %g m (l0/h = %.3g); the "
                  "zero level of F crosses %zu bricks of 8^3 cells\n",
                  sim->time, f->n, h, sim->l0 / h, cross->b.n);
    if (warm)
        mf_log_printf(log, MF_LOG_NORMAL,
                      "levelSet: warm start from the previous frame's phi (%zu points kept, %zu "
                      "new from F = 0 where the fluid moved or appeared)\n",
                      nkept, nnew);
    else
        mf_log_printf(log, MF_LOG_NORMAL, "levelSet: cold start from F = 0 (%zu seed points)\n",
                      nnew);
    mf_log_printf(log, MF_LOG_NORMAL,
                  "levelSet: band of %zu points (%zu evolved) in %zu bricks, %.1f MB; %ld "
                  "rebuilds\n",
                  band->b.n * (size_t)LS_B3, band->nact, band->b.n,
                  ls_band_memory(band) / 1048576.0, st->rebuilds);
    if (d->imex)
        mf_log_printf(log, MF_LOG_NORMAL,
                      "levelSet ARKStep (IMEX Euler ARS(1,1,1), curvature implicit, SPGMR): %ld "
                      "steps (%ld stability-limited, %ld accuracy-limited), %ld error-test "
                      "failures; right-hand sides %ld explicit + %ld implicit + %ld in "
                      "Jacobian-vector products; Newton iterations %ld (%ld failed), SPGMR "
                      "iterations %ld (%ld failed)\n",
                      st->steps, st->steps_stability, st->steps_accuracy, st->error_fails,
                      st->rhs_explicit, st->rhs_implicit, st->rhs_jtimes, st->newton_iters,
                      st->newton_fails, st->lin_iters, st->lin_fails);
    else
        mf_log_printf(log, MF_LOG_NORMAL,
                      "levelSet ERKStep (damped Chebyshev RKC, %d stages at fixed steps of "
                      "%.3g): %ld steps, %ld right-hand sides, %ld chunks redone with a "
                      "smaller step\n",
                      st->stages, st->step, st->steps, st->rhs_explicit, st->redone);
    mf_log_printf(log, st->converged ? MF_LOG_NORMAL : MF_LOG_QUIET,
                  "levelSet: %s after pseudo-time %.4g: |dphi/dtau| near the surface %.3g "
                  "cells, tolerance %g\n",
                  st->converged ? "converged" : "Warning: NOT converged (maxSteps or "
                                                "maxPseudoTime reached; the surface is the last "
                                                "state)",
                  st->pseudo_time, st->last_change, d->s.tolerance);
    mf_log_printf(log, MF_LOG_NORMAL,
                  "levelSet: mesh of %zu vertices and %zu triangles; seconds wall (CPU, all "
                  "threads): field %.3f (%.3f), zero level %.3f (%.3f), band %.3f (%.3f), "
                  "evolution %.3f (%.3f), mesh %.3f (%.3f)\n",
                  out->nverts, out->ntris, d->t_field, d->c_field, d->t_detect, d->c_detect,
                  d->t_band, d->c_band, d->t_evolve, d->c_evolve, d->t_mesh, d->c_mesh);
}

int ls_frame(ls_data *d, const mf_sim *sim, mf_mesh *out)
{
    const ls_settings *s = &d->s;
    const double l0 = sim->l0, h = ls_grid_spacing(s->grid_spacing, l0);
    const size_t limit = ls_memory_limit(s->max_memory);
    char what[96];
    snprintf(what, sizeof what, "levelSet at time %g", sim->time);
    out->nverts = out->ntris = 0;
    out->time = sim->time;
    ls_field f;
    ls_crossing cross;
    ls_band band;
    ls_field_init(&f);
    ls_crossing_init(&cross);
    ls_band_init(&band, (double)s->band_width, limit);
    ls_seed *fs = NULL, *seeds = NULL;
    size_t nfs = 0, nseeds = 0, nkept = 0, nnew = 0;
    bool warm = false;
    int rc = 0;

    double t = mf_wall_seconds(), c = mf_cpu_seconds();
    MF_CALL_GOTO(rc, ls_field_setup(&f, sim->p, LS_KERNEL_LEVELSET, h, l0, s->radius, s->cutoff,
                                    (double)s->kernel_power, s->threshold, s->anisotropic, limit,
                                    what),
                 done);
    d->t_field = mf_wall_seconds() - t;
    d->c_field = mf_cpu_seconds() - c;
    t = mf_wall_seconds();
    c = mf_cpu_seconds();
    MF_CALL_GOTO(rc, ls_detect(&f, l0, limit, &cross), done);
    d->t_detect = mf_wall_seconds() - t;
    d->c_detect = mf_cpu_seconds() - c;

    t = mf_wall_seconds();
    c = mf_cpu_seconds();
    MF_CALL_GOTO(rc, ls_crossing_seeds(&cross, &fs, &nfs), done);
    warm = s->warm_start && d->have_previous && d->prev_h == h && d->band.b.n > 0;
    if (warm) {
        MF_CALL_GOTO(rc, warm_seeds(&d->band, &cross, fs, nfs, &seeds, &nseeds, &nkept, &nnew),
                     done);
    } else {
        seeds = fs;
        nseeds = nnew = nfs;
        fs = NULL;
    }
    if (nseeds == 0) {
        mf_log_printf(sim->log, MF_LOG_QUIET,
                      "levelSet: Warning: at time %g F = T + sum f_i is below 0 everywhere (T = "
                      "%g): no surface; isolated particles and thin sheets vanish when -T "
                      "exceeds the kernel sum they reach\n",
                      sim->time, s->threshold);
        ls_band_free(&d->band);
        d->have_previous = false;
        goto done;
    }
    MF_CALL_GOTO(rc, ls_band_from_seeds(&band, seeds, nseeds), done);
    MF_CALL_GOTO(rc, ls_band_fill_F(&band, &f, &cross.b, cross.F), done);
    d->t_band = mf_wall_seconds() - t;
    d->c_band = mf_cpu_seconds() - c;

    t = mf_wall_seconds();
    c = mf_cpu_seconds();
    ls_evolve_opts o = {
        .imex = d->imex,
        .alpha = s->alpha,
        .beta_grid = s->beta * l0 / h,
        .rel_tol = s->rel_tol,
        .abs_tol = s->abs_tol,
        .tolerance = s->tolerance,
        .max_steps = s->max_steps,
        .max_pseudo_time = s->max_pseudo_time,
    };
    MF_CALL_GOTO(rc, ls_evolve(&band, &f, &o, &d->last), done);
    d->t_evolve = mf_wall_seconds() - t;
    d->c_evolve = mf_cpu_seconds() - c;

    t = mf_wall_seconds();
    c = mf_cpu_seconds();
    MF_CALL_GOTO(rc, ls_mesh_extract(&band.b, band.nb, NULL, band.phi, band.flag, h, out), done);
    d->t_mesh = mf_wall_seconds() - t;
    d->c_mesh = mf_cpu_seconds() - c;
    if (ls_band_memory(&band) > d->peak_band_bytes)
        d->peak_band_bytes = ls_band_memory(&band);
    log_frame(d, sim, h, &f, &cross, &band, warm, nkept, nnew, out);

    /* keep this frame's band for the next one */
    ls_band_free(&d->band);
    d->band = band;
    ls_band_init(&band, (double)s->band_width, limit);
    d->have_previous = true;
    d->prev_h = h;
done:
    free(fs);
    free(seeds);
    ls_field_free(&f);
    ls_crossing_free(&cross);
    ls_band_free(&band);
    return rc;
}
