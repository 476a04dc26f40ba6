/* metric_layering.c: two fluids settling (multi-fluid cases): error = the
 * fraction of light particles below the interface height (the height the
 * heavy fluid would fill), time-averaged after settleTime; the CSV has both
 * mean heights. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_snapshots.h"
#include "mf_error.h"
#include "mf_post.h"

typedef struct layer_settings {
    const char *metric, *heavy, *light;
    double bottom, cross, settle;
} layer_settings;


static const mf_param layer_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(layer_settings, metric),
     "layering"},
    {"heavyFluid", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(layer_settings, heavy),
     "the denser fluid"},
    {"lightFluid", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(layer_settings, light),
     "the lighter fluid"},
    {"bottom", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL, offsetof(layer_settings, bottom),
     "height of the floor, m"},
    {"crossSection", MF_PARAM_SCALAR, NULL, 1e-12, 1e12, NULL,
     offsetof(layer_settings, cross), "width (2-D, m) or floor area (3-D, m^2) of the tank"},
    {"settleTime", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(layer_settings, settle),
     "average over the snapshots after this time, s"},
};

static int layer_evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    const char *case_dir = ctx->case_dir;
    layer_settings s = *(const layer_settings *)settings;
    int heavy = 0, light = 0;
    MF_CALL(mf_post_fluid_index(case_dir, s.heavy, &heavy));
    MF_CALL(mf_post_fluid_index(case_dir, s.light, &light));
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    mf_table t = {.ncols = 5};
    int rc = 0;
    double below_sum = 0, h_int = 0, yh_sum = 0, yl_sum = 0;
    size_t used = 0;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        mf_fsnap sn;
        rc = mf_fsnap_load(case_dir, idx[k], &sn);
        if (rc != 0)
            break;
        if (!sn.fid) {
            mf_fsnap_free(&sn);
            rc = MF_ERROR(MF_ERR_INPUT, "%s: the snapshots have no FluidId (one fluid?)",
                          case_dir);
            break;
        }
        const mf_particles *p = sn.sim.p;
        double yh = 0, yl = 0;
        size_t nh = 0, nlight = 0, below = 0;
        for (size_t i = 0; i < p->n; i++) {
            if (p->kind[i] != MF_FLUID)
                continue;
            if (sn.fid[i] == heavy) {
                yh += p->pos[3 * i + 1];
                nh++;
            } else if (sn.fid[i] == light) {
                yl += p->pos[3 * i + 1];
                nlight++;
            }
        }
        /* The heavy fluid filling the bottom: N l0^d / crossSection high. */
        h_int = s.bottom + (double)nh * pow(sn.h.l0, sn.h.dim) / s.cross;
        for (size_t i = 0; i < p->n; i++)
            if (p->kind[i] == MF_FLUID && sn.fid[i] == light && p->pos[3 * i + 1] < h_int)
                below++;
        double frac = nlight ? (double)below / (double)nlight : 0;
        double row[5] = {sn.h.time, nh ? yh / (double)nh : 0, nlight ? yl / (double)nlight : 0,
                         h_int, 1 - frac};
        rc = mf_table_add(&t, row);
        if (rc == 0 && sn.h.time >= s.settle) {
            below_sum += frac;
            yh_sum += row[1];
            yl_sum += row[2];
            used++;
        }
        mf_fsnap_free(&sn);
    }
    free(idx);
    if (rc == 0 && used == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no snapshot after settleTime %g", case_dir, s.settle);
    if (rc == 0) {
        *error = below_sum / (double)used;
        char comment[768], title[256];
        snprintf(comment, sizeof comment,
                 "layering of %s (light) over %s (heavy): interface height h = bottom + "
                 "N_heavy l0^d / crossSection = %.6g m\nafter t = %g s (%zu snapshots): mean "
                 "height heavy %.6g m, light %.6g m; fraction of light particles below h "
                 "(the error) %.6g",
                 s.light, s.heavy, h_int, s.settle, used, yh_sum / (double)used,
                 yl_sum / (double)used, *error);
        snprintf(title, sizeof title, "Layering: %s over %s (light below h: %.3g)", s.light,
                 s.heavy, *error);
        mf_plot plot = {title, "t, s", "mean height, m", false, false, NULL};
        mf_series series[3] = {{s.heavy, t.col[0], t.col[1], t.n, "linespoints", NULL},
                               {s.light, t.col[0], t.col[2], t.n, "linespoints", NULL},
                               {"interface height", t.col[0], t.col[3], t.n, "lines", NULL}};
        rc = mf_table_report(ctx->out_dir, comment, "t,y_heavy,y_light,h_interface,light_above",
                          &t, &plot, series, 3);
    }
    mf_table_free(&t);
    return rc;
}

const mf_metric_ops mf_metric_layering = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "layering",
     "two fluids settled: light above the interface height",
     layer_params, sizeof layer_params / sizeof layer_params[0], sizeof(layer_settings)},
    layer_evaluate,
    NULL,
};
