/* metric_resting_tank.c: a tank of fluid at rest, the three checks of issue
 * 13 at once.
 *
 * Over the snapshots at or after settleTime:
 *   speed     the largest fluid particle speed, against sqrt(g H);
 *   pressure  the time-averaged pressure of the interior fluid particles of
 *             the deepest layer (height below bottom + l0), against rho g
 *             (H - y) at each particle: (sum p - sum rho g (H - y)) /
 *             (count rho g H);
 *   walls     fluid particle centres outside the box [min, max], the faces
 *             of the tank the fluid fills: a particle past a wall face.
 * error = the largest of speed / (speedTolerance sqrt(g H)) and |pressure| /
 * pressureTolerance, or 1 + the number of snapshots with a particle past a
 * face when there is one: at most 1 when the tank passes all three.
 * result.csv lists each snapshot. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_post.h"
#include "mf_report.h"

typedef struct tank_settings {
    const char *metric;
    double rho, g, surface, bottom, settle, speed_tol, pressure_tol;
    double lo[3], hi[3];
} tank_settings;

static const mf_param tank_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(tank_settings, metric),
     "restingTank"},
    {"rho", MF_PARAM_SCALAR, NULL, 1e-9, 1e9, NULL, offsetof(tank_settings, rho),
     "density, kg/m^3"},
    {"gravity", MF_PARAM_SCALAR, "9.81", 1e-9, 1e9, NULL, offsetof(tank_settings, g), "g, m/s^2"},
    {"surface", MF_PARAM_SCALAR, NULL, -1e9, 1e9, NULL, offsetof(tank_settings, surface),
     "height of the free surface at rest, m"},
    {"bottom", MF_PARAM_SCALAR, "0", -1e9, 1e9, NULL, offsetof(tank_settings, bottom),
     "height of the floor (its wall face), m"},
    {"settleTime", MF_PARAM_SCALAR, "0.5", 0, 1e9, NULL, offsetof(tank_settings, settle),
     "use the snapshots at or after this time, s"},
    {"speedTolerance", MF_PARAM_SCALAR, "0.01", 1e-9, 1e9, NULL,
     offsetof(tank_settings, speed_tol), "largest speed allowed, in sqrt(g H)"},
    {"pressureTolerance", MF_PARAM_SCALAR, "0.01", 1e-9, 1e9, NULL,
     offsetof(tank_settings, pressure_tol), "bottom pressure error allowed, in rho g H"},
    {"min", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(tank_settings, lo),
     "lower corner of the tank's wall faces, m"},
    {"max", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL, offsetof(tank_settings, hi),
     "upper corner of the tank's wall faces, m (an open top: above the fluid)"},
};
#define TANK_NPARAMS (sizeof tank_params / sizeof tank_params[0])

typedef struct tank_snapshot {
    double time, speed, pressure;
    long past;
} tank_snapshot;

/* One snapshot: its largest speed, its bottom-layer sums, its particles past
 * a face. */
static int read_one(const char *path, const tank_settings *s, tank_snapshot *out, double *psum,
                    double *pex_sum, double *count)
{
    mf_sim snap;
    memset(&snap, 0, sizeof snap);
    MF_CALL(mf_hdf5_read_snapshot(path, &snap));
    const mf_particles *p = snap.p;
    const int fp = mf_particles_field_index(p, "Pressure");
    const int ff = mf_particles_field_index(p, "Flags");
    const double H = s->surface - s->bottom, l0 = snap.l0;
    int rc = fp < 0 ? MF_ERROR(MF_ERR_INPUT, "%s: no Pressure field", path) : 0;
    out->speed = 0;
    out->past = 0;
    double ps = 0, pe = 0, c = 0;
    for (size_t i = 0; rc == 0 && i < p->n; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *x = &p->pos[3 * i], *v = &p->vel[3 * i];
        const double u = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (u > out->speed)
            out->speed = u;
        bool past = false;
        for (int a = 0; a < p->dim; a++)
            past = past || x[a] < s->lo[a] || x[a] > s->hi[a];
        out->past += past;
        const double y = x[1] - s->bottom;
        if (y >= 0 && y < l0 && !(ff >= 0 && mf_particles_fi(p, ff)[i] & 1)) {
            ps += mf_particles_fd(p, fp)[i];
            pe += s->rho * s->g * (H - y);
            c += 1;
        }
    }
    out->pressure = c > 0 ? (ps - pe) / (c * s->rho * s->g * H) : NAN;
    *psum += ps;
    *pex_sum += pe;
    *count += c;
    mf_particles_destroy(snap.p);
    return rc;
}

static int evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    tank_settings s = *(const tank_settings *)settings;
    const double H = s.surface - s.bottom;
    if (!(H > 0))
        return MF_ERROR(MF_ERR_INPUT, "%s/validation/metric: surface %g is not above bottom %g",
                        ctx->case_dir, s.surface, s.bottom);
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    tank_snapshot *rows = calloc(nsnap ? nsnap : 1, sizeof *rows);
    int rc = rows ? 0 : MF_ERROR(MF_ERR_MEMORY, "out of memory");
    size_t used = 0;
    double psum = 0, pex_sum = 0, count = 0, speed = 0;
    long past_snapshots = 0;
    char path[4400];
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        mf_snapshot_path(ctx->case_dir, idx[k], path, sizeof path);
        mf_hdf5_header h;
        rc = mf_hdf5_read_header(path, &h);
        if (rc != 0 || h.time < s.settle * (1 - 1e-9))
            continue;
        tank_snapshot *r = &rows[used];
        r->time = h.time;
        rc = read_one(path, &s, r, &psum, &pex_sum, &count);
        if (rc != 0)
            break;
        speed = fmax(speed, r->speed);
        past_snapshots += r->past > 0;
        used++;
    }
    free(idx);
    if (rc == 0 && used == 0)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no snapshot at or after settleTime %g", ctx->case_dir,
                      s.settle);
    if (rc == 0 && !(count > 0))
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no interior fluid particle in the deepest layer",
                      ctx->case_dir);
    const double scale = sqrt(s.g * H);
    const double pressure = rc == 0 ? (psum - pex_sum) / (count * s.rho * s.g * H) : NAN;
    if (rc == 0) {
        *error = fmax(speed / (s.speed_tol * scale), fabs(pressure) / s.pressure_tol);
        if (past_snapshots > 0)
            *error = fmax(*error, 1.0 + (double)past_snapshots);
    }
    double *cols[4] = {NULL, NULL, NULL, NULL};
    for (int c = 0; c < 4 && rc == 0; c++)
        if (!(cols[c] = malloc(used * sizeof *cols[c])))
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    for (size_t k = 0; rc == 0 && k < used; k++) {
        cols[0][k] = rows[k].time;
        cols[1][k] = rows[k].speed / scale;
        cols[2][k] = rows[k].pressure;
        cols[3][k] = (double)rows[k].past;
    }
    if (rc == 0) {
        snprintf(path, sizeof path, "%s/result.csv", ctx->out_dir);
        char comment[768];
        snprintf(comment, sizeof comment,
                 "resting tank: %zu snapshots from t = %g s; sqrt(g H) = %g m/s\n"
                 "largest speed %.4g sqrt(g H) (tolerance %g); bottom pressure error %.4g rho g "
                 "H (time average, tolerance %g); snapshots with a particle past a wall face: "
                 "%ld\nerror = %.6g (at most 1: passed)",
                 used, s.settle, scale, speed / scale, s.speed_tol, pressure, s.pressure_tol,
                 past_snapshots, *error);
        const double *cc[4] = {cols[0], cols[1], cols[2], cols[3]};
        rc = mf_report_csv(path, comment, "time,speed_over_sqrt_gH,bottom_pressure_error,past",
                           4, cc, used);
    }
    if (rc == 0) {
        snprintf(path, sizeof path, "%s/result.png", ctx->out_dir);
        char title[256];
        snprintf(title, sizeof title, "Resting tank: largest speed (max %.3g sqrt(gH))",
                 speed / scale);
        mf_plot plot = {title, "t, s", "speed / sqrt(g H)", false, true, NULL};
        mf_series series[1] = {{"largest fluid speed", cols[0], cols[1], used, "lines lw 2",
                                NULL}};
        rc = mf_report_plot(path, &plot, series, 1);
    }
    for (int c = 0; c < 4; c++)
        free(cols[c]);
    free(rows);
    return rc;
}

const mf_metric_ops mf_metric_resting_tank = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "restingTank",
     "a tank at rest: largest speed, bottom pressure, particles past the walls",
     tank_params, TANK_NPARAMS, sizeof(tank_settings)},
    evaluate,
    NULL,
};
