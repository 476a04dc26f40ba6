/* mf_mat3.h: the 3x3 (row-major) matrix and 3-vector products the rigid
 * motions need: solid states (walls_motion.c, walls.c) and the bodies the
 * fluid moves (rigid_bodies.c). */
#ifndef MF_MAT3_H
#define MF_MAT3_H

/* y = M x */
static inline void mf_mat3_vec(const double M[9], const double x[3], double y[3])
{
    for (int a = 0; a < 3; a++)
        y[a] = M[3 * a] * x[0] + M[3 * a + 1] * x[1] + M[3 * a + 2] * x[2];
}

/* y = M^T x */
static inline void mf_mat3_t_vec(const double M[9], const double x[3], double y[3])
{
    for (int a = 0; a < 3; a++)
        y[a] = M[a] * x[0] + M[3 + a] * x[1] + M[6 + a] * x[2];
}

/* C = A B */
static inline void mf_mat3_mul(const double A[9], const double B[9], double C[9])
{
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            C[3 * r + c] = A[3 * r] * B[c] + A[3 * r + 1] * B[3 + c] + A[3 * r + 2] * B[6 + c];
}

/* c = a x b */
static inline void mf_cross3(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

#endif
