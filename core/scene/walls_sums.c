/* walls_sums.c: the wall weight sums of the solids (mf_walls.h) at a point:
 * each shape's expansion into terms of mf_wall_weight.h.
 *
 * A tank's solid is the union of the half-spaces behind its closed faces
 * (whole planes: the wall does not end where the box does); by inclusion and
 * exclusion its sums are those of each face, less those of each edge (two
 * orthogonal faces: the quadrant behind both was counted twice), plus those
 * of each corner. A box obstacle's solid is the intersection of three slabs;
 * along each axis the slab is the half-line behind its near face less the
 * half-line behind its far face, and the product expands into terms. Curved
 * shapes take the tangent plane at their nearest point (the flat-wall
 * approximation of Harada et al. 2008 and of Mitsume et al. 2015's polygon
 * walls: exact as the radius of curvature grows against re); polygon
 * surfaces their faces' planes where the faces meet at about right angles,
 * else the same tangent plane (walls_mesh.c). */
#include <math.h>
#include <string.h>

#include "mf_wall_lattice.h"
#include "mf_walls.h"
#include "walls_internal.h"

#define MAX_TERMS 32

/* One axis factor of a box: up to two entries, each free or a half-line. */
typedef struct factor_entry {
    double coef;
    bool is_free;
    double delta;
    double e[3];
} factor_entry;

/* Tank: inclusion-exclusion over the closed faces within reach. */
static int tank_terms(const mf_wall *w, const mf_wall_tables *t, int dim, const double xb[3],
                      mf_wall_term *terms)
{
    const double reach = mf_wall_tables_reach(t), freed = mf_wall_tables_free_beyond(t);
    int nf = 0, axis[6];
    double delta[6], e[6][3];
    for (int a = 0; a < dim; a++)
        for (int s = 0; s < 2; s++) {
            if (w->open[a][s])
                continue;
            const double d = s == 0 ? xb[a] - w->min[a] : w->max[a] - xb[a];
            if (d >= reach)
                continue;
            if (d <= -freed) { /* deep behind a face: the solid fills the reach */
                terms[0] = (mf_wall_term){.c = 0, .sign = 1};
                return 1;
            }
            axis[nf] = a;
            delta[nf] = d;
            memset(e[nf], 0, sizeof e[nf]);
            e[nf][a] = s == 0 ? -1 : 1;
            nf++;
        }
    int nt = 0;
    for (int mask = 1; mask < (1 << nf); mask++) {
        int used = 0, c = 0;
        bool ok = true;
        mf_wall_term tm = {.c = 0};
        for (int f = 0; f < nf && ok; f++) {
            if (!(mask >> f & 1))
                continue;
            if (used >> axis[f] & 1) { /* opposite faces: their half-spaces are apart */
                ok = false;
                break;
            }
            used |= 1 << axis[f];
            memcpy(tm.e[c], e[f], sizeof tm.e[c]);
            tm.delta[c] = delta[f];
            c++;
        }
        if (!ok)
            continue;
        tm.c = c;
        tm.sign = c % 2 ? 1 : -1;
        terms[nt++] = tm;
    }
    return nt;
}

/* Box obstacle: the product over axes of (near half-line - far half-line). */
static int box_terms(const mf_wall *w, const mf_wall_tables *t, int dim, const double xb[3],
                     mf_wall_term *terms)
{
    const double reach = mf_wall_tables_reach(t), freed = mf_wall_tables_free_beyond(t);
    factor_entry fe[3][2];
    int nfe[3] = {0, 0, 0};
    for (int a = 0; a < dim; a++) {
        const double c = 0.5 * (w->min[a] + w->max[a]);
        const bool plus = xb[a] <= c; /* the solid lies toward +a from the near face */
        const double dn = plus ? w->min[a] - xb[a] : xb[a] - w->max[a];
        const double df = plus ? w->max[a] - xb[a] : xb[a] - w->min[a];
        double e[3] = {0, 0, 0};
        e[a] = plus ? 1 : -1;
        if (dn >= reach)
            return 0; /* the solid is out of reach along this axis */
        const double ds[2] = {dn, df}, cs[2] = {1, -1};
        for (int k = 0; k < 2; k++) {
            if (ds[k] >= reach)
                continue;
            factor_entry *f = &fe[a][nfe[a]++];
            f->coef = cs[k];
            f->is_free = ds[k] <= -freed;
            f->delta = ds[k];
            memcpy(f->e, e, sizeof e);
        }
    }
    int nt = 0;
    int pick[3] = {0, 0, 0};
    for (;;) {
        mf_wall_term tm = {.c = 0, .sign = 1};
        for (int a = 0; a < dim; a++) {
            const factor_entry *f = &fe[a][pick[a]];
            tm.sign *= f->coef;
            if (!f->is_free) {
                memcpy(tm.e[tm.c], f->e, sizeof tm.e[tm.c]);
                tm.delta[tm.c] = f->delta;
                tm.c++;
            }
        }
        terms[nt++] = tm;
        int a = 0;
        while (a < dim && ++pick[a] == nfe[a])
            pick[a++] = 0;
        if (a == dim)
            break;
    }
    return nt;
}

/* A curved shape: its tangent plane at the nearest point. */
static int tangent_term(double d, const double n[3], int dim, const mf_wall_tables *t,
                        mf_wall_term *terms)
{
    if (d >= mf_wall_tables_reach(t))
        return 0;
    if (d <= -mf_wall_tables_free_beyond(t)) {
        terms[0] = (mf_wall_term){.c = 0, .sign = 1};
        return 1;
    }
    mf_wall_term tm = {.c = 1, .sign = 1, .delta = {d, 0, 0}};
    double len = 0;
    for (int a = 0; a < dim; a++) {
        tm.e[0][a] = -n[a];
        len += n[a] * n[a];
    }
    if (!(len > 0))
        return 0;
    len = sqrt(len);
    for (int a = 0; a < dim; a++)
        tm.e[0][a] /= len;
    terms[0] = tm;
    return 1;
}

static void add_rotated(const double R[9], const mf_wall_sums *b, mf_wall_sums *s)
{
    double g[3], m[3];
    for (int a = 0; a < 3; a++) {
        g[a] = R[3 * a] * b->g[0] + R[3 * a + 1] * b->g[1] + R[3 * a + 2] * b->g[2];
        m[a] = R[3 * a] * b->m[0] + R[3 * a + 1] * b->m[1] + R[3 * a + 2] * b->m[2];
    }
    const double T[3][3] = {{b->t[0], b->t[3], b->t[4]},
                            {b->t[3], b->t[1], b->t[5]},
                            {b->t[4], b->t[5], b->t[2]}};
    double RT[3][3]; /* R T R^T */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double v = 0;
            for (int k = 0; k < 3; k++)
                for (int l = 0; l < 3; l++)
                    v += R[3 * i + k] * T[k][l] * R[3 * j + l];
            RT[i][j] = v;
        }
    s->zn += b->zn;
    s->visc += b->visc;
    for (int a = 0; a < 3; a++) {
        s->g[a] += g[a];
        s->m[a] += m[a];
    }
    s->t[0] += RT[0][0];
    s->t[1] += RT[1][1];
    s->t[2] += RT[2][2];
    s->t[3] += RT[0][1];
    s->t[4] += RT[0][2];
    s->t[5] += RT[1][2];
}

bool mf_wall_sums_of(const mf_wall *w, const mf_wall_tables *t, int dim, double l0,
                     const double x[3], mf_wall_sums *s)
{
    (void)l0;
    memset(s, 0, sizeof *s);
    double xb[3], nb[3];
    mf_wall_to_body(w, x, xb);
    if (dim == 2)
        xb[2] = 0;
    mf_wall_term terms[MAX_TERMS];
    int nt = 0;
    switch (w->shape) {
    case MF_SOLID_TANK:
        nt = tank_terms(w, t, dim, xb, terms);
        break;
    case MF_SOLID_BOX:
        nt = box_terms(w, t, dim, xb, terms);
        break;
    case MF_SOLID_CYLINDER:
    case MF_SOLID_SPHERE: {
        const double d = mf_wall_body_distance(w, xb, nb);
        nt = tangent_term(d, nb, dim, t, terms);
        break;
    }
    case MF_SOLID_MESH:
        if (w->mesh)
            nt = mf_wall_mesh_terms(w->mesh, t, xb, terms, MAX_TERMS);
        break;
    default:
        break;
    }
    if (nt == 0)
        return false;
    mf_wall_sums b;
    memset(&b, 0, sizeof b);
    bool any = false;
    for (int k = 0; k < nt; k++)
        any = mf_wall_term_add(t, &terms[k], &b) || any;
    if (!any)
        return false;
    add_rotated(w->state.R, &b, s);
    return true;
}

bool mf_walls_sums(const mf_walls *ws, const mf_wall_tables *t, const double x[3],
                   mf_wall_point *out)
{
    memset(out, 0, sizeof *out);
    out->dist = INFINITY;
    out->wall = -1;
    bool any = false;
    for (size_t k = 0; ws && k < ws->n; k++) {
        const mf_wall *w = &ws->w[k];
        double n[3];
        const double d = mf_wall_distance(w, x, n);
        if (d < out->dist) {
            out->dist = d;
            memcpy(out->normal, n, sizeof n);
            out->wall = (int)k;
        }
        if (!(d < mf_wall_tables_reach(t)))
            continue; /* every term out of reach (the l1 norm of the offsets bounds the l2) */
        mf_wall_sums s;
        if (!mf_wall_sums_of(w, t, ws->dim, ws->l0, x, &s))
            continue;
        any = true;
        double u[3], us[3], acc[3];
        mf_wall_velocity(w, x, false, u);
        mf_wall_velocity(w, x, true, us);
        /* the surface velocity along the surface only */
        double sn = 0;
        for (int a = 0; a < 3; a++)
            sn += (us[a] - u[a]) * n[a];
        for (int a = 0; a < 3; a++)
            u[a] = us[a] - sn * n[a];
        mf_wall_acceleration(w, x, acc);
        out->s.zn += s.zn;
        out->s.visc += s.visc;
        for (int a = 0; a < 3; a++) {
            out->s.g[a] += s.g[a];
            out->s.m[a] += s.m[a];
            out->visc_u[a] += s.visc * u[a];
        }
        for (int q = 0; q < 6; q++)
            out->s.t[q] += s.t[q];
        out->m_a += s.m[0] * acc[0] + s.m[1] * acc[1] + s.m[2] * acc[2];
        const double T[3][3] = {{s.t[0], s.t[3], s.t[4]},
                                {s.t[3], s.t[1], s.t[5]},
                                {s.t[4], s.t[5], s.t[2]}};
        for (int a = 0; a < 3; a++)
            out->t_a[a] += T[a][0] * acc[0] + T[a][1] * acc[1] + T[a][2] * acc[2];
    }
    if (ws && ws->dim == 2) {
        out->s.g[2] = out->s.m[2] = out->visc_u[2] = out->t_a[2] = 0;
        out->s.t[2] = out->s.t[4] = out->s.t[5] = 0;
    }
    return any;
}

/* mf_wall_points_each: a term's lattice point from its local frame (the
 * constrained axes e[k], then the body axes the term leaves free) to the
 * world frame. */
typedef struct points_ctx {
    const mf_wall_term *tm;
    const double *R; /* body to world */
    int dim, free_axis[3];
    double R2; /* points at R or farther are left out */
    mf_wall_point_fn fn;
    void *ctx;
} points_ctx;

static void term_point(void *ctx, const double v[3])
{
    const points_ctx *pc = ctx;
    const mf_wall_term *tm = pc->tm;
    if (!(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] < pc->R2))
        return;
    double b[3] = {0, 0, 0};
    double depth = INFINITY, dist = 0;
    for (int k = 0; k < tm->c; k++) {
        for (int a = 0; a < 3; a++)
            b[a] += v[k] * tm->e[k][a];
        const double s = v[k] - tm->delta[k];
        if (s < depth) {
            depth = s;
            dist = tm->delta[k];
        }
    }
    for (int f = tm->c; f < pc->dim; f++)
        b[pc->free_axis[f - tm->c]] += v[f];
    if (tm->c == 0)
        depth = dist = 0;
    double r[3];
    for (int a = 0; a < 3; a++)
        r[a] = pc->R[3 * a] * b[0] + pc->R[3 * a + 1] * b[1] + pc->R[3 * a + 2] * b[2];
    if (pc->dim == 2)
        r[2] = 0;
    pc->fn(pc->ctx, r, depth, dist, tm->sign);
}

bool mf_wall_points_each(const mf_wall *w, const mf_wall_tables *t, int dim, double l0,
                         double R, const double x[3], mf_wall_point_fn fn, void *ctx)
{
    if (w->shape != MF_SOLID_TANK && w->shape != MF_SOLID_BOX)
        return false;
    double xb[3];
    mf_wall_to_body(w, x, xb);
    if (dim == 2)
        xb[2] = 0;
    mf_wall_term terms[MAX_TERMS];
    const int nt = w->shape == MF_SOLID_TANK ? tank_terms(w, t, dim, xb, terms)
                                             : box_terms(w, t, dim, xb, terms);
    for (int k = 0; k < nt; k++) {
        const mf_wall_term *tm = &terms[k];
        points_ctx pc = {.tm = tm, .R = w->state.R, .dim = dim, .R2 = R * R, .fn = fn,
                         .ctx = ctx};
        int nfree = 0;
        for (int a = 0; a < dim; a++) { /* the body axes no constrained axis takes */
            bool used = false;
            for (int c = 0; c < tm->c; c++)
                used = used || fabs(tm->e[c][a]) > 0.5;
            if (!used)
                pc.free_axis[nfree++] = a;
        }
        mf_wall_lattice_each(dim, l0, R, tm->c, tm->delta, term_point, &pc);
    }
    return true;
}
