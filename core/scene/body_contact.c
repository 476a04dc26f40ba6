/* body_contact.c: contact between a rigid body and the other solids (walls,
 * obstacles, other bodies; mf_bodies.h), a collision of rigid bodies
 * without friction (Baraff 1997, "An introduction to physically based
 * modeling: rigid body simulation II - nonpenetration constraints", SIGGRAPH
 * course notes, section 8, eqs. 8-12 and 8-18), the way the MPS collision
 * model treats two particles (Koshizuka & Oka 1996), for whole bodies:
 *
 * At the trial state (mf_bodies_set_trial), each outer particle of body A
 * is placed where the trial state has it (x' = x_t + R_t R^T (x - x), p's
 * positions being the committed state's) and its distance d to solid B's
 * shape (mf_wall_distance, positive on the fluid side, normal n pointing
 * away from B) is taken; the body's surface lies l0/2 beyond its outer
 * particles, so the overlap is delta = l0/2 - d. At each overlapping
 * particle where A approaches B (v_n = (v_A(x') - v_B(x')).n < 0), the
 * impulse
 *
 *   j = -(1 + e) v_n / (1/m_A + n.(I_A^-1 (r_A x n)) x r_A  [+ the same of B])
 *
 * along n is added to A (and -j to B when B is a body), in sweeps over the
 * points (sequential impulses, each point's total kept >= 0), and the overlap
 * that is left at the new trial state is removed from A's trial position
 * (shared with B by inverse mass). The impulse is an external one for a
 * wall, an exchange between two bodies (their momentum is kept). Friction
 * and the fluid squeezed out of a gap are not modelled. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_parallel.h"

#include "bodies_internal.h"
#include "mf_mat3.h"

/* The outer (wall) particles of the bodies where the committed state has
 * them, gathered from every rank (each owns some), so that every rank sweeps
 * the same points in the same order and reaches the same trial states; on
 * one rank in the particles' order, on several sorted by (body, id). */
typedef struct body_point {
    int64_t id;
    int64_t body; /* the body's place in ws */
    double x[3];
} body_point;

typedef struct body_points {
    body_point *pt;
    size_t n;
} body_points;

static int cmp_point(const void *a, const void *b)
{
    const body_point *u = a, *v = b;
    if (u->body != v->body)
        return u->body < v->body ? -1 : 1;
    return (u->id > v->id) - (u->id < v->id);
}

/* Particle i is an outer particle of a body (id: the WallId field). */
static bool is_body_point(const mf_walls *ws, const mf_particles *p, const int32_t *id, size_t i)
{
    return id[i] > 0 && (size_t)id[i] <= ws->n && ws->w[id[i] - 1].body &&
           p->kind[i] == MF_WALL;
}

static int gather_points(const mf_walls *ws, const mf_particles *p, body_points *out)
{
    const int32_t *id = mf_particles_fi(p, ws->f_wall_id);
    size_t n = 0;
    for (size_t i = 0; i < p->n_owned; i++)
        n += is_body_point(ws, p, id, i);
    body_point *mine = malloc((n ? n : 1) * sizeof *mine);
    if (!mine)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the rigid bodies' contacts");
    n = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        if (!is_body_point(ws, p, id, i))
            continue;
        mine[n].id = p->id[i];
        mine[n].body = id[i] - 1;
        memcpy(mine[n].x, &p->pos[3 * i], sizeof mine[n].x);
        n++;
    }
    if (!ws->par) {
        out->pt = mine;
        out->n = n;
        return 0;
    }
    void *all = NULL;
    size_t bytes = 0;
    const int rc = mf_parallel_allgatherv(ws->par, mine, n * sizeof *mine, &all, &bytes);
    free(mine);
    MF_CALL(rc);
    out->pt = all;
    out->n = bytes / sizeof *out->pt;
    qsort(out->pt, out->n, sizeof *out->pt, cmp_point);
    return 0;
}

/* The overlap of body A's outer particles with solid B at the trial
 * states: returns the deepest delta (<= 0: none), and the overlapping
 * particles' mean trial position and mean normal of B, weighted by their
 * overlap (a face resting flat on a plane: its middle, so that the impulse
 * there stops the body without turning it). */
static double overlap(const mf_walls *ws, const body_points *p, size_t ka, const mf_wall *B,
                      double xc[3], double nc[3])
{
    const mf_wall *A = &ws->w[ka];
    const mf_body *a = A->body;
    double best = 0, sw = 0, sx[3] = {0, 0, 0}, sn[3] = {0, 0, 0};
    for (size_t i = 0; i < p->n; i++) {
        if (p->pt[i].body != (int64_t)ka)
            continue;
        const double *x = p->pt[i].x;
        const double r[3] = {x[0] - a->x[0], x[1] - a->x[1], x[2] - a->x[2]};
        double rb[3], rt[3], xt[3], n[3];
        mf_mat3_t_vec(a->R, r, rb); /* body axes */
        mf_mat3_vec(a->Rt, rb, rt);
        for (int c = 0; c < 3; c++)
            xt[c] = a->xt[c] + rt[c];
        const double delta = 0.5 * ws->l0 - mf_wall_distance(B, xt, n);
        if (!(delta > 0) || !isfinite(delta))
            continue;
        best = fmax(best, delta);
        sw += delta;
        for (int c = 0; c < 3; c++) {
            sx[c] += delta * xt[c];
            sn[c] += delta * n[c];
        }
    }
    if (!(sw > 0))
        return 0;
    const double len = sqrt(sn[0] * sn[0] + sn[1] * sn[1] + sn[2] * sn[2]);
    if (!(len > 0))
        return 0;
    for (int c = 0; c < 3; c++) {
        xc[c] = sx[c] / sw;
        nc[c] = sn[c] / len;
    }
    return best;
}

/* 1/m + n.((I^-1 (r x n)) x r), I^-1 = R I_b^-1 R^T (the committed R, as
 * the trial's w is computed), and the velocity of body point x. */
static double inverse_mass(const mf_body *b, const double x[3], const double n[3], double v[3])
{
    const double r[3] = {x[0] - b->xt[0], x[1] - b->xt[1], x[2] - b->xt[2]};
    double rn[3], t[3], u[3], Iu[3], k[3];
    mf_cross3(r, n, rn);
    mf_mat3_t_vec(b->R, rn, t);
    mf_mat3_vec(b->Ib_inv, t, u);
    mf_mat3_vec(b->R, u, Iu);
    mf_cross3(Iu, r, k);
    double wr[3];
    mf_cross3(b->wt, r, wr);
    for (int c = 0; c < 3; c++)
        v[c] = b->vt[c] + wr[c];
    return 1 / b->mass + (k[0] * n[0] + k[1] * n[1] + k[2] * n[2]);
}

/* Impulse j n at world point x on body w; its trial state again. */
static void apply(mf_wall *w, int dim, double dt, const double x[3], const double jn[3])
{
    mf_body *b = w->body;
    const double r[3] = {x[0] - b->xt[0], x[1] - b->xt[1], x[2] - b->xt[2]};
    double h[3];
    mf_cross3(r, jn, h);
    for (int c = 0; c < 3; c++) {
        b->vt[c] += c < dim ? jn[c] / b->mass : 0;
        b->Lt[c] += h[c];
    }
    mf_body_finish_trial(w, dim, dt);
}

/* Moves the trial position of w by s (the overlap removed). */
static void shift(mf_wall *w, int dim, const double s[3])
{
    mf_body *b = w->body;
    for (int c = 0; c < dim; c++)
        b->xt[c] += s[c];
    for (int c = 0; c < 3; c++)
        w->state.d[c] = b->xt[c] - w->motion.origin[c];
}

/* Sweeps of the sequential impulses over the contact points of a pair (a
 * resting face reaches its support in a few; Catto 2005, "Iterative
 * dynamics with temporal coherence", GDC). */
#define CONTACT_SWEEPS 50
#define CONTACT_PASSES 4

/* Coulomb friction at contact point x of A with B after its normal impulse
 * (Catto 2005: the tangential impulse that stops the sliding velocity v_t,
 * its total lt over the sweeps kept within the friction cone |lt| <= mu
 * lam, lam the point's normal total). Returns the change of the impulse. */
static double friction(mf_wall *A, mf_wall *B, int dim, double dt, const double x[3],
                       const double n[3], double mu, double lam, double lt[3])
{
    mf_body *a = A->body, *b = B->body;
    double va[3], vb[3] = {0, 0, 0};
    inverse_mass(a, x, n, va);
    if (b)
        inverse_mass(b, x, n, vb);
    else
        mf_wall_velocity(B, x, true, vb);
    const double rel[3] = {va[0] - vb[0], va[1] - vb[1], va[2] - vb[2]};
    const double vn = rel[0] * n[0] + rel[1] * n[1] + rel[2] * n[2];
    double vt[3], want[3];
    for (int c = 0; c < 3; c++)
        vt[c] = c < dim ? rel[c] - vn * n[c] : 0;
    const double speed = sqrt(vt[0] * vt[0] + vt[1] * vt[1] + vt[2] * vt[2]);
    memcpy(want, lt, sizeof want);
    if (speed > 0) {
        const double t[3] = {vt[0] / speed, vt[1] / speed, vt[2] / speed};
        double ua[3], ub[3];
        double k = inverse_mass(a, x, t, ua);
        if (b)
            k += inverse_mass(b, x, t, ub);
        for (int c = 0; c < 3; c++)
            want[c] -= speed / k * t[c];
    }
    const double len = sqrt(want[0] * want[0] + want[1] * want[1] + want[2] * want[2]);
    if (len > mu * lam)
        for (int c = 0; c < 3; c++)
            want[c] *= mu * lam / len;
    const double dj[3] = {want[0] - lt[0], want[1] - lt[1], want[2] - lt[2]};
    const double mdj[3] = {-dj[0], -dj[1], -dj[2]};
    memcpy(lt, want, sizeof want);
    const double change = sqrt(dj[0] * dj[0] + dj[1] * dj[1] + dj[2] * dj[2]);
    if (change > 0) {
        apply(A, dim, dt, x, dj);
        if (b)
            apply(B, dim, dt, x, mdj);
    }
    return change;
}

/* One sweep over A's particles that overlap B at the first sweep (normal
 * holds B's normal there; target NaN: not a contact): the normal impulse at each
 * is set so that its approach v_n becomes the target -e v_n0 (v_n0 its
 * approach at the first sweep), its total lam[i] over the sweeps kept >= 0
 * (a contact pushes, never pulls: Catto's accumulated clamping). Returns
 * the largest change of an impulse, N s (2-D: per metre). */
static double sweep(mf_walls *ws, const body_points *p, size_t ka, size_t kb, double e,
                    double mu, double dt, bool first, double *lam, double *target,
                    double *normal, double *lt)
{
    mf_wall *A = &ws->w[ka], *B = &ws->w[kb];
    const int dim = ws->dim;
    double change = 0;
    for (size_t i = 0; i < p->n; i++) {
        if (p->pt[i].body != (int64_t)ka)
            continue;
        mf_body *a = A->body, *b = B->body;
        const double *x0 = p->pt[i].x;
        const double r[3] = {x0[0] - a->x[0], x0[1] - a->x[1], x0[2] - a->x[2]};
        double rb[3], rt[3], x[3], n[3];
        mf_mat3_t_vec(a->R, r, rb);
        mf_mat3_vec(a->Rt, rb, rt);
        for (int c = 0; c < 3; c++)
            x[c] = a->xt[c] + rt[c];
        /* the contact points and normals are those of the first sweep */
        if (first) {
            lam[i] = 0;
            lt[3 * i] = lt[3 * i + 1] = lt[3 * i + 2] = 0;
            target[i] = NAN;
            const double delta = 0.5 * ws->l0 - mf_wall_distance(B, x, &normal[3 * i]);
            if (!(delta > 0) || !isfinite(delta))
                continue;
        } else if (isnan(target[i])) {
            continue;
        }
        memcpy(n, &normal[3 * i], sizeof n);
        double va[3], vb[3] = {0, 0, 0};
        double k = inverse_mass(a, x, n, va);
        if (b)
            k += inverse_mass(b, x, n, vb);
        else
            mf_wall_velocity(B, x, true, vb);
        const double vn = (va[0] - vb[0]) * n[0] + (va[1] - vb[1]) * n[1] + (va[2] - vb[2]) * n[2];
        if (first)
            target[i] = vn < 0 ? -e * vn : 0;
        const double next = fmax(lam[i] + (target[i] - vn) / k, 0);
        const double j = next - lam[i];
        lam[i] = next;
        if (j != 0) {
            const double jn[3] = {j * n[0], j * n[1], j * n[2]};
            const double mjn[3] = {-jn[0], -jn[1], -jn[2]};
            apply(A, dim, dt, x, jn);
            if (b)
                apply(B, dim, dt, x, mjn);
            change = fmax(change, fabs(j));
        }
        if (mu > 0) /* mu 0: no friction, the frictionless results unchanged */
            change = fmax(change, friction(A, B, dim, dt, x, n, mu, lam[i], &lt[3 * i]));
    }
    return change;
}

static void contact_pair(mf_walls *ws, const body_points *p, size_t ka, size_t kb, double dt,
                         bool bounce, double *lam, double *target, double *normal, double *lt)
{
    mf_wall *A = &ws->w[ka], *B = &ws->w[kb];
    mf_body *a = A->body, *b = B->body;
    const int dim = ws->dim;
    double x[3], n[3];
    if (!(overlap(ws, p, ka, B, x, n) > 0))
        return;
    const double e = !bounce ? 0
                     : b     ? 0.5 * (A->motion.restitution + B->motion.restitution)
                             : A->motion.restitution;
    const double mu = b ? 0.5 * (A->motion.friction + B->motion.friction) : A->motion.friction;
    /* until the impulses change by less than 1e-9 of the body's momentum
     * scale m sqrt(g l0), or CONTACT_SWEEPS */
    const double g = sqrt(A->motion.g[0] * A->motion.g[0] + A->motion.g[1] * A->motion.g[1] +
                          A->motion.g[2] * A->motion.g[2]);
    const double tol = 1e-9 * a->mass * fmax(sqrt(g * ws->l0), 1e-3);
    for (int s = 0; s < CONTACT_SWEEPS; s++)
        if (!(sweep(ws, p, ka, kb, e, mu, dt, s == 0, lam, target, normal, lt) > tol))
            break;
    /* the overlap left at the new trial states */
    const double delta = overlap(ws, p, ka, B, x, n);
    if (!(delta > 0))
        return;
    const double wa = b ? (1 / a->mass) / (1 / a->mass + 1 / b->mass) : 1;
    const double sa[3] = {wa * delta * n[0], wa * delta * n[1], wa * delta * n[2]};
    shift(A, dim, sa);
    if (b) {
        const double wb = 1 - wa;
        const double sb[3] = {-wb * delta * n[0], -wb * delta * n[1], -wb * delta * n[2]};
        shift(B, dim, sb);
    }
}

int mf_bodies_contact(mf_walls *ws, const mf_particles *p, double dt)
{
    if (ws->f_wall_id < 0 || !ws->particles || mf_bodies_count(ws) == 0)
        return 0;
    body_points pts = {NULL, 0};
    MF_CALL(gather_points(ws, p, &pts));
    const size_t n = pts.n ? pts.n : 1;
    double *lam = malloc(n * sizeof *lam), *target = malloc(n * sizeof *target);
    double *normal = malloc(3 * n * sizeof *normal), *lt = malloc(3 * n * sizeof *lt);
    if (!lam || !target || !normal || !lt) {
        free(lt);
        free(lam);
        free(target);
        free(normal);
        free(pts.pt);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the rigid bodies' contacts");
    }
    /* every pair, CONTACT_PASSES times: what one pair's impulses do to a
     * body is seen by its other contacts (a stack on a floor); restitution
     * in the first pass only */
    for (int pass = 0; pass < CONTACT_PASSES; pass++)
        for (size_t ka = 0; ka < ws->n; ka++) {
            if (!ws->w[ka].body)
                continue;
            for (size_t kb = 0; kb < ws->n; kb++)
                if (kb != ka)
                    contact_pair(ws, &pts, ka, kb, dt, pass == 0, lam, target, normal, lt);
        }
    free(pts.pt);
    free(lam);
    free(target);
    free(normal);
    free(lt);
    return 0;
}
