/* ls_field.c: the field the surface is a level of.
 *
 * Level set (eqs. 30-32): F(x) = T + sum_i f(d'_i(x)),
 *     f(d) = 1 / (1 + (d / r)^k)                                    (eq. 31)
 * truncated smoothly at the cutoff Rc: f is multiplied by (1 - d^2/Rc^2)^2,
 * so F is C1 and a point only sums the particles within Rc. Without a
 * cutoff the sum of 1/d^2 over a 3-D body grows with its size (the
 * integral of 4 pi d^2 / d^2); the taper makes F a local quantity. With the
 * defaults (r = 0.73 l0, Rc = 2.5 l0, T = -2) the zero level of a flat face
 * of a cubic lattice lies 0.497 l0 beyond the last layer of particles
 * (ripple +-0.011 l0), i.e. on the face of the particles' volume.
 *
 * d' is the anisotropic distance of eq. 32: with u the unit velocity and
 * s = |u_i| / s_max, d'^2 = (d_par / (1 + s))^2 + ((1 + s) d_perp)^2, kept
 * as c2 |dx|^2 + c1 (dx . u)^2 with c2 = (1 + s)^2, c1 = (1 + s)^-2 - c2.
 *
 * Blobby: F(x) = sum_i (1 - d^2/R^2)^3 - isoValue (Wyvill's compact kernel).
 *
 * Evaluation gathers, per brick of the grid, the particles whose support
 * reaches it (binned once per frame: a particle -> brick list in CSR form),
 * then filters them per row of the brick. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "levelset.h"

/* Bricks are binned with this margin (cells) beyond a particle's support, so
 * that a brick with no candidate is at least this far from any support: the
 * grid edges leaving a brick can then only change sign inside binned bricks. */
#define BIN_MARGIN 1.5

void ls_field_init(ls_field *f)
{
    memset(f, 0, sizeof *f);
    ls_bricks_init(&f->touched);
}

void ls_field_free(ls_field *f)
{
    free(f->x);
    free(f->y);
    free(f->z);
    free(f->ux);
    free(f->uy);
    free(f->uz);
    free(f->c1);
    free(f->c2);
    free(f->ex);
    free(f->ey);
    free(f->ez);
    free(f->start);
    free(f->list);
    ls_bricks_free(&f->touched);
    ls_field_init(f);
}

static int alloc_particles(ls_field *f, size_t n)
{
    f->x = malloc(n * sizeof *f->x);
    f->y = malloc(n * sizeof *f->y);
    f->z = malloc(n * sizeof *f->z);
    f->ux = malloc(n * sizeof *f->ux);
    f->uy = malloc(n * sizeof *f->uy);
    f->uz = malloc(n * sizeof *f->uz);
    f->c1 = malloc(n * sizeof *f->c1);
    f->c2 = malloc(n * sizeof *f->c2);
    f->ex = malloc(n * sizeof *f->ex);
    f->ey = malloc(n * sizeof *f->ey);
    f->ez = malloc(n * sizeof *f->ez);
    if (!f->x || !f->y || !f->z || !f->ux || !f->uy || !f->uz || !f->c1 || !f->c2 || !f->ex ||
        !f->ey || !f->ez)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particles", n);
    return 0;
}

/* Range of bricks a particle's support (+ margin) reaches along one axis. */
static inline void brick_range(double c, double e, int32_t *lo, int32_t *hi)
{
    *lo = ls_brick_of((int32_t)floor(c - e - BIN_MARGIN));
    *hi = ls_brick_of((int32_t)ceil(c + e + BIN_MARGIN));
}

static int bin_particles(ls_field *f, size_t mem_limit, double h, const char *what)
{
    /* Count the particle-brick pairs first: a grid far too fine for the
     * memory is refused before anything large is allocated. */
    double pairs = 0;
    for (size_t i = 0; i < f->n; i++) {
        int32_t lo[3], hi[3];
        brick_range(f->x[i], f->ex[i], &lo[0], &hi[0]);
        brick_range(f->y[i], f->ey[i], &lo[1], &hi[1]);
        brick_range(f->z[i], f->ez[i], &lo[2], &hi[2]);
        pairs += (double)(hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1);
    }
    /* Each pair: a list entry; each brick (at most one per pair): hash slots,
     * coordinates, a start offset and, later, 512 field values while the
     * zero level is searched. */
    double bytes = pairs * 4.0 + fmin(pairs, pairs / 8 + 1e6) * 64.0;
    if (bytes > (double)mem_limit)
        return MF_ERROR(MF_ERR_MEMORY,
                        "%s: gridSpacing %g m is too fine for this frame: binning %zu particles "
                        "into bricks of 8^3 cells needs about %.3g GB (%.3g particle-brick "
                        "pairs), more than the memory limit of %.3g GB (maxMemory); use a "
                        "coarser gridSpacing",
                        what, h, f->n, bytes / 1073741824.0, pairs, mem_limit / 1073741824.0);
    size_t *count = NULL;
    size_t cap_count = 0;
    ls_bricks_clear(&f->touched);
    for (size_t i = 0; i < f->n; i++) {
        int32_t lo[3], hi[3];
        brick_range(f->x[i], f->ex[i], &lo[0], &hi[0]);
        brick_range(f->y[i], f->ey[i], &lo[1], &hi[1]);
        brick_range(f->z[i], f->ez[i], &lo[2], &hi[2]);
        for (int32_t bz = lo[2]; bz <= hi[2]; bz++)
            for (int32_t by = lo[1]; by <= hi[1]; by++)
                for (int32_t bx = lo[0]; bx <= hi[0]; bx++) {
                    int32_t k;
                    int rc = ls_bricks_insert(&f->touched, bx, by, bz, &k, NULL);
                    if (rc == 0 && (size_t)k >= cap_count) {
                        size_t cap = cap_count ? 2 * cap_count : 4096;
                        if (mf_resize(&count, cap, sizeof *count))
                            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory binning particles");
                        else {
                            memset(count + cap_count, 0, (cap - cap_count) * sizeof *count);
                            cap_count = cap;
                        }
                    }
                    if (rc != 0) {
                        free(count);
                        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
                    }
                    count[k]++;
                }
    }
    const size_t nb = f->touched.n;
    if (nb + 1 > f->cap_start) {
        free(f->start);
        f->start = malloc((nb + 1) * sizeof *f->start);
        f->cap_start = f->start ? nb + 1 : 0;
    }
    size_t total = 0;
    for (size_t k = 0; k < nb; k++)
        total += count[k];
    if (total > f->cap_list) {
        free(f->list);
        f->list = malloc(total * sizeof *f->list);
        f->cap_list = f->list ? total : 0;
    }
    if (!f->start || (!f->list && total > 0)) {
        free(count);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particle-brick pairs", total);
    }
    f->start[0] = 0;
    for (size_t k = 0; k < nb; k++) {
        f->start[k + 1] = f->start[k] + count[k];
        count[k] = f->start[k];
    }
    for (size_t i = 0; i < f->n; i++) {
        int32_t lo[3], hi[3];
        brick_range(f->x[i], f->ex[i], &lo[0], &hi[0]);
        brick_range(f->y[i], f->ey[i], &lo[1], &hi[1]);
        brick_range(f->z[i], f->ez[i], &lo[2], &hi[2]);
        for (int32_t bz = lo[2]; bz <= hi[2]; bz++)
            for (int32_t by = lo[1]; by <= hi[1]; by++)
                for (int32_t bx = lo[0]; bx <= hi[0]; bx++) {
                    int32_t k = ls_bricks_find(&f->touched, bx, by, bz);
                    f->list[count[k]++] = (uint32_t)i;
                }
    }
    free(count);
    return 0;
}

int ls_field_setup(ls_field *f, const mf_particles *p, int kernel, double h, double l0,
                   double radius_l0, double cutoff_l0, double kernel_power, double offset,
                   bool anisotropic, size_t mem_limit, const char *what)
{
    if (p->dim != 3)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: surface reconstruction needs 3-D particles; these are %d-D", what,
                        p->dim);
    if (!(h > 0) || !isfinite(h))
        return MF_ERROR(MF_ERR_INPUT, "%s: the grid spacing must be positive (got %g m)", what,
                        h);
    if (!(l0 > 0) || !isfinite(l0))
        return MF_ERROR(MF_ERR_INPUT, "%s: the particle spacing l0 must be positive (got %g m)",
                        what, l0);
    size_t nf = 0;
    double smax = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *x = &p->pos[3 * i], *v = &p->vel[3 * i];
        if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2]))
            return MF_ERROR(MF_ERR_INPUT,
                            "%s: fluid particle %lld (index %zu) has a non-finite position "
                            "(%g, %g, %g)",
                            what, (long long)p->id[i], i, x[0], x[1], x[2]);
        if (anisotropic && (!isfinite(v[0]) || !isfinite(v[1]) || !isfinite(v[2])))
            return MF_ERROR(MF_ERR_INPUT,
                            "%s: fluid particle %lld (index %zu) has a non-finite velocity "
                            "(%g, %g, %g); the anisotropic kernel (eq. 32) needs velocities",
                            what, (long long)p->id[i], i, v[0], v[1], v[2]);
        double s = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (s > smax)
            smax = s;
        nf++;
    }
    if (nf == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: no fluid particles: nothing to reconstruct", what);
    /* The grid's coordinate range: bricks within +-2^20, i.e. 8.4 million cells. */
    const double range = 8.0 * (LS_BRICK_LIMIT - 4);
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->kind[i] == MF_FLUID)
            for (int a = 0; a < 3; a++)
                if (fabs(p->pos[3 * i + a] / h) + cutoff_l0 * l0 / h * 2 > range)
                    return MF_ERROR(MF_ERR_INPUT,
                                    "%s: gridSpacing %g m is too fine for particles reaching "
                                    "%g m from the origin (the grid holds %.3g cells per axis); "
                                    "use a coarser gridSpacing",
                                    what, h, fabs(p->pos[3 * i + a]), 2 * range);
    ls_field_free(f);
    f->kernel = kernel;
    f->h = h;
    const double r = radius_l0 * l0 / h, rc = cutoff_l0 * l0 / h;
    f->r2_inv = r > 0 ? 1.0 / (r * r) : 0;
    f->rc2 = rc * rc;
    f->rc2_inv = 1.0 / (rc * rc);
    f->k_half = 0.5 * kernel_power;
    f->offset = offset;
    f->anisotropic = anisotropic && smax > 0;
    MF_CALL(alloc_particles(f, nf));
    size_t k = 0;
    f->ext_max = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (p->kind[i] != MF_FLUID)
            continue;
        const double *x = &p->pos[3 * i], *v = &p->vel[3 * i];
        f->x[k] = x[0] / h;
        f->y[k] = x[1] / h;
        f->z[k] = x[2] / h;
        double u[3] = {0, 0, 0}, s = 0;
        double speed = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (f->anisotropic && speed > 0) {
            s = speed / smax; /* eq. 32 */
            for (int a = 0; a < 3; a++)
                u[a] = v[a] / speed;
        }
        const double stretch = 1.0 + s;
        const double c2 = stretch * stretch, c1 = 1.0 / (stretch * stretch) - c2;
        f->ux[k] = (float)u[0];
        f->uy[k] = (float)u[1];
        f->uz[k] = (float)u[2];
        f->c1[k] = (float)c1;
        f->c2[k] = (float)c2;
        /* The support d' < Rc is an ellipsoid with semi-axis Rc (1 + s) along
         * u and Rc / (1 + s) across; its half-extent along axis a is
         * sqrt(A^2 u_a^2 + B^2 (1 - u_a^2)). */
        const double A = rc * stretch, B = rc / stretch;
        float *e[3] = {&f->ex[k], &f->ey[k], &f->ez[k]};
        for (int a = 0; a < 3; a++) {
            double ea = sqrt(A * A * u[a] * u[a] + B * B * (1 - u[a] * u[a]));
            if (s == 0)
                ea = rc;
            /* float rounding must not cut the support */
            *e[a] = (float)(ea * (1 + 1e-6) + 1e-6);
            if (*e[a] > f->ext_max)
                f->ext_max = *e[a];
        }
        k++;
    }
    f->n = nf;
    MF_CALL(bin_particles(f, mem_limit, h, what));
    return 0;
}

/* ---- evaluation ---------------------------------------------------------- */

static inline double kernel_value(const ls_field *f, double d2)
{
    double w = 1.0 - d2 * f->rc2_inv;
    if (f->kernel == LS_KERNEL_BLOBBY)
        return w * w * w;
    double q2 = d2 * f->r2_inv;
    double den = f->k_half == 1.0 ? 1.0 + q2 : 1.0 + pow(q2, f->k_half);
    return w * w / den;
}

static inline double pair_d2(const ls_field *f, size_t i, double dx, double dy, double dz)
{
    double r2 = dx * dx + dy * dy + dz * dz;
    if (!f->anisotropic)
        return r2;
    double along = dx * f->ux[i] + dy * f->uy[i] + dz * f->uz[i];
    return f->c2[i] * r2 + f->c1[i] * along * along;
}

/* Not a particle-pair loop and not core's neighbour service: the level set's
 * nodes (integer grid coordinates) against the particles binned into its
 * bricks, each with its own (anisotropic) support; the service's lists are
 * of particles around particles. */
double ls_field_at(const ls_field *f, int32_t cand, int32_t x, int32_t y, int32_t z)
{
    double sum = 0;
    if (cand >= 0) {
        for (size_t q = f->start[cand]; q < f->start[cand + 1]; q++) {
            size_t i = f->list[q];
            double dx = x - f->x[i], dy = y - f->y[i], dz = z - f->z[i];
            if (fabs(dx) >= f->ex[i] || fabs(dy) >= f->ey[i] || fabs(dz) >= f->ez[i])
                continue;
            double d2 = pair_d2(f, i, dx, dy, dz);
            if (d2 < f->rc2)
                sum += kernel_value(f, d2);
        }
    }
    return f->offset + sum;
}

/* Values at (x0 + s i, y0 + s j, z0 + s k), i, j, k in [0, n), x fastest.
 * Each candidate is first sorted into the rows (j, k) its support meets
 * (a counting sort), so a row only visits the particles that reach it and,
 * of those, only the points within their x extent. */
#define MAX_N 9
#define ROW_MAX 1024

/* Four lanes of single precision (GCC/Clang vector extensions: SSE on
 * x86-64 without intrinsics). */
typedef float v4f __attribute__((vector_size(16)));
typedef int32_t v4i __attribute__((vector_size(16)));

/* sum over q < m (a multiple of 4) of the kernel at the point px of a row,
 * for particles at x offsets cx and squared distances across the row cb:
 * (1 - d^2/Rc^2)^2 / (1 + d^2/r^2) (eq. 31, k = 2, tapered) or the blobby
 * (1 - d^2/R^2)^3; zero beyond the support. */
static float row_sum(const float *cx, const float *cb, int m, float px, float rc2_inv,
                     float r2_inv, bool blobby)
{
    const v4f zero = {0, 0, 0, 0}, one = {1, 1, 1, 1};
    v4f acc = zero;
    for (int q = 0; q < m; q += 4) {
        v4f x, b;
        memcpy(&x, cx + q, sizeof x);
        memcpy(&b, cb + q, sizeof b);
        const v4f dx = px - x, d2 = b + dx * dx;
        v4f w = one - d2 * rc2_inv;
        w = (v4f)((v4i)w & (v4i)(w > zero)); /* max(w, 0) */
        acc += blobby ? w * w * w : w * w / (one + d2 * r2_inv);
    }
    return (acc[0] + acc[1]) + (acc[2] + acc[3]);
}
static void eval_block(const ls_field *f, int32_t cand, int32_t x0, int32_t y0, int32_t z0,
                       int n, int s, float *out)
{
    const size_t nn = (size_t)n * n * n;
    if (cand < 0) {
        for (size_t q = 0; q < nn; q++)
            out[q] = (float)f->offset;
        return;
    }
    const size_t c0 = f->start[cand], nc = f->start[cand + 1] - c0;
    const double inv_s = 1.0 / s;
    size_t count[MAX_N * MAX_N + 1] = {0};
    /* pass 1: the row ranges of each candidate, and the row counts */
    int16_t range_stack[4 * 512];
    int16_t *range = nc <= 512 ? range_stack : malloc(4 * nc * sizeof *range);
    uint32_t list_stack[8192];
    uint32_t *list = NULL;
    size_t total = 0;
    if (range) {
        for (size_t q = 0; q < nc; q++) {
            const uint32_t i = f->list[c0 + q];
            double jl = ceil((f->y[i] - f->ey[i] - y0) * inv_s),
                   jh = floor((f->y[i] + f->ey[i] - y0) * inv_s),
                   kl = ceil((f->z[i] - f->ez[i] - z0) * inv_s),
                   kh = floor((f->z[i] + f->ez[i] - z0) * inv_s);
            int16_t *r = &range[4 * q];
            r[0] = (int16_t)(jl < 0 ? 0 : jl);
            r[1] = (int16_t)(jh > n - 1 ? n - 1 : jh);
            r[2] = (int16_t)(kl < 0 ? 0 : kl);
            r[3] = (int16_t)(kh > n - 1 ? n - 1 : kh);
            for (int k = r[2]; k <= r[3]; k++)
                for (int j = r[0]; j <= r[1]; j++) {
                    count[j + n * k + 1]++;
                    total++;
                }
        }
        list = total <= 8192 ? list_stack : malloc(total * sizeof *list);
    }
    if (!list) {
        /* no memory for the row lists: slow but correct */
        if (range != range_stack)
            free(range);
        for (int k = 0; k < n; k++)
            for (int j = 0; j < n; j++)
                for (int i = 0; i < n; i++)
                    out[i + n * (j + n * k)] =
                        (float)ls_field_at(f, cand, x0 + s * i, y0 + s * j, z0 + s * k);
        return;
    }
    for (int r = 0; r < n * n; r++)
        count[r + 1] += count[r];
    size_t fill[MAX_N * MAX_N];
    memcpy(fill, count, (size_t)n * n * sizeof *fill);
    for (size_t q = 0; q < nc; q++) {
        const int16_t *r = &range[4 * q];
        for (int k = r[2]; k <= r[3]; k++)
            for (int j = r[0]; j <= r[1]; j++)
                list[fill[j + n * k]++] = f->list[c0 + q];
    }
    /* pass 2: each row */
    double acc[MAX_N];
    for (int k = 0; k < n; k++)
        for (int j = 0; j < n; j++) {
            const double py = y0 + s * j, pz = z0 + s * k;
            for (int i = 0; i < n; i++)
                acc[i] = 0;
            const size_t r = (size_t)(j + n * k);
            const bool simd_kernel = f->kernel == LS_KERNEL_BLOBBY || f->k_half == 1.0;
            if (!f->anisotropic && simd_kernel && count[r + 1] - count[r] <= ROW_MAX) {
                /* isotropic, k = 2 or blobby: the row's particles that reach
                 * it, gathered as (x offset, dy^2 + dz^2) in single
                 * precision, then every point of the row against all of them
                 * in SIMD (beyond the support w = 0: it adds 0). The sum of
                 * about 60 terms of at most 1 in single precision moves the
                 * zero level by about 1e-6 cells. */
                float cx[ROW_MAX + 4], cb[ROW_MAX + 4];
                int m = 0;
                for (size_t q = count[r]; q < count[r + 1]; q++) {
                    const uint32_t i = list[q];
                    const double dy = py - f->y[i], dz = pz - f->z[i];
                    const double base = dy * dy + dz * dz;
                    if (base >= f->rc2)
                        continue;
                    cx[m] = (float)(f->x[i] - x0);
                    cb[m] = (float)base;
                    m++;
                }
                /* pad to whole vectors with particles beyond the support */
                while (m % 4) {
                    cx[m] = 0;
                    cb[m] = (float)(2 * f->rc2);
                    m++;
                }
                const bool blobby = f->kernel == LS_KERNEL_BLOBBY;
                for (int ii = 0; ii < n; ii++)
                    acc[ii] = row_sum(cx, cb, m, (float)(s * ii), (float)f->rc2_inv,
                                      (float)f->r2_inv, blobby);
            } else {
                for (size_t q = count[r]; q < count[r + 1]; q++) {
                    const uint32_t i = list[q];
                    const double dy = py - f->y[i], dz = pz - f->z[i];
                    double lo = (f->x[i] - f->ex[i] - x0) * inv_s,
                           hi = (f->x[i] + f->ex[i] - x0) * inv_s;
                    int a = lo < 0 ? 0 : (int)ceil(lo), b = hi >= n ? n - 1 : (int)floor(hi);
                    for (int ii = a; ii <= b; ii++) {
                        const double dx = x0 + s * ii - f->x[i];
                        double d2 = pair_d2(f, i, dx, dy, dz);
                        if (d2 < f->rc2)
                            acc[ii] += kernel_value(f, d2);
                    }
                }
            }
            float *o = out + (size_t)n * (j + (size_t)n * k);
            for (int i = 0; i < n; i++)
                o[i] = (float)(f->offset + acc[i]);
        }
    if (range != range_stack)
        free(range);
    if (list != list_stack)
        free(list);
}

void ls_field_brick(const ls_field *f, int32_t bx, int32_t by, int32_t bz, int n, float *out)
{
    int32_t cand = ls_bricks_find(&f->touched, bx, by, bz);
    eval_block(f, cand, LS_B * bx, LS_B * by, LS_B * bz, n, 1, out);
}

void ls_field_brick_coarse(const ls_field *f, int32_t bx, int32_t by, int32_t bz, int s,
                           float *out)
{
    int32_t cand = ls_bricks_find(&f->touched, bx, by, bz);
    eval_block(f, cand, LS_B * bx, LS_B * by, LS_B * bz, LS_B / s + 1, s, out);
}
