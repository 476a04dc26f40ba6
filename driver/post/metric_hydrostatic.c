/* metric_hydrostatic.c: pressure of a resting column against rho g (H - y).
 *
 * Over the snapshots after settleTime, the pressure of interior fluid
 * particles (not flagged as free surface) is averaged in time and in bins
 * of height l0. error = RMS over the bins of (p_avg - rho g (H - y)) / (rho g H),
 * H being the free-surface height. The CSV also lists the deepest bin's
 * relative error, the figure the hydrostatic test checks. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_post.h"
#include "mf_report.h"

typedef struct hydro_settings {
    const char *metric;
    double rho, g, surface, bottom, settle;
} hydro_settings;

static const mf_param hydro_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(hydro_settings, metric),
     "hydrostaticPressure"},
    {"rho", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(hydro_settings, rho),
     "density, kg/m^3"},
    {"gravity", MF_PARAM_SCALAR, "9.81", 1e-9, 1e9, NULL, offsetof(hydro_settings, g), "g, m/s^2"},
    {"surface", MF_PARAM_SCALAR, NULL, -1e9, 1e9, NULL, offsetof(hydro_settings, surface),
     "height of the free surface, m"},
    {"bottom", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL, offsetof(hydro_settings, bottom),
     "height of the floor, m"},
    {"settleTime", MF_PARAM_SCALAR, "0", 0, 1e9, NULL, offsetof(hydro_settings, settle),
     "average only snapshots after this time, s"},
};

static int evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    const char *case_dir = ctx->case_dir;
    hydro_settings s = *(const hydro_settings *)settings;
    const double H = s.surface - s.bottom;
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    size_t nbins = 0;
    double *psum = NULL, *count = NULL, l0 = 0;
    int rc = 0, used = 0;
    char path[4400];
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        mf_snapshot_path(case_dir, idx[k], path, sizeof path);
        mf_hdf5_header h;
        rc = mf_hdf5_read_header(path, &h);
        if (rc != 0 || h.time < s.settle)
            continue;
        mf_sim snap;
        memset(&snap, 0, sizeof snap);
        rc = mf_hdf5_read_snapshot(path, &snap);
        const mf_particles *p = snap.p;
        int fp = rc == 0 ? mf_particles_field_index(p, "Pressure") : -1;
        int ff = rc == 0 ? mf_particles_field_index(p, "Flags") : -1;
        if (rc == 0 && fp < 0)
            rc = MF_ERROR(MF_ERR_INPUT, "%s: no Pressure field", path);
        if (rc == 0 && !psum) {
            l0 = h.l0;
            nbins = (size_t)ceil(H / l0);
            psum = calloc(nbins, sizeof *psum);
            count = calloc(nbins, sizeof *count);
            if (!psum || !count)
                rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
        }
        for (size_t i = 0; rc == 0 && i < p->n; i++) {
            if (p->kind[i] != MF_FLUID || (ff >= 0 && mf_particles_fi(p, ff)[i] & 1))
                continue;
            double y = p->pos[3 * i + 1] - s.bottom;
            if (y < 0 || y >= H)
                continue;
            size_t b = (size_t)(y / l0);
            psum[b] += mf_particles_fd(p, fp)[i];
            count[b] += 1;
        }
        mf_particles_destroy(snap.p);
        used++;
    }
    free(idx);
    if (rc == 0 && used == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no snapshot after settleTime %g", case_dir, s.settle);
    double *y = calloc(nbins + 1, sizeof *y), *pavg = calloc(nbins + 1, sizeof *pavg),
           *pex = calloc(nbins + 1, sizeof *pex), *rel = calloc(nbins + 1, sizeof *rel);
    size_t nb = 0;
    double sum = 0;
    for (size_t b = 0; rc == 0 && y && pavg && pex && rel && b < nbins; b++) {
        if (count[b] == 0)
            continue;
        y[nb] = s.bottom + (b + 0.5) * l0;
        pavg[nb] = psum[b] / count[b];
        pex[nb] = s.rho * s.g * (s.surface - y[nb]);
        rel[nb] = (pavg[nb] - pex[nb]) / (s.rho * s.g * H);
        sum += rel[nb] * rel[nb];
        nb++;
    }
    if (rc == 0 && nb == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no interior fluid particle below the surface", case_dir);
    if (rc == 0) {
        *error = sqrt(sum / nb);
        snprintf(path, sizeof path, "%s/result.csv", ctx->out_dir);
        const double *cols[4] = {y, pavg, pex, rel};
        char comment[512];
        snprintf(comment, sizeof comment,
                 "hydrostatic pressure: time average over %d snapshots after t = %g s, bins of "
                 "l0 = %g m\nexact p = rho g (H - y), rho = %g, g = %g, surface at %g m\n"
                 "RMS relative error = %.6g; deepest bin: %.6g",
                 used, s.settle, l0, s.rho, s.g, s.surface, *error, rel[0]);
        rc = mf_report_csv(path, comment, "y,p_mpsflow,p_exact,relative_error", 4, cols, nb);
    }
    if (rc == 0) {
        snprintf(path, sizeof path, "%s/result.png", ctx->out_dir);
        char title[256];
        snprintf(title, sizeof title, "Hydrostatic pressure (RMS relative error %.3g)", *error);
        mf_plot plot = {title, "p, Pa", "y, m", false, false, NULL};
        mf_series series[2] = {{"mpsflow (time average)", pavg, y, nb, "points pt 7", NULL},
                               {"rho g (H - y)", pex, y, nb, "lines lw 2", NULL}};
        rc = mf_report_plot(path, &plot, series, 2);
    }
    free(psum);
    free(count);
    free(y);
    free(pavg);
    free(pex);
    free(rel);
    return rc;
}

const mf_metric_ops mf_metric_hydrostatic = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "hydrostaticPressure",
     "time-averaged pressure of a resting column",
     hydro_params, sizeof hydro_params / sizeof hydro_params[0], sizeof(hydro_settings)},
    evaluate,
    NULL,
};
