/* metric_containment.c: a case without a published reference that must keep
 * its fluid (tutorials/damBreakObstacle): no fluid particle lost, none
 * outside the tank, none inside the obstacles.
 *
 * Over every snapshot: count the fluid particles, those outside the tank's
 * region (tankMin, tankMax, grown by l0/2: the wall face plus the half
 * spacing a particle sits from it) and those inside the obstacle's box
 * (obstacleMin, obstacleMax, shrunk by l0/2; with wall particles, the box
 * they stand for, mf_box_lattice_max: the box the run's watch sees, smaller
 * than asked where the size is not a multiple of l0). error = the largest
 * over the snapshots of (|N - N_first| + outside + inside) / N_first: 0 for
 * a run that keeps its fluid where it belongs. The CSV lists (t, N, outside, inside). */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_hdf5.h"
#include "mf_post.h"
#include "mf_report.h"
#include "mf_walls.h"

typedef struct containment_settings {
    const char *metric;
    double tank_min[3], tank_max[3], obst_min[3], obst_max[3];
} containment_settings;

static const mf_param containment_params[] = {
    {"metric", MF_PARAM_WORD, NULL, MF_NO_RANGE, NULL, offsetof(containment_settings, metric),
     "containment"},
    {"tankMin", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL,
     offsetof(containment_settings, tank_min), "lower corner of the tank's region, m"},
    {"tankMax", MF_PARAM_VECTOR, NULL, MF_NO_RANGE, NULL,
     offsetof(containment_settings, tank_max),
     "upper corner of the tank's region, m (an open top: give it high)"},
    {"obstacleMin", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL,
     offsetof(containment_settings, obst_min), "lower corner of a box obstacle, m"},
    {"obstacleMax", MF_PARAM_VECTOR, "(0 0 0)", MF_NO_RANGE, NULL,
     offsetof(containment_settings, obst_max),
     "upper corner of a box obstacle, m (equal corners: none)"},
};
#define NCP (sizeof containment_params / sizeof containment_params[0])

static bool in_box(const double *x, const double *mn, const double *mx, double grow, int dim)
{
    for (int a = 0; a < dim; a++)
        if (x[a] < mn[a] - grow || x[a] > mx[a] + grow)
            return false;
    return true;
}

static int evaluate(const void *settings, const mf_metric_ctx *ctx, double *error)
{
    containment_settings s = *(const containment_settings *)settings;
    int *idx = NULL;
    size_t nsnap = 0;
    MF_CALL(mf_metric_snapshots(ctx, &idx, &nsnap));
    double *col[4];
    int rc = 0;
    for (int c = 0; c < 4; c++)
        if (!(col[c] = calloc(nsnap ? nsnap : 1, sizeof *col[c])))
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
    bool obstacle = false;
    for (int a = 0; a < 3; a++)
        obstacle |= s.obst_max[a] > s.obst_min[a];
    double n_first = 0, worst = 0;
    for (size_t k = 0; rc == 0 && k < nsnap; k++) {
        char path[4400];
        mf_snapshot_path(ctx->case_dir, idx[k], path, sizeof path);
        mf_sim snap;
        memset(&snap, 0, sizeof snap);
        rc = mf_hdf5_read_snapshot(path, &snap);
        if (rc != 0)
            break;
        const mf_particles *p = snap.p;
        const double h = 0.5 * snap.l0;
        size_t n = 0, outside = 0, inside = 0, solid = 0;
        for (size_t i = 0; i < p->n; i++)
            solid += p->kind[i] != MF_FLUID;
        double obst_max[3];
        memcpy(obst_max, s.obst_max, sizeof obst_max);
        if (solid > 0)
            mf_box_lattice_max(snap.l0, snap.dim, s.obst_min, obst_max);
        for (size_t i = 0; i < p->n; i++) {
            if (p->kind[i] != MF_FLUID)
                continue;
            const double *x = &p->pos[3 * i];
            n++;
            outside += !in_box(x, s.tank_min, s.tank_max, h, snap.dim);
            inside += obstacle && in_box(x, s.obst_min, obst_max, -h, snap.dim);
        }
        col[0][k] = snap.time;
        col[1][k] = (double)n;
        col[2][k] = (double)outside;
        col[3][k] = (double)inside;
        mf_particles_destroy(snap.p);
        if (k == 0)
            n_first = (double)n;
        if (n_first > 0)
            worst = fmax(worst, (fabs((double)n - n_first) + (double)(outside + inside)) / n_first);
    }
    free(idx);
    if (rc == 0 && !(n_first > 0))
        rc = MF_ERROR(MF_ERR_INPUT, "%s: no fluid particle in the first snapshot", ctx->case_dir);
    if (rc == 0) {
        *error = worst;
        char path[4400], comment[512];
        snprintf(path, sizeof path, "%s/result.csv", ctx->out_dir);
        snprintf(comment, sizeof comment,
                 "containment: fluid particles N, those outside the tank and inside the "
                 "obstacle, per snapshot\nerror = max over snapshots of (|N - N_0| + outside + "
                 "inside) / N_0 = %.6g (N_0 = %.0f)",
                 worst, n_first);
        const double *const cols[4] = {col[0], col[1], col[2], col[3]};
        rc = mf_report_csv(path, comment, "t,N,outside,inside", 4, cols, nsnap);
    }
    for (int c = 0; c < 4; c++)
        free(col[c]);
    return rc;
}

const mf_metric_ops mf_metric_containment = {
    {MF_ABI_VERSION, MF_KIND_METRIC, "containment",
     "fluid kept: particle count, none outside the tank or inside the obstacle (no reference)",
     containment_params, NCP, sizeof(containment_settings)},
    evaluate,
    NULL,
};
