/* test_particles: the structure-of-arrays store keeps every array, optional
 * fields included, attached to the right particle through add, remove and
 * permute. Each field holds a function of the particle's id, so any slip
 * shows up as a mismatch. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mf_particles.h"
#include "mf_test.h"

typedef struct {
    int scalar, integer, vector; /* field indices */
} fields;

static void set_from_id(mf_particles *p, size_t i, const fields *f)
{
    double id = (double)p->id[i];
    mf_particles_fd(p, f->scalar)[i] = id;
    mf_particles_fi(p, f->integer)[i] = (int32_t)p->id[i];
    for (int d = 0; d < 3; d++)
        mf_particles_fd(p, f->vector)[3 * i + d] = (d + 1) * id;
}

/* Every array of particle i agrees with its id; returns mismatches. */
static size_t count_mismatches(const mf_particles *p, const fields *f)
{
    size_t bad = 0;
    for (size_t i = 0; i < p->n; i++) {
        double id = (double)p->id[i];
        const double *x = p->pos + 3 * i, *v = p->vel + 3 * i;
        bool ok = mf_particles_fd(p, f->scalar)[i] == id &&
                  mf_particles_fi(p, f->integer)[i] == (int32_t)p->id[i] && x[0] == id &&
                  x[1] == -id && x[2] == 0.5 * id && v[0] == 2 * id && v[1] == 0 && v[2] == -id &&
                  p->kind[i] == p->id[i] % MF_NKINDS;
        for (int d = 0; d < 3; d++)
            ok = ok && mf_particles_fd(p, f->vector)[3 * i + d] == (d + 1) * id;
        bad += !ok;
    }
    return bad;
}

static bool ids_unique(const mf_particles *p)
{
    /* ids are handed out increasing and every operation here keeps or
     * permutes them, so uniqueness = no repeat among n values in [0, next_id). */
    size_t range = (size_t)p->next_id;
    uint8_t *seen = calloc(range + 1, 1);
    bool ok = seen != NULL;
    for (size_t i = 0; ok && i < p->n; i++) {
        int64_t id = p->id[i];
        if (id < p->id_base || id >= p->next_id || seen[id])
            ok = false;
        else
            seen[id] = 1;
    }
    free(seen);
    return ok;
}

static void add_with_id_values(mf_particles *p, const fields *f, size_t count)
{
    for (size_t k = 0; k < count; k++) {
        double id = (double)p->next_id;
        double x[3] = {id, -id, 0.5 * id}, v[3] = {2 * id, 0, -id};
        int64_t got = -1;
        size_t old_cap = p->cap;
        CHECK_OK(mf_particles_add(p, (int)(p->next_id % MF_NKINDS), x, v, &got));
        CHECK(got == (int64_t)id);
        if (p->cap != old_cap) /* growth by doubling */
            CHECK_MSG(p->cap == 2 * old_cap, "capacity %zu -> %zu", old_cap, p->cap);
        size_t i = p->n - 1;
        /* A new particle's optional fields start at zero. */
        CHECK(mf_particles_fd(p, f->scalar)[i] == 0.0 && mf_particles_fi(p, f->integer)[i] == 0);
        set_from_id(p, i, f);
    }
}

static void test_defaults(void)
{
    mf_particles *p = NULL;
    CHECK(mf_particles_create(4, 10, &p) == MF_ERR_INPUT);
    CHECK(p == NULL);
    mf_error_clear();
    CHECK_OK(mf_particles_create(3, 5, &p));
    CHECK(p->dim == 3 && p->n == 0 && p->n_owned == 0 && p->cap >= 5);
    CHECK(p->rank == 0 && p->nranks == 1 && p->global_offset == 0 && p->id_base == 0);
    CHECK(p->next_id == 0 && p->nfields == 0);
    CHECK(strcmp(mf_particle_kind_name(MF_FLUID), "fluid") == 0);
    CHECK(strcmp(mf_particle_kind_name(MF_WALL), "wall") == 0);
    CHECK(strcmp(mf_particle_kind_name(MF_DUMMY), "dummy") == 0);
    CHECK(strcmp(mf_particle_kind_name(MF_INLET), "inlet") == 0);
    CHECK(strcmp(mf_particle_kind_name(MF_OUTLET), "outlet") == 0);
    CHECK(mf_particle_kind_name(MF_NKINDS) != NULL);
    double x[3] = {0, 0, 0};
    CHECK(mf_particles_add(p, MF_NKINDS, x, NULL, NULL) == MF_ERR_INPUT);
    mf_error_clear();
    CHECK(p->n == 0);
    mf_particles_destroy(p);
    mf_particles_destroy(NULL);

    /* 2-D stores keep z = 0 whatever is passed. */
    CHECK_OK(mf_particles_create(2, 0, &p));
    double x2[3] = {1, 2, 3}, v2[3] = {4, 5, 6};
    CHECK_OK(mf_particles_add(p, MF_FLUID, x2, v2, NULL));
    CHECK(p->pos[0] == 1 && p->pos[1] == 2 && p->pos[2] == 0);
    CHECK(p->vel[0] == 4 && p->vel[1] == 5 && p->vel[2] == 0);
    mf_particles_destroy(p);
}

static void test_fields(void)
{
    mf_particles *p = NULL;
    CHECK_OK(mf_particles_create(3, 0, &p));
    int a = -1, b = -1;
    CHECK_OK(mf_particles_request_field(p, "pressure", 1, MF_FIELD_DOUBLE, false, &a));
    CHECK_OK(mf_particles_request_field(p, "pressure", 1, MF_FIELD_DOUBLE, true, &b));
    CHECK(a == b && p->nfields == 1);
    CHECK(p->field[a].output); /* one request for output is enough */
    CHECK(mf_particles_request_field(p, "pressure", 3, MF_FIELD_DOUBLE, false, &b) == MF_ERR_INPUT);
    mf_error_clear();
    CHECK(mf_particles_request_field(p, "pressure", 1, MF_FIELD_INT32, false, &b) == MF_ERR_INPUT);
    mf_error_clear();
    CHECK(mf_particles_field_index(p, "pressure") == a);
    CHECK(mf_particles_field_index(p, "velocity_gradient") == -1);

    char long_name[40];
    memset(long_name, 'x', sizeof long_name - 1);
    long_name[32] = '\0'; /* 32 characters: one too many */
    CHECK(mf_particles_request_field(p, long_name, 1, MF_FIELD_DOUBLE, false, &b) == MF_ERR_INPUT);
    mf_error_clear();
    long_name[31] = '\0'; /* 31 is the maximum */
    CHECK_OK(mf_particles_request_field(p, long_name, 1, MF_FIELD_DOUBLE, false, &b));
    CHECK(mf_particles_field_index(p, long_name) == b);
    CHECK(mf_particles_request_field(p, "", 1, MF_FIELD_DOUBLE, false, &b) == MF_ERR_INPUT);
    mf_error_clear();
    CHECK(mf_particles_request_field(p, "bad_type", 1, 7, false, &b) == MF_ERR_INPUT);
    mf_error_clear();

    /* Fill the slots up, then one more fails. */
    while (p->nfields < MF_MAX_FIELDS) {
        char name[16];
        snprintf(name, sizeof name, "f%d", p->nfields);
        CHECK_OK(mf_particles_request_field(p, name, 1, MF_FIELD_INT32, false, &b));
    }
    CHECK(mf_particles_request_field(p, "one_too_many", 1, MF_FIELD_DOUBLE, false, &b) ==
          MF_ERR_INPUT);
    mf_error_clear();
    mf_particles_destroy(p);

    /* A field requested after particles exist is zero for all of them, also
     * after growth. */
    CHECK_OK(mf_particles_create(2, 0, &p));
    double x[3] = {0, 0, 0};
    for (int k = 0; k < 100; k++)
        CHECK_OK(mf_particles_add(p, MF_FLUID, x, NULL, NULL));
    CHECK_OK(mf_particles_request_field(p, "late", 3, MF_FIELD_DOUBLE, false, &a));
    for (int k = 0; k < 100; k++)
        CHECK_OK(mf_particles_add(p, MF_FLUID, x, NULL, NULL));
    size_t nonzero = 0;
    for (size_t i = 0; i < 3 * p->n; i++)
        nonzero += mf_particles_fd(p, a)[i] != 0.0;
    CHECK(nonzero == 0);
    mf_particles_destroy(p);
}

static void test_add_remove_permute(void)
{
    mf_particles *p = NULL;
    CHECK_OK(mf_particles_create(3, 4, &p));
    fields f;
    CHECK_OK(mf_particles_request_field(p, "scalar", 1, MF_FIELD_DOUBLE, true, &f.scalar));
    CHECK_OK(mf_particles_request_field(p, "integer", 1, MF_FIELD_INT32, false, &f.integer));
    CHECK_OK(mf_particles_request_field(p, "vector", 3, MF_FIELD_DOUBLE, false, &f.vector));

    add_with_id_values(p, &f, 1000);
    CHECK(p->n == 1000 && p->n_owned == 1000 && p->next_id == 1000);
    CHECK(ids_unique(p));
    CHECK(count_mismatches(p, &f) == 0);
    size_t counts[MF_NKINDS];
    mf_particles_count_kinds(p, counts);
    CHECK(counts[MF_FLUID] == 200 && counts[MF_OUTLET] == 200);

    /* Remove every third particle and a block: order of the rest is kept. */
    uint8_t *flag = calloc(p->n, 1);
    size_t expect = 0;
    for (size_t i = 0; i < p->n; i++) {
        flag[i] = i % 3 == 0 || (i >= 500 && i < 600);
        expect += flag[i];
    }
    size_t removed = 0;
    CHECK_OK(mf_particles_remove(p, flag, &removed));
    free(flag);
    CHECK(removed == expect && p->n == 1000 - expect && p->n_owned == p->n);
    size_t unordered = 0;
    for (size_t i = 1; i < p->n; i++)
        unordered += p->id[i] <= p->id[i - 1];
    CHECK(unordered == 0);
    CHECK(count_mismatches(p, &f) == 0);
    CHECK(ids_unique(p));

    /* Ids are never reused; a reused slot starts with zero fields (checked in
     * add_with_id_values). */
    add_with_id_values(p, &f, 50);
    CHECK(p->id[p->n - 1] == 1049);
    CHECK(ids_unique(p));
    CHECK(count_mismatches(p, &f) == 0);

    /* Reverse, then a random shuffle. */
    size_t n = p->n;
    size_t *perm = malloc(n * sizeof *perm);
    for (size_t k = 0; k < n; k++)
        perm[k] = n - 1 - k;
    int64_t first_id = p->id[0], last_id = p->id[n - 1];
    CHECK_OK(mf_particles_permute(p, perm));
    CHECK(p->id[0] == last_id && p->id[n - 1] == first_id);
    CHECK(count_mismatches(p, &f) == 0);
    uint64_t s = 12345;
    for (size_t k = 0; k < n; k++)
        perm[k] = k;
    for (size_t k = n - 1; k > 0; k--) { /* Fisher-Yates */
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        size_t r = (size_t)(s >> 33) % (k + 1);
        size_t t = perm[k];
        perm[k] = perm[r];
        perm[r] = t;
    }
    int64_t *before = malloc(n * sizeof *before);
    memcpy(before, p->id, n * sizeof *before);
    CHECK_OK(mf_particles_permute(p, perm));
    size_t misplaced = 0;
    for (size_t k = 0; k < n; k++)
        misplaced += p->id[k] != before[perm[k]];
    CHECK(misplaced == 0);
    CHECK(count_mismatches(p, &f) == 0);
    CHECK(ids_unique(p));

    /* Not a permutation: a repeat, and an index out of range. */
    perm[1] = perm[0];
    CHECK(mf_particles_permute(p, perm) == MF_ERR_INPUT);
    mf_error_clear();
    perm[1] = n;
    CHECK(mf_particles_permute(p, perm) == MF_ERR_INPUT);
    mf_error_clear();
    CHECK(count_mismatches(p, &f) == 0); /* a refused permutation changes nothing */
    free(perm);
    free(before);

    /* Remove everything. */
    flag = malloc(p->n);
    memset(flag, 1, p->n);
    CHECK_OK(mf_particles_remove(p, flag, &removed));
    free(flag);
    CHECK(p->n == 0 && p->n_owned == 0 && removed == n);
    CHECK_OK(mf_particles_remove(p, NULL, &removed)); /* nothing to flag */
    CHECK(removed == 0);
    mf_particles_destroy(p);
}

static void test_reserve_memory(void)
{
    mf_particles *p = NULL;
    CHECK_OK(mf_particles_create(3, 0, &p));
    size_t per_particle = 2 * 3 * sizeof(double) + sizeof(uint8_t) + sizeof(int64_t);
    size_t m0 = mf_particles_memory(p);
    CHECK(m0 >= p->cap * per_particle);
    int fi = -1;
    CHECK_OK(mf_particles_request_field(p, "v3", 3, MF_FIELD_DOUBLE, false, &fi));
    size_t m1 = mf_particles_memory(p);
    CHECK(m1 >= m0 + p->cap * 3 * sizeof(double));

    double x[3] = {1, 2, 3};
    CHECK_OK(mf_particles_add(p, MF_WALL, x, NULL, NULL));
    CHECK_OK(mf_particles_reserve(p, 100000));
    CHECK(p->cap >= 100000);
    CHECK(p->n == 1 && p->pos[0] == 1 && p->pos[2] == 3 && p->kind[0] == MF_WALL);
    size_t m2 = mf_particles_memory(p);
    CHECK(m2 >= p->cap * (per_particle + 3 * sizeof(double)));
    CHECK(m2 < p->cap * (per_particle + 3 * sizeof(double)) + 4096 + sizeof *p);
    size_t cap = p->cap;
    CHECK_OK(mf_particles_reserve(p, 10)); /* never shrinks */
    CHECK(p->cap == cap);
    /* Growth keeps the new part of fields zero. */
    size_t nonzero = 0;
    for (size_t i = 0; i < 3 * p->cap; i++)
        nonzero += mf_particles_fd(p, fi)[i] != 0.0;
    CHECK(nonzero == 0);
    mf_particles_destroy(p);
}

int main(void)
{
    test_defaults();
    test_fields();
    test_add_remove_permute();
    test_reserve_memory();
    return mf_test_summary("particles");
}
