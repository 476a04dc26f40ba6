/* trimesh_mass.c: the volume, centroid and inertia of the solid a closed
 * triangle mesh bounds (mf_trimesh.h: mf_trimesh_mass), by the divergence
 * theorem: the volume integrals of 1, x, y, z, x^2, y^2, z^2, xy, yz, zx
 * become sums over the triangles of polynomials in their vertices. The
 * sums are Eberly's, "Polyhedral mass properties (revisited)", Geometric
 * Tools (2002), function Compute (the subexpressions f1, f2, f3, g0, g1, g2
 * of each coordinate), which simplifies Mirtich (1996), "Fast and accurate
 * computation of polyhedral mass properties", J. Graphics Tools 1(2),
 * 31-50, for triangles. */
#include <string.h>

#include "mf_trimesh.h"

/* Eberly's subexpressions of one coordinate's three vertex values. */
static void subexpressions(double w0, double w1, double w2, double *f1, double *f2, double *f3,
                           double g[3])
{
    const double temp0 = w0 + w1, temp1 = w0 * w0, temp2 = temp1 + w1 * temp0;
    *f1 = temp0 + w2;
    *f2 = temp2 + w2 * *f1;
    *f3 = w0 * temp1 + w1 * temp2 + w2 * *f2;
    g[0] = *f2 + w0 * (*f1 + w0);
    g[1] = *f2 + w1 * (*f1 + w1);
    g[2] = *f2 + w2 * (*f1 + w2);
}

void mf_trimesh_mass(const mf_trimesh *m, double *volume, double centre[3], double I[9])
{
    /* about the bounding box's centre: the parallel-axis step below
     * subtracts V c^2 from the second moments, which loses the digits of a
     * small body far from the origin */
    double lo[3], hi[3], o[3];
    mf_trimesh_bounds(m, lo, hi);
    for (int a = 0; a < 3; a++)
        o[a] = 0.5 * (lo[a] + hi[a]);
    double s[10] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    for (size_t t = 0; t < m->ntris; t++) {
        double p[3][3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                p[k][a] = m->xyz[3 * (size_t)m->tri[3 * t + k] + a] - o[a];
        const double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
        const double e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
        const double d[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        double f1[3], f2[3], f3[3], g[3][3];
        for (int a = 0; a < 3; a++)
            subexpressions(p[0][a], p[1][a], p[2][a], &f1[a], &f2[a], &f3[a], g[a]);
        s[0] += d[0] * f1[0];
        s[1] += d[0] * f2[0];
        s[2] += d[1] * f2[1];
        s[3] += d[2] * f2[2];
        s[4] += d[0] * f3[0];
        s[5] += d[1] * f3[1];
        s[6] += d[2] * f3[2];
        s[7] += d[0] * (p[0][1] * g[0][0] + p[1][1] * g[0][1] + p[2][1] * g[0][2]);
        s[8] += d[1] * (p[0][2] * g[1][0] + p[1][2] * g[1][1] + p[2][2] * g[1][2]);
        s[9] += d[2] * (p[0][0] * g[2][0] + p[1][0] * g[2][1] + p[2][0] * g[2][2]);
    }
    static const double mult[10] = {1.0 / 6,   1.0 / 24,  1.0 / 24,  1.0 / 24,  1.0 / 60,
                                    1.0 / 60,  1.0 / 60,  1.0 / 120, 1.0 / 120, 1.0 / 120};
    for (int k = 0; k < 10; k++)
        s[k] *= mult[k];
    const double V = s[0];
    *volume = V;
    memset(I, 0, 9 * sizeof *I);
    if (!(V != 0)) {
        memcpy(centre, o, 3 * sizeof *centre);
        return;
    }
    const double c[3] = {s[1] / V, s[2] / V, s[3] / V};
    /* second moments about the centroid, per unit volume (= per unit mass) */
    const double xx = s[4] / V - c[0] * c[0], yy = s[5] / V - c[1] * c[1],
                 zz = s[6] / V - c[2] * c[2];
    const double xy = s[7] / V - c[0] * c[1], yz = s[8] / V - c[1] * c[2],
                 zx = s[9] / V - c[2] * c[0];
    I[0] = yy + zz;
    I[4] = zz + xx;
    I[8] = xx + yy;
    I[1] = I[3] = -xy;
    I[5] = I[7] = -yz;
    I[2] = I[6] = -zx;
    for (int a = 0; a < 3; a++)
        centre[a] = c[a] + o[a];
}
