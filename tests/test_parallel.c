/* test_parallel: the distributed particle set (core/parallel) on however
 * many ranks mpirun gives it (CI: 1 and 3, oversubscribed).
 *
 *  - distribute: every particle owned by exactly one rank, none lost, every
 *    array and field still attached to its particle (fields are functions of
 *    the id), each particle in the region of the rank that owns it;
 *  - migrate: after the fluid moves, the same, and the count conserved;
 *  - rebalance: all fluid pushed into one corner is one rank's load; the
 *    imbalance then passes the threshold, a new partition brings it back
 *    below a bound (printed);
 *  - halo: for every owned particle, the particles within the radius found
 *    among [0, n) are exactly those a brute-force search over all particles
 *    finds (through the periodic axis too), and updates give each copy its
 *    owner's value;
 *  - agree: a failure on one rank reaches every rank with its message.
 */
#include <math.h>
#include <mpi.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mf_halo.h"
#include "mf_parallel.h"
#include "mf_test.h"

static int rank, nranks;

/* Fields: a scalar f(id) and an int32 vector (3 comps). */
typedef struct {
    int scalar, ivec;
} fields;

static double f_of(int64_t id)
{
    return 0.25 * (double)id + 1.0;
}

/* A 2-D or 3-D block of particles on a jittered lattice (the same on every
 * rank: same seed), kinds by position (a floor of walls and dummies). */
static mf_particles *make_particles(int dim, int nx, fields *f, double *L)
{
    mf_particles *p = NULL;
    CHECK_OK(mf_particles_create(dim, 16, &p));
    CHECK_OK(mf_particles_request_field(p, "S", 1, MF_FIELD_DOUBLE, true, &f->scalar));
    CHECK_OK(mf_particles_request_field(p, "I", 3, MF_FIELD_INT32, false, &f->ivec));
    unsigned seed = 12345;
    const int nz = dim == 3 ? nx / 2 : 1;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < nx; j++)
            for (int i = 0; i < nx; i++) {
                seed = seed * 1103515245u + 12345u;
                double jitter = ((seed >> 16) & 1023) / 1023.0 - 0.5;
                double x[3] = {i + 0.5 + 0.2 * jitter, j + 0.3 * jitter, dim == 3 ? k : 0};
                double v[3] = {jitter, 0, 0};
                int kind = j == 0 ? MF_DUMMY : j == 1 ? MF_WALL : MF_FLUID;
                int64_t id;
                CHECK_OK(mf_particles_add(p, kind, x, v, &id));
                size_t at = p->n - 1;
                mf_particles_fd(p, f->scalar)[at] = f_of(id);
                for (int c = 0; c < 3; c++)
                    mf_particles_fi(p, f->ivec)[3 * at + c] = (int32_t)(id * (c + 2));
            }
    *L = nx;
    return p;
}

/* Everything attached to particle i agrees with its id. */
static size_t mismatches(const mf_particles *p, const fields *f, size_t from, size_t to)
{
    size_t bad = 0;
    for (size_t i = from; i < to; i++) {
        int64_t id = p->id[i];
        bool ok = mf_particles_fd(p, f->scalar)[i] == f_of(id);
        for (int c = 0; c < 3; c++)
            ok = ok && mf_particles_fi(p, f->ivec)[3 * i + c] == (int32_t)(id * (c + 2));
        bad += !ok;
    }
    return bad;
}

/* Every id in [0, total) owned exactly once over the ranks. */
static void check_ownership(const mf_parallel *par, const mf_particles *p, int64_t total,
                            const char *when)
{
    int64_t n = (int64_t)p->n_owned;
    mf_parallel_sum_i64(par, &n, 1);
    CHECK_MSG(n == total, "%s: %lld particles owned, %lld expected", when, (long long)n,
              (long long)total);
    int32_t *count = calloc((size_t)total, sizeof *count);
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->id[i] >= 0 && p->id[i] < total)
            count[p->id[i]]++;
    MPI_Allreduce(MPI_IN_PLACE, count, (int)total, MPI_INT32_T, MPI_SUM, MPI_COMM_WORLD);
    int64_t twice = 0, lost = 0;
    for (int64_t k = 0; k < total; k++) {
        twice += count[k] > 1;
        lost += count[k] == 0;
    }
    CHECK_MSG(twice == 0 && lost == 0, "%s: %lld particles owned twice, %lld lost", when,
              (long long)twice, (long long)lost);
    free(count);
    /* Each owned particle lies in its rank's region (walls and dummies too:
     * a partition places them, migration never needs to). */
    size_t elsewhere = 0;
    for (size_t i = 0; i < p->n_owned; i++)
        elsewhere += mf_parallel_owner_of(par, &p->pos[3 * i]) != rank;
    CHECK_MSG(elsewhere == 0, "%s: %zu particles of rank %d are in another rank's region",
              when, elsewhere, rank);
}

/* All particles of every rank (owned), gathered everywhere: positions and ids. */
static void gather_all(const mf_particles *p, double **pos, int64_t **ids, int *ntotal)
{
    int mine = (int)p->n_owned;
    int *counts = malloc(nranks * sizeof *counts), *displs = malloc(nranks * sizeof *displs);
    MPI_Allgather(&mine, 1, MPI_INT, counts, 1, MPI_INT, MPI_COMM_WORLD);
    int total = 0;
    for (int r = 0; r < nranks; r++) {
        displs[r] = total;
        total += counts[r];
    }
    *ids = malloc((size_t)total * sizeof **ids);
    *pos = malloc(3 * (size_t)total * sizeof **pos);
    MPI_Allgatherv(p->id, mine, MPI_INT64_T, *ids, counts, displs, MPI_INT64_T, MPI_COMM_WORLD);
    for (int r = 0; r < nranks; r++) {
        counts[r] *= 3;
        displs[r] *= 3;
    }
    MPI_Allgatherv(p->pos, 3 * mine, MPI_DOUBLE, *pos, counts, displs, MPI_DOUBLE,
                   MPI_COMM_WORLD);
    *ntotal = total;
    free(counts);
    free(displs);
}

/* Neighbours within r of each owned particle: from [0, n) against brute
 * force over all particles with the minimum image along x (period L, or
 * none when L == 0). Compared by count and by the sum of ids. */
static void check_halo(const mf_particles *p, double r, double L, const char *when)
{
    double *all;
    int64_t *ids;
    int total;
    gather_all(p, &all, &ids, &total);
    size_t wrong = 0;
    for (size_t i = 0; i < p->n_owned; i++) {
        const double *x = &p->pos[3 * i];
        long n_local = 0, n_brute = 0;
        int64_t s_local = 0, s_brute = 0;
        for (size_t j = 0; j < p->n; j++) {
            if (j == i)
                continue;
            double d2 = 0;
            for (int c = 0; c < 3; c++)
                d2 += (p->pos[3 * j + c] - x[c]) * (p->pos[3 * j + c] - x[c]);
            if (d2 < r * r) {
                n_local++;
                s_local += p->id[j];
            }
        }
        for (int j = 0; j < total; j++) {
            if (ids[j] == p->id[i])
                continue;
            double d[3];
            for (int c = 0; c < 3; c++)
                d[c] = all[3 * j + c] - x[c];
            if (L > 0)
                d[0] -= L * round(d[0] / L);
            if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < r * r) {
                n_brute++;
                s_brute += ids[j];
            }
        }
        wrong += n_local != n_brute || s_local != s_brute;
    }
    CHECK_MSG(wrong == 0, "%s: %zu particles of rank %d see other neighbours than brute force",
              when, wrong, rank);
    free(all);
    free(ids);
}

static void test_set(int dim, int nx, mf_decompose_method method)
{
    fields f;
    double L = 0;
    mf_particles *p = make_particles(dim, nx, &f, &L);
    const int64_t total = (int64_t)p->n_owned;
    mf_parallel_settings s;
    mf_parallel_default_settings(&s);
    s.method = method;
    mf_parallel *par = NULL;
    CHECK_OK(mf_parallel_create(&s, &par));
    CHECK((par == NULL) == (nranks == 1));
    CHECK_OK(mf_parallel_distribute(par, p, p->next_id));
    check_ownership(par, p, total, "distribute");
    CHECK(mismatches(p, &f, 0, p->n_owned) == 0);
    double imb = mf_parallel_imbalance(par, p, NULL);
    if (rank == 0)
        printf("%d-D %s, %d ranks: %lld particles, imbalance after the first partition %.3f\n",
               dim, method == MF_DECOMPOSE_RCB ? "RCB" : "HSFC", nranks, (long long)total, imb);
    CHECK_MSG(imb <= 1.1, "imbalance %g after the first partition", imb);

    /* New ids never collide across ranks. */
    int64_t before = p->next_id, id = -1;
    double x[3] = {0.5, 3.5, 0};
    CHECK_OK(mf_particles_add(p, MF_FLUID, x, NULL, &id));
    CHECK(id == before && (id - total) % nranks == rank);
    int64_t *all_new = malloc(nranks * sizeof *all_new);
    MPI_Allgather(&id, 1, MPI_INT64_T, all_new, 1, MPI_INT64_T, MPI_COMM_WORLD);
    for (int r = 0; r < nranks; r++)
        for (int q = 0; q < r; q++)
            CHECK(all_new[r] != all_new[q]);
    free(all_new);
    size_t last = p->n - 1;
    mf_particles_fd(p, f.scalar)[last] = f_of(id);
    for (int c = 0; c < 3; c++)
        mf_particles_fi(p, f.ivec)[3 * last + c] = (int32_t)(id * (c + 2));
    int64_t total_now = total + nranks;

    /* The fluid moves a few spacings: migration keeps every particle once. */
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->kind[i] == MF_FLUID)
            p->pos[3 * i] += 2.3 + 0.5 * sin((double)p->id[i]);
    CHECK_OK(mf_parallel_balance(par, p, false));
    /* ids of the new particles run past total: count by id range. */
    int64_t n = (int64_t)p->n_owned;
    mf_parallel_sum_i64(par, &n, 1);
    CHECK(n == total_now);
    CHECK(mismatches(p, &f, 0, p->n_owned) == 0);
    size_t elsewhere = 0;
    for (size_t i = 0; i < p->n_owned; i++)
        elsewhere += mf_parallel_owner_of(par, &p->pos[3 * i]) != rank;
    CHECK(elsewhere == 0);

    /* Halo at radius 2.1 without and with a period along x (all fluid
     * wrapped into the period first, walls are inside it already). */
    mf_halo *h = NULL;
    CHECK_OK(mf_halo_create(&h));
    mf_halo_spec hs = {.radius = 2.1, .velocities = true, .nfields = 1, .field = {f.scalar}};
    CHECK_OK(mf_halo_build(h, par, p, &hs));
    check_halo(p, hs.radius, 0, "halo");
    CHECK(mismatches(p, &f, p->n_owned, p->n) == 0 || hs.nfields < 2);
    size_t bad_scalar = 0;
    for (size_t j = p->n_owned; j < p->n; j++)
        bad_scalar += mf_particles_fd(p, f.scalar)[j] != f_of(p->id[j]);
    CHECK(bad_scalar == 0);
    mf_halo_drop(h, p);

    hs.periodic_axis = 0;
    hs.periodic_origin = 0;
    hs.periodic_length = L;
    mf_halo_wrap(&hs, p);
    CHECK_OK(mf_parallel_balance(par, p, false));
    CHECK_OK(mf_halo_build(h, par, p, &hs));
    check_halo(p, hs.radius, L, "periodic halo");
    /* Updates: a value computed on the owned particles reaches the copies,
     * and the motion of owners moves the copies (shifted for images). */
    int64_t *value = malloc((p->n + 1) * sizeof *value);
    for (size_t i = 0; i < p->n; i++)
        value[i] = i < p->n_owned ? 7 * p->id[i] + 1 : -1;
    CHECK_OK(mf_halo_update(h, par, p, value, sizeof *value));
    size_t bad_value = 0;
    for (size_t j = p->n_owned; j < p->n; j++)
        bad_value += value[j] != 7 * p->id[j] + 1;
    CHECK(bad_value == 0);
    free(value);
    for (size_t i = 0; i < p->n_owned; i++)
        p->vel[3 * i + 1] = (double)p->id[i];
    double *copy_x = malloc((p->n + 1) * sizeof *copy_x);
    for (size_t j = 0; j < p->n; j++)
        copy_x[j] = p->pos[3 * j];
    for (size_t i = 0; i < p->n_owned; i++)
        p->pos[3 * i] += 0.01;
    CHECK_OK(mf_halo_update_motion(h, par, p));
    size_t bad_motion = 0;
    for (size_t j = p->n_owned; j < p->n; j++)
        bad_motion += fabs(p->pos[3 * j] - copy_x[j] - 0.01) > 1e-12 ||
                      p->vel[3 * j + 1] != (double)p->id[j];
    CHECK(bad_motion == 0);
    free(copy_x);
    mf_halo_drop(h, p);
    CHECK(p->n == p->n_owned);

    /* A deliberately unbalanced state: all fluid in one corner. */
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->kind[i] == MF_FLUID)
            for (int c = 0; c < dim; c++)
                p->pos[3 * i + c] = 0.05 * (p->pos[3 * i + c] - 2) + 0.2 * L + (c == 1 ? 2 : 0);
    mf_parallel_stats *st = mf_parallel_statistics(par);
    long rebalances = st ? st->rebalances : 0;
    CHECK_OK(mf_parallel_balance(par, p, false));
    imb = mf_parallel_imbalance(par, p, NULL);
    if (rank == 0 && st)
        printf("    unbalanced start: imbalance %.3f, after rebalancing %.3f (%ld partitions)\n",
               st->imbalance_before, imb, st->rebalances);
    if (st) {
        CHECK(st->rebalances == rebalances + 1);
        CHECK(st->imbalance_before > s.imbalance_threshold);
    }
    CHECK_MSG(imb <= 1.1, "imbalance %g after rebalancing", imb);
    n = (int64_t)p->n_owned;
    mf_parallel_sum_i64(par, &n, 1);
    CHECK(n == total_now);
    CHECK(mismatches(p, &f, 0, p->n_owned) == 0);

    mf_halo_destroy(h);
    mf_parallel_destroy(par);
    mf_particles_destroy(p);
}

static void test_agree(void)
{
    mf_parallel *par = NULL;
    CHECK_OK(mf_parallel_create(NULL, &par));
    CHECK(mf_parallel_agree(par, 0) == 0);
    int rc = rank == nranks - 1 ? MF_ERROR(MF_ERR_NUMERIC, "unstable (test) on the last rank")
                                : 0;
    rc = mf_parallel_agree(par, rc);
    CHECK(rc == MF_ERR_NUMERIC);
    CHECK(strstr(mf_error_message(), "unstable (test) on the last rank") != NULL);
    mf_error_clear();
    /* Exclusive scan: rank r's offset is the sum of the ranks before it. */
    CHECK(mf_parallel_exscan(par, 10 + rank) == 10 * rank + rank * (rank - 1) / 2);
    double v = rank == 1 % nranks ? 5.0 : 1.0;
    int who = -1;
    mf_parallel_maxloc(par, &v, &who);
    CHECK(v == 5.0 && who == 1 % nranks);
    mf_parallel_destroy(par);
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &nranks);
    test_agree();
    test_set(2, 40, MF_DECOMPOSE_RCB);
    test_set(3, 16, MF_DECOMPOSE_RCB);
    test_set(2, 40, MF_DECOMPOSE_HSFC);
    int failures = mf_test_failures;
    MPI_Allreduce(MPI_IN_PLACE, &failures, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    int rc = rank == 0 ? mf_test_summary("parallel") : 0;
    if (failures && rank == 0)
        rc = EXIT_FAILURE;
    MPI_Finalize();
    return rc;
}
