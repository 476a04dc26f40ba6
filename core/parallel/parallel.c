/* parallel.c: the communicator, reductions and agreement of mf_parallel.h. */
#include "parallel_internal.h"
#include "mf_parallel_mpi.h"

#include <stdlib.h>
#include <string.h>

#include "mf_error.h"

void mf_parallel_default_settings(mf_parallel_settings *s)
{
    memset(s, 0, sizeof *s);
    s->method = MF_DECOMPOSE_RCB;
    s->imbalance_threshold = 1.1;
    /* Instructions a step per particle of each kind, relative to a fluid
     * particle (callgrind, the 3-D dam break at l0 = 0.02 m with 2 and 4
     * dummy layers, 1 and 2 wall layers, the column 0.25 and 0.5 m long;
     * docs/topics/parallel.md). */
    s->weight[MF_FLUID] = 1.0;
    s->weight[MF_WALL] = 0.35;
    s->weight[MF_DUMMY] = 0.2;
    s->weight[MF_INLET] = 1.0;
    s->weight[MF_OUTLET] = 1.0;
    s->weight_pressure_wall = 0.33;
    s->multi_criteria = true;
    s->first_partition = true;
}

int mf_parallel_world_size(void)
{
    int init = 0, fin = 0, size = 1;
    MPI_Initialized(&init);
    MPI_Finalized(&fin);
    if (init && !fin)
        MPI_Comm_size(MPI_COMM_WORLD, &size);
    return size;
}

int mf_parallel_world_rank(void)
{
    int init = 0, fin = 0, rank = 0;
    MPI_Initialized(&init);
    MPI_Finalized(&fin);
    if (init && !fin)
        MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    return rank;
}

int mf_parallel_create(const mf_parallel_settings *s, mf_parallel **out)
{
    *out = NULL;
    int init = 0;
    MPI_Initialized(&init);
    if (!init)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_parallel_create: MPI is not initialised");
    if (mf_parallel_world_size() == 1)
        return 0; /* the serial run */
    mf_parallel_settings defaults;
    mf_parallel_default_settings(&defaults);
    if (!s)
        s = &defaults;
    if (!(s->imbalance_threshold >= 1.0))
        return MF_ERROR(MF_ERR_INPUT, "imbalanceThreshold %g must be at least 1",
                        s->imbalance_threshold);
    for (int k = 0; k < MF_NKINDS; k++)
        if (!(s->weight[k] >= 0))
            return MF_ERROR(MF_ERR_INPUT, "the load weight of %s particles is %g (>= 0 wanted)",
                            mf_particle_kind_name(k), s->weight[k]);
    mf_parallel *par = calloc(1, sizeof *par);
    if (!par)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    par->s = *s;
    MPI_Comm_dup(MPI_COMM_WORLD, &par->comm);
    MPI_Comm_rank(par->comm, &par->rank);
    MPI_Comm_size(par->comm, &par->size);
    *out = par;
    return 0;
}

void mf_parallel_destroy(mf_parallel *par)
{
    if (!par)
        return;
    mf_decompose_free(par);
    MPI_Comm_free(&par->comm);
    free(par);
}

int mf_parallel_rank(const mf_parallel *par)
{
    return par ? par->rank : 0;
}

int mf_parallel_size(const mf_parallel *par)
{
    return par ? par->size : 1;
}

mf_parallel_stats *mf_parallel_statistics(mf_parallel *par)
{
    return par ? &par->stats : NULL;
}

/* ---- reductions ------------------------------------------------------------ */

static void reduce(const mf_parallel *par, void *v, int n, MPI_Datatype type, MPI_Op op)
{
    if (par && n > 0)
        MPI_Allreduce(MPI_IN_PLACE, v, n, type, op, par->comm);
}

void mf_parallel_sum(const mf_parallel *par, double *v, int n)
{
    reduce(par, v, n, MPI_DOUBLE, MPI_SUM);
}

void mf_parallel_max(const mf_parallel *par, double *v, int n)
{
    reduce(par, v, n, MPI_DOUBLE, MPI_MAX);
}

void mf_parallel_min(const mf_parallel *par, double *v, int n)
{
    reduce(par, v, n, MPI_DOUBLE, MPI_MIN);
}

void mf_parallel_sum_i64(const mf_parallel *par, int64_t *v, int n)
{
    reduce(par, v, n, MPI_INT64_T, MPI_SUM);
}

void mf_parallel_max_i64(const mf_parallel *par, int64_t *v, int n)
{
    reduce(par, v, n, MPI_INT64_T, MPI_MAX);
}

int64_t mf_parallel_exscan(const mf_parallel *par, int64_t v)
{
    if (!par)
        return 0;
    int64_t before = 0;
    MPI_Exscan(&v, &before, 1, MPI_INT64_T, MPI_SUM, par->comm);
    return par->rank == 0 ? 0 : before; /* MPI leaves rank 0's result undefined */
}

void mf_parallel_maxloc(const mf_parallel *par, double *v, int *rank)
{
    if (!par) {
        if (rank)
            *rank = 0;
        return;
    }
    struct {
        double value;
        int rank;
    } in = {*v, par->rank}, out;
    MPI_Allreduce(&in, &out, 1, MPI_DOUBLE_INT, MPI_MAXLOC, par->comm);
    *v = out.value;
    if (rank)
        *rank = out.rank;
}

void mf_parallel_argmax(const mf_parallel *par, double *value, const mf_particles *p, size_t i,
                        mf_particle_info *out)
{
    memset(out, 0, sizeof *out);
    int who = 0;
    mf_parallel_maxloc(par, value, &who);
    if (mf_parallel_rank(par) == who && i != SIZE_MAX && i < p->n) {
        out->found = true;
        out->kind = p->kind[i];
        out->id = p->id[i];
        memcpy(out->x, &p->pos[3 * i], sizeof out->x);
        memcpy(out->v, &p->vel[3 * i], sizeof out->v);
    }
    mf_parallel_bcast(par, out, sizeof *out, who);
}

void mf_parallel_bcast(const mf_parallel *par, void *buf, size_t bytes, int root)
{
    if (par && bytes > 0)
        MPI_Bcast(buf, (int)bytes, MPI_BYTE, root, par->comm);
}

void mf_parallel_allgather(const mf_parallel *par, const void *mine, size_t bytes, void *all)
{
    if (!par) {
        memmove(all, mine, bytes);
        return;
    }
    MPI_Allgather(mine, (int)bytes, MPI_BYTE, all, (int)bytes, MPI_BYTE, par->comm);
}

int mf_parallel_allgatherv(const mf_parallel *par, const void *mine, size_t bytes, void **all,
                           size_t *total)
{
    const int size = par ? par->size : 1;
    int *counts = malloc(2 * (size_t)size * sizeof *counts);
    if (!counts)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory gathering from the ranks");
    int *displs = counts + size;
    const int mine_count = (int)bytes;
    if (par)
        MPI_Allgather(&mine_count, 1, MPI_INT, counts, 1, MPI_INT, par->comm);
    else
        counts[0] = mine_count;
    size_t sum = 0;
    for (int r = 0; r < size; r++) {
        displs[r] = (int)sum;
        sum += (size_t)counts[r];
    }
    *all = malloc(sum ? sum : 1);
    if (!*all) {
        free(counts);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory gathering %zu bytes from the ranks", sum);
    }
    if (par)
        MPI_Allgatherv(mine, mine_count, MPI_BYTE, *all, counts, displs, MPI_BYTE, par->comm);
    else if (bytes)
        memcpy(*all, mine, bytes);
    *total = sum;
    free(counts);
    return 0;
}

/* Severity of a status, for choosing whose failure every rank reports:
 * a fatal error above a retry above success. */
static int severity(int rc)
{
    return rc < 0 ? 2 : rc > 0 ? 1 : 0;
}

int mf_parallel_agree(const mf_parallel *par, int rc)
{
    if (!par)
        return rc;
    struct {
        int severity;
        int rank;
    } in = {severity(rc), par->rank}, out;
    /* MAXLOC picks the lowest rank among those with the worst severity. */
    in.rank = par->size - 1 - par->rank;
    MPI_Allreduce(&in, &out, 1, MPI_2INT, MPI_MAXLOC, par->comm);
    if (out.severity == 0)
        return 0;
    const int who = par->size - 1 - out.rank;
    /* That rank's status and message, so that every rank reports one
     * failure, takes the same retry decision and names where it happened. */
    struct {
        int rc;
        char message[1024];
    } msg;
    memset(&msg, 0, sizeof msg);
    if (par->rank == who) {
        msg.rc = rc;
        snprintf(msg.message, sizeof msg.message, "%s", mf_error_message());
    }
    MPI_Bcast(&msg, (int)sizeof msg, MPI_BYTE, who, par->comm);
    if (rc == msg.rc)
        return rc; /* this rank failed the same way: its own message stands */
    return mf_error_raise(msg.rc, __FILE__, __LINE__, __func__, "%s (on MPI rank %d)",
                          msg.message, who);
}

void mf_parallel_abort(const mf_parallel *par, int rc)
{
    if (!par)
        return;
    fprintf(stderr, "mpsflow: MPI rank %d stops every rank:\n", par->rank);
    mf_error_print(stderr);
    MPI_Abort(par->comm, rc < 0 ? -rc : 1);
}

MPI_Comm mf_parallel_comm(const mf_parallel *par)
{
    return par ? par->comm : MPI_COMM_SELF;
}
