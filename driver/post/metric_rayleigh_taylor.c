/* metric_rayleigh_taylor.c: the Rayleigh-Taylor instability (multi-fluid
 * cases): the spike (lowest heavy particle) and bubble (highest light
 * particle) against time; error = the share of the available potential
 * energy not yet released at the last snapshot (0: the fluids have
 * swapped). The set-up is that of the PySPH examples (heavy 1.8 over light
 * 1, g = 1, interface y = 1 - 0.15 sin(2 pi x), Re = 420). */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_snapshots.h"
#include "mf_error.h"
#include "mf_post.h"

typedef struct rt_settings {
    const char *metric, *heavy, *light;
    double bottom, height, gravity;
} rt_settings;


static const mf_param rt_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(rt_settings, metric),
     "rayleighTaylor"},
    {"heavyFluid", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(rt_settings, heavy),
     "the denser fluid (on top at the start)"},
    {"lightFluid", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(rt_settings, light),
     "the lighter fluid"},
    {"bottom", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL, offsetof(rt_settings, bottom),
     "height of the floor, m"},
    {"height", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(rt_settings, height),
     "height of the domain, m"},
    {"gravity", MF_PARAM_SCALAR, "1", 1e-9, 1e9, NULL, offsetof(rt_settings, gravity),
     "g, m/s^2"},
};

static int rt_evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    const char *case_dir = ctx->case_dir;
    rt_settings s = *(const rt_settings *)settings;
    int heavy = 0, light = 0;
    MF_CALL(mf_post_fluid_index(case_dir, s.heavy, &heavy));
    MF_CALL(mf_post_fluid_index(case_dir, s.light, &light));
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    mf_table t = {.ncols = 4};
    int rc = 0;
    double e0 = 0, e_end = 0, e_min = 0;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        mf_fsnap sn;
        rc = mf_fsnap_load(case_dir, idx[k], &sn);
        if (rc != 0)
            break;
        if (!sn.fid) {
            mf_fsnap_free(&sn);
            rc = MF_ERROR(MF_ERR_INPUT, "%s: the snapshots have no FluidId", case_dir);
            break;
        }
        const mf_particles *p = sn.sim.p;
        double spike = INFINITY, bubble = -INFINITY, sh = 0;
        size_t nh = 0;
        for (size_t i = 0; i < p->n; i++) {
            if (p->kind[i] != MF_FLUID)
                continue;
            double y = p->pos[3 * i + 1];
            if (sn.fid[i] == heavy) {
                spike = fmin(spike, y);
                sh += y - s.bottom;
                nh++;
            } else if (sn.fid[i] == light) {
                bubble = fmax(bubble, y);
            }
        }
        /* Potential energy of the density excess: (rho_h - rho_l) g sum y V,
         * as a mean height of the heavy particles (the light ones fill the
         * rest). Fully overturned: the heavy fluid in the bottom layer. */
        double ybar = nh ? sh / (double)nh : 0;
        if (k == 0) {
            e0 = ybar;
            double frac = 0; /* heavy share of the domain height */
            size_t nall = 0;
            for (size_t i = 0; i < p->n; i++)
                nall += p->kind[i] == MF_FLUID;
            frac = nall ? (double)nh / (double)nall : 0;
            e_min = 0.5 * frac * s.height;
        }
        e_end = ybar;
        double row[4] = {sn.h.time, spike - s.bottom, bubble - s.bottom, ybar};
        rc = mf_table_add(&t, row);
        mf_fsnap_free(&sn);
    }
    free(idx);
    if (rc == 0 && t.n < 2)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: fewer than two snapshots", case_dir);
    if (rc == 0) {
        *error = e0 > e_min ? (e_end - e_min) / (e0 - e_min) : 0;
        char comment[768], title[256];
        snprintf(comment, sizeof comment,
                 "Rayleigh-Taylor: spike = lowest %s particle, bubble = highest %s particle "
                 "(heights above the floor)\nmean height of the heavy fluid: %.6g m at the "
                 "start, %.6g m at the end, %.6g m fully overturned; error = share of the "
                 "available potential energy left = %.6g",
                 s.heavy, s.light, e0, e_end, e_min, *error);
        snprintf(title, sizeof title, "Rayleigh-Taylor (potential energy left %.3g)", *error);
        mf_plot plot = {title, "t, s", "height, m", false, false, NULL};
        mf_series series[3] = {
            {"spike (heavy, lowest)", t.col[0], t.col[1], t.n, "lines lw 2", NULL},
            {"bubble (light, highest)", t.col[0], t.col[2], t.n, "lines lw 2", NULL},
            {"heavy mean height", t.col[0], t.col[3], t.n, "lines", NULL}};
        rc = mf_table_report(ctx->out_dir, comment, "t,spike,bubble,heavy_mean_height", &t, &plot,
                          series, 3);
    }
    mf_table_free(&t);
    return rc;
}

const mf_metric_ops mf_metric_rayleigh_taylor = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "rayleighTaylor",
     "spike and bubble of a Rayleigh-Taylor instability",
     rt_params, sizeof rt_params / sizeof rt_params[0], sizeof(rt_settings)},
    rt_evaluate,
    NULL,
};
