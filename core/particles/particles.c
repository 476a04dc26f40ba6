/* particles.c: the structure-of-arrays particle store of mf_particles.h.
 *
 * Every per-particle array (the fixed ones and the optional fields) is
 * handled through one small description, its base pointer and element size,
 * so that remove and permute cannot forget an array when fields are added.
 */
#include "mf_particles.h"

#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_error.h"

/* A fresh store never starts smaller than this: tiny capacities only cost
 * reallocations. */
#define MIN_CAPACITY 16

const char *mf_particle_kind_name(int kind)
{
    static const char *const names[MF_NKINDS] = {"fluid", "wall", "dummy", "inlet", "outlet"};
    if (kind < 0 || kind >= MF_NKINDS)
        return "unknown";
    return names[kind];
}

/* ---- per-particle array descriptions ---------------------------------- */

typedef struct {
    void **data;      /* address of the array pointer, so reserve can replace it */
    size_t elem_size; /* bytes per particle */
} array_ref;

enum { MAX_ARRAYS = 4 + MF_MAX_FIELDS };

static size_t field_elem_size(const mf_field *f)
{
    size_t scalar = f->type == MF_FIELD_INT32 ? sizeof(int32_t) : sizeof(double);
    return (size_t)f->ncomp * scalar;
}

size_t mf_particles_field_bytes(const mf_field *f)
{
    return field_elem_size(f);
}

/* Lists every per-particle array of p; returns how many. */
static int list_arrays(mf_particles *p, array_ref refs[MAX_ARRAYS])
{
    int n = 0;
    refs[n++] = (array_ref){(void **)&p->pos, 3 * sizeof(double)};
    refs[n++] = (array_ref){(void **)&p->vel, 3 * sizeof(double)};
    refs[n++] = (array_ref){(void **)&p->kind, sizeof(uint8_t)};
    refs[n++] = (array_ref){(void **)&p->id, sizeof(int64_t)};
    for (int f = 0; f < p->nfields; f++)
        refs[n++] = (array_ref){&p->field[f].data, field_elem_size(&p->field[f])};
    return n;
}

/* count * size in bytes, or 0 if that overflows size_t. */
static size_t checked_bytes(size_t count, size_t size)
{
    if (size != 0 && count > SIZE_MAX / size)
        return 0;
    return count * size;
}

/* ---- create / destroy / reserve ---------------------------------------- */

int mf_particles_create(int dim, size_t cap, mf_particles **out)
{
    if (!out)
        return MF_ERROR(MF_ERR_INPUT, "mf_particles_create: out is NULL");
    *out = NULL;
    if (dim != 2 && dim != 3)
        return MF_ERROR(MF_ERR_INPUT, "particle dimension must be 2 or 3, got %d", dim);

    mf_particles *p = calloc(1, sizeof *p);
    if (!p)
        return MF_ERROR(MF_ERR_MEMORY, "cannot allocate the particle store");
    p->dim = dim;
    p->rank = 0;
    p->nranks = 1;
    p->global_offset = 0;
    p->id_base = 0;
    p->next_id = 0;
    p->id_stride = 1;

    int rc = mf_particles_reserve(p, cap < MIN_CAPACITY ? MIN_CAPACITY : cap);
    if (rc != 0) {
        mf_particles_destroy(p);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    *out = p;
    return 0;
}

void mf_particles_destroy(mf_particles *p)
{
    if (!p)
        return;
    free(p->pos);
    free(p->vel);
    free(p->kind);
    free(p->id);
    for (int f = 0; f < p->nfields; f++)
        free(p->field[f].data);
    free(p);
}

/* Grow every array to new_cap elements, zeroing the new tail of the optional
 * fields (a field is zero until someone writes it). On failure the arrays
 * already grown keep their larger size; p->cap is only raised when all of
 * them succeeded, so the store stays consistent. */
int mf_particles_reserve(mf_particles *p, size_t cap)
{
    if (!p)
        return MF_ERROR(MF_ERR_INPUT, "mf_particles_reserve: p is NULL");
    if (cap <= p->cap)
        return 0;
    size_t new_cap = p->cap > SIZE_MAX / 2 ? cap : 2 * p->cap;
    if (new_cap < cap)
        new_cap = cap;

    array_ref refs[MAX_ARRAYS];
    int narrays = list_arrays(p, refs);
    for (int a = 0; a < narrays; a++) {
        size_t bytes = checked_bytes(new_cap, refs[a].elem_size);
        if (bytes == 0)
            return MF_ERROR(MF_ERR_MEMORY, "particle capacity %zu is too large", new_cap);
        if (mf_resize(refs[a].data, bytes, 1))
            return MF_ERROR(MF_ERR_MEMORY,
                            "cannot grow particle arrays to %zu particles (%zu bytes)", new_cap,
                            bytes);
        void *grown = *refs[a].data;
        if (a >= 4) { /* optional fields start at zero */
            size_t old_bytes = p->cap * refs[a].elem_size;
            memset((char *)grown + old_bytes, 0, bytes - old_bytes);
        }
    }
    p->cap = new_cap;
    return 0;
}

/* Shrink every array to the particles held plus headroom (never below
 * them): the doubling of mf_particles_add leaves up to half of each array
 * unused once a scene is built. A realloc to a smaller size keeps the
 * contents; should one fail, that array keeps its larger block. */
int mf_particles_fit(mf_particles *p, size_t headroom)
{
    if (!p)
        return MF_ERROR(MF_ERR_INPUT, "mf_particles_fit: p is NULL");
    size_t cap = p->n + headroom;
    if (cap < MIN_CAPACITY)
        cap = MIN_CAPACITY;
    if (cap >= p->cap)
        return 0;
    array_ref refs[MAX_ARRAYS];
    int narrays = list_arrays(p, refs);
    for (int a = 0; a < narrays; a++) {
        void *q = realloc(*refs[a].data, cap * refs[a].elem_size);
        if (q) /* on failure the array keeps its larger block: still >= cap */
            *refs[a].data = q;
    }
    p->cap = cap;
    return 0;
}

/* ---- add / remove / permute -------------------------------------------- */

int mf_particles_add(mf_particles *p, int kind, const double x[3], const double v[3],
                     int64_t *id_out)
{
    if (!p || !x)
        return MF_ERROR(MF_ERR_INPUT, "mf_particles_add: NULL particle store or position");
    if (kind < 0 || kind >= MF_NKINDS)
        return MF_ERROR(MF_ERR_INPUT, "unknown particle kind %d", kind);
    if (p->n != p->n_owned)
        /* An owned particle appended after halo copies would break the
         * [owned | halo] layout: halos must be dropped first. */
        return MF_ERROR(MF_ERR_INPUT,
                        "cannot add a particle while %zu halo particles are present",
                        p->n - p->n_owned);
    if (p->n == p->cap)
        MF_CALL(mf_particles_reserve(p, p->n + 1));

    size_t i = p->n;
    for (int d = 0; d < 3; d++) {
        p->pos[3 * i + d] = x[d];
        p->vel[3 * i + d] = v ? v[d] : 0.0;
    }
    if (p->dim == 2) { /* 2-D vectors keep z = 0 */
        p->pos[3 * i + 2] = 0.0;
        p->vel[3 * i + 2] = 0.0;
    }
    p->kind[i] = (uint8_t)kind;
    p->id[i] = p->next_id;
    p->next_id += p->id_stride;
    /* The slot may hold stale values of a removed particle. */
    for (int f = 0; f < p->nfields; f++) {
        size_t es = field_elem_size(&p->field[f]);
        memset((char *)p->field[f].data + i * es, 0, es);
    }
    if (id_out)
        *id_out = p->id[i];
    p->n++;
    p->n_owned++;
    return 0;
}

/* Compact one array, keeping the elements whose flag is clear, in order.
 * Kept elements come in runs, so move whole runs. */
static void compact_array(char *base, size_t elem_size, size_t n, const uint8_t *flag)
{
    size_t write = 0, i = 0;
    while (i < n) {
        while (i < n && flag[i])
            i++;
        size_t run_start = i;
        while (i < n && !flag[i])
            i++;
        size_t run = i - run_start;
        if (run && write != run_start)
            memmove(base + write * elem_size, base + run_start * elem_size, run * elem_size);
        write += run;
    }
}

int mf_particles_remove(mf_particles *p, const uint8_t *remove_flag, size_t *nremoved)
{
    if (!p || (!remove_flag && p->n > 0))
        return MF_ERROR(MF_ERR_INPUT, "mf_particles_remove: NULL particle store or flags");
    size_t removed = 0, removed_owned = 0;
    for (size_t i = 0; i < p->n; i++) {
        if (remove_flag[i]) {
            removed++;
            if (i < p->n_owned)
                removed_owned++;
        }
    }
    if (removed) {
        array_ref refs[MAX_ARRAYS];
        int narrays = list_arrays(p, refs);
        for (int a = 0; a < narrays; a++)
            compact_array(*refs[a].data, refs[a].elem_size, p->n, remove_flag);
        p->n -= removed;
        p->n_owned -= removed_owned;
    }
    if (nremoved)
        *nremoved = removed;
    return 0;
}

/* scratch[k] = base[perm[k]]. The fixed sizes let the compiler turn memcpy
 * into plain loads and stores for the common element sizes. */
static void gather(char *restrict scratch, const char *restrict base, size_t elem_size,
                   const size_t *perm, size_t n)
{
#define GATHER_FIXED(SIZE)                                                   \
    for (size_t k = 0; k < n; k++)                                           \
        memcpy(scratch + k * (SIZE), base + perm[k] * (SIZE), (SIZE));       \
    break;
    switch (elem_size) {
    case 1: GATHER_FIXED(1)
    case 4: GATHER_FIXED(4)
    case 8: GATHER_FIXED(8)
    case 12: GATHER_FIXED(12)
    case 24: GATHER_FIXED(24)
    default:
        for (size_t k = 0; k < n; k++)
            memcpy(scratch + k * elem_size, base + perm[k] * elem_size, elem_size);
        break;
    }
#undef GATHER_FIXED
}

/* A bad permutation would silently duplicate or lose particles (and ids), so
 * check it: a bijection of [0, n) that keeps owned particles before halos. */
static int check_permutation(const mf_particles *p, const size_t *perm)
{
    uint8_t *seen = calloc(p->n, 1);
    if (!seen)
        return MF_ERROR(MF_ERR_MEMORY, "cannot allocate %zu bytes to check a permutation", p->n);
    int rc = 0;
    for (size_t k = 0; k < p->n; k++) {
        size_t old = perm[k];
        if (old >= p->n || seen[old]) {
            rc = MF_ERROR(MF_ERR_INPUT, "not a permutation: entry %zu is %zu (n = %zu)%s", k, old,
                          p->n, old < p->n ? ", a repeat" : "");
            break;
        }
        if ((k < p->n_owned) != (old < p->n_owned)) {
            rc = MF_ERROR(MF_ERR_INPUT,
                          "permutation mixes owned and halo particles at entry %zu (n_owned = %zu)",
                          k, p->n_owned);
            break;
        }
        seen[old] = 1;
    }
    free(seen);
    return rc;
}

int mf_particles_permute(mf_particles *p, const size_t *perm)
{
    if (!p || (!perm && p->n > 0))
        return MF_ERROR(MF_ERR_INPUT, "mf_particles_permute: NULL particle store or permutation");
    if (p->n == 0)
        return 0;
    MF_CALL(check_permutation(p, perm));

    array_ref refs[MAX_ARRAYS];
    int narrays = list_arrays(p, refs);
    size_t max_elem = 0;
    for (int a = 0; a < narrays; a++)
        if (refs[a].elem_size > max_elem)
            max_elem = refs[a].elem_size;
    /* One scratch buffer serves every array in turn. */
    size_t bytes = checked_bytes(p->n, max_elem);
    char *scratch = bytes ? malloc(bytes) : NULL;
    if (!scratch)
        return MF_ERROR(MF_ERR_MEMORY, "cannot allocate %zu bytes to permute particles", bytes);
    for (int a = 0; a < narrays; a++) {
        gather(scratch, *refs[a].data, refs[a].elem_size, perm, p->n);
        memcpy(*refs[a].data, scratch, p->n * refs[a].elem_size);
    }
    free(scratch);
    return 0;
}

/* ---- optional fields ----------------------------------------------------- */

int mf_particles_field_index(const mf_particles *p, const char *name)
{
    if (!p || !name)
        return -1;
    for (int f = 0; f < p->nfields; f++)
        if (strcmp(p->field[f].name, name) == 0)
            return f;
    return -1;
}

int mf_particles_set_step_scratch(mf_particles *p, int index)
{
    if (!p || index < 0 || index >= p->nfields)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_particles_set_step_scratch: no field %d", index);
    p->field[index].step_scratch = true;
    return 0;
}

int mf_particles_request_field(mf_particles *p, const char *name, int ncomp, int type,
                               bool output, int *index)
{
    if (!p || !name)
        return MF_ERROR(MF_ERR_INPUT, "mf_particles_request_field: NULL particle store or name");
    size_t len = strlen(name);
    if (len == 0 || len >= sizeof p->field[0].name)
        return MF_ERROR(MF_ERR_INPUT, "field name '%s' must have 1 to %zu characters", name,
                        sizeof p->field[0].name - 1);
    if (ncomp < 1 || ncomp > 9)
        return MF_ERROR(MF_ERR_INPUT, "field '%s': %d components (1 to 9 allowed)", name, ncomp);
    if (type != MF_FIELD_DOUBLE && type != MF_FIELD_INT32)
        return MF_ERROR(MF_ERR_INPUT, "field '%s': unknown type %d", name, type);

    int f = mf_particles_field_index(p, name);
    if (f >= 0) {
        mf_field *fd = &p->field[f];
        if (fd->ncomp != ncomp || fd->type != type)
            return MF_ERROR(MF_ERR_INPUT,
                            "field '%s' already exists as %d %s component(s); requested %d %s",
                            name, fd->ncomp, fd->type == MF_FIELD_INT32 ? "int32" : "double",
                            ncomp, type == MF_FIELD_INT32 ? "int32" : "double");
        fd->output = fd->output || output; /* one module wanting it written is enough */
        if (index)
            *index = f;
        return 0;
    }

    if (p->nfields == MF_MAX_FIELDS)
        return MF_ERROR(MF_ERR_INPUT, "cannot add field '%s': all %d field slots are in use", name,
                        MF_MAX_FIELDS);
    mf_field fd = {.ncomp = ncomp, .type = type, .output = output};
    memcpy(fd.name, name, len + 1);
    size_t elem = field_elem_size(&fd);
    size_t count = p->cap ? p->cap : 1;
    if (checked_bytes(count, elem) == 0)
        return MF_ERROR(MF_ERR_MEMORY, "field '%s' is too large", name);
    fd.data = calloc(count, elem);
    if (!fd.data)
        return MF_ERROR(MF_ERR_MEMORY, "cannot allocate field '%s' (%zu particles)", name, count);
    f = p->nfields++;
    p->field[f] = fd;
    if (index)
        *index = f;
    return 0;
}

void mf_particles_set_id_block(mf_particles *p, int64_t first, int rank, int nranks)
{
    p->id_base = first;
    p->next_id = first + rank;
    p->id_stride = nranks > 0 ? nranks : 1;
}

/* ---- packed particles (migration between ranks) ------------------------- */

size_t mf_particles_packed_bytes(const mf_particles *p)
{
    array_ref refs[MAX_ARRAYS];
    int narrays = list_arrays((mf_particles *)p, refs);
    size_t bytes = 0;
    for (int a = 0; a < narrays; a++)
        bytes += refs[a].elem_size;
    return bytes;
}

void mf_particles_pack(const mf_particles *p, const size_t *idx, size_t n, void *buf)
{
    array_ref refs[MAX_ARRAYS];
    int narrays = list_arrays((mf_particles *)p, refs);
    char *out = buf;
    for (size_t k = 0; k < n; k++)
        for (int a = 0; a < narrays; a++) {
            const size_t es = refs[a].elem_size;
            memcpy(out, (const char *)*refs[a].data + idx[k] * es, es);
            out += es;
        }
}

int mf_particles_append_packed(mf_particles *p, const void *buf, size_t n)
{
    if (p->n != p->n_owned)
        return MF_ERROR(MF_ERR_INPUT,
                        "cannot append particles while %zu halo particles are present",
                        p->n - p->n_owned);
    MF_CALL(mf_particles_reserve(p, p->n + n));
    array_ref refs[MAX_ARRAYS];
    int narrays = list_arrays(p, refs);
    const char *in = buf;
    for (size_t k = 0; k < n; k++)
        for (int a = 0; a < narrays; a++) {
            const size_t es = refs[a].elem_size;
            memcpy((char *)*refs[a].data + (p->n + k) * es, in, es);
            in += es;
        }
    p->n += n;
    p->n_owned += n;
    return 0;
}

/* ---- statistics -------------------------------------------------------- */

/* Counts owned particles only: halo particles are copies of another rank's,
 * and counts are summed over ranks. */
void mf_particles_count_kinds(const mf_particles *p, size_t counts[MF_NKINDS])
{
    for (int k = 0; k < MF_NKINDS; k++)
        counts[k] = 0;
    if (!p)
        return;
    for (size_t i = 0; i < p->n_owned; i++)
        if (p->kind[i] < MF_NKINDS)
            counts[p->kind[i]]++;
}

size_t mf_particles_memory(const mf_particles *p)
{
    if (!p)
        return 0;
    size_t bytes = sizeof *p;
    size_t per_particle = 3 * sizeof(double) * 2 + sizeof(uint8_t) + sizeof(int64_t);
    bytes += p->cap * per_particle;
    for (int f = 0; f < p->nfields; f++)
        bytes += (p->cap ? p->cap : 1) * field_elem_size(&p->field[f]);
    return bytes;
}

/* Lattice points other than the origin within radius r (in spacings). */
static long lattice_neighbours(int dim, double r)
{
    long m = (long)r + 1, count = 0;
    for (long i = -m; i <= m; i++)
        for (long j = -m; j <= m; j++)
            for (long k = dim == 3 ? -m : 0; k <= (dim == 3 ? m : 0); k++) {
                double d2 = (double)(i * i + j * j + k * k);
                count += d2 > 0 && d2 < r * r;
            }
    return count;
}

double mf_memory_per_particle(int dim, double radius_l0)
{
    if (!(radius_l0 >= 1) || radius_l0 > 20)
        radius_l0 = radius_l0 > 20 ? 20 : 1;
    const double arrays = 3 * sizeof(double) * 2 + sizeof(uint8_t) + sizeof(int64_t) +
                          12 * sizeof(double);
    const double grid = sizeof(size_t) + 3 * sizeof(double) + 2 * sizeof(uint64_t) +
                        2 * sizeof(uint32_t);
    const double nb = (double)lattice_neighbours(dim == 3 ? 3 : 2, radius_l0);
    const double lists = 2 * (nb * sizeof(uint32_t) + sizeof(size_t));
    const double matrix = 2 * (nb + 1) * (sizeof(double) + sizeof(int32_t));
    /* A snapshot is built in memory before it is written: twice the arrays. */
    const double snapshot = 2 * arrays;
    return 2 * arrays + grid + lists + matrix + snapshot;
}
