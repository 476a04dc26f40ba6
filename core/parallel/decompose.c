/* decompose.c: the partition of the particles over the ranks (Zoltan) and
 * the migration of particles between them.
 *
 * Zoltan (Devine et al. 2002, Sandia; Debian's libtrilinos-zoltan-dev)
 * computes a geometric partition of the particle positions, weighted by
 * kind: recursive coordinate bisection (RCB, Berger & Bokhari 1987: cut
 * planes, so each subdomain is a box and its halo is a thin shell) or the
 * Hilbert space-filling curve (HSFC; the decomposition of Guo et al. 2018).
 * The cuts are kept (KEEP_CUTS), so between two partitions a particle that
 * moved is assigned to the rank whose region holds it
 * (Zoltan_LB_Point_Assign) and sent there. Particles travel whole, packed
 * by mf_particles_pack (every array and optional field), through Zoltan's
 * unstructured communication plans (Zoltan_Comm, the engine of its own
 * migration): one message to each rank that receives any, none to the
 * others.
 */
#include "parallel_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <zoltan.h>
#include <zoltan_comm.h>

#include "mf_error.h"

/* mf_wall_seconds lives in core/run (above this layer). */
static double now(void)
{
    return MPI_Wtime();
}

/* ---- Zoltan's callbacks: the owned particles of par->zp ---------------- */

/* The load of particle i: its kind's weight, more for a pressure wall. */
static double load_of(const mf_parallel *par, const mf_particles *p, const uint8_t *walls,
                      size_t i)
{
    const int k = p->kind[i] < MF_NKINDS ? p->kind[i] : 0;
    return par->s.weight[k] + (walls && walls[i] ? par->s.weight_pressure_wall : 0.0);
}

/* Particle i's row in the pressure equation (the second criterion): fluid,
 * inlet and outlet particles and the walls in the equation. */
static double row_of(const mf_particles *p, const uint8_t *walls, size_t i)
{
    const int k = p->kind[i];
    return k == MF_FLUID || k == MF_INLET || k == MF_OUTLET || (walls && walls[i]) ? 1.0 : 0.0;
}

/* The rows as a second criterion: with RCB only (Zoltan's HSFC balances
 * one weight). */
static bool two_criteria(const mf_parallel *par)
{
    return par->s.multi_criteria && par->s.method == MF_DECOMPOSE_RCB;
}

static int num_obj(void *data, int *ierr)
{
    const mf_parallel *par = data;
    *ierr = ZOLTAN_OK;
    return (int)par->zp->n_owned;
}

static void obj_list(void *data, int ngid, int nlid, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids,
                     int wdim, float *weights, int *ierr)
{
    const mf_parallel *par = data;
    const mf_particles *p = par->zp;
    (void)nlid;
    for (size_t i = 0; i < p->n_owned; i++) {
        /* The 64-bit id in two 32-bit entries (Debian's Zoltan has 32-bit ids). */
        const uint64_t id = (uint64_t)p->id[i];
        gids[(size_t)ngid * i] = (ZOLTAN_ID_TYPE)(id & 0xffffffffu);
        gids[(size_t)ngid * i + 1] = (ZOLTAN_ID_TYPE)(id >> 32);
        lids[i] = (ZOLTAN_ID_TYPE)i;
        if (wdim > 0)
            weights[(size_t)wdim * i] = (float)load_of(par, p, par->zwalls, i);
        if (wdim > 1)
            weights[(size_t)wdim * i + 1] = (float)row_of(p, par->zwalls, i);
    }
    *ierr = ZOLTAN_OK;
}

static int num_geom(void *data, int *ierr)
{
    const mf_parallel *par = data;
    *ierr = ZOLTAN_OK;
    return par->geom_dim;
}

static void geom_multi(void *data, int ngid, int nlid, int nobj, ZOLTAN_ID_PTR gids,
                       ZOLTAN_ID_PTR lids, int dim, double *coords, int *ierr)
{
    const mf_parallel *par = data;
    (void)ngid;
    (void)gids;
    for (int k = 0; k < nobj; k++) {
        const size_t i = lids[(size_t)nlid * k];
        for (int c = 0; c < dim; c++)
            coords[(size_t)dim * k + c] = par->zp->pos[3 * i + c];
    }
    *ierr = ZOLTAN_OK;
}

static int zoltan_setup(mf_parallel *par, int dim)
{
    if (par->zz)
        return 0;
    float version = 0;
    if (Zoltan_Initialize(0, NULL, &version) != ZOLTAN_OK)
        return MF_ERROR(MF_ERR_LIBRARY, "Zoltan_Initialize failed");
    par->zz = Zoltan_Create(par->comm);
    if (!par->zz)
        return MF_ERROR(MF_ERR_LIBRARY, "Zoltan_Create failed");
    par->geom_dim = dim;
    struct Zoltan_Struct *zz = par->zz;
    const char *method = par->s.method == MF_DECOMPOSE_HSFC ? "HSFC" : "RCB";
    Zoltan_Set_Param(zz, "DEBUG_LEVEL", "0");
    Zoltan_Set_Param(zz, "LB_METHOD", method);
    Zoltan_Set_Param(zz, "NUM_GID_ENTRIES", "2");
    Zoltan_Set_Param(zz, "NUM_LID_ENTRIES", "1");
    /* Two criteria: Zoltan's RCB then tries a cut along every axis and keeps
     * the one whose worse criterion is best balanced (the max norm), where
     * one criterion always cuts the longest axis. */
    Zoltan_Set_Param(zz, "OBJ_WEIGHT_DIM", two_criteria(par) ? "2" : "1");
    if (two_criteria(par))
        Zoltan_Set_Param(zz, "RCB_MULTICRITERIA_NORM", "3");
    /* Dots on a cut (a lattice plane) all go to one side, as
     * Zoltan_LB_Point_Assign later puts them: the balance Zoltan computes
     * for each axis is then the one the ranks get. */
    if (par->s.method == MF_DECOMPOSE_RCB)
        Zoltan_Set_Param(zz, "RCB_RECTILINEAR_BLOCKS", "1");
    Zoltan_Set_Param(zz, "RETURN_LISTS", "EXPORT");
    Zoltan_Set_Param(zz, "KEEP_CUTS", "1");      /* for Zoltan_LB_Point_Assign */
    Zoltan_Set_Param(zz, "IMBALANCE_TOL", "1.02");
    if (par->s.method == MF_DECOMPOSE_RCB)
        Zoltan_Set_Param(zz, "RCB_REUSE", "1"); /* start from the last cuts: fewer moves */
    Zoltan_Set_Num_Obj_Fn(zz, num_obj, par);
    Zoltan_Set_Obj_List_Fn(zz, obj_list, par);
    Zoltan_Set_Num_Geom_Fn(zz, num_geom, par);
    Zoltan_Set_Geom_Multi_Fn(zz, geom_multi, par);
    return 0;
}

void mf_decompose_free(mf_parallel *par)
{
    if (par->zz)
        Zoltan_Destroy(&par->zz);
    par->zz = NULL;
}

/* ---- moving particles -------------------------------------------------------- */

/* Send the owned particles idx[k] to rank dest[k] (never this rank) and
 * take in those sent here: every rank calls it, with or without movers. */
static int exchange(mf_parallel *par, mf_particles *p, const size_t *idx, int *dest, size_t n,
                    size_t *moved)
{
    const size_t row = mf_particles_packed_bytes(p);
    if (row > (size_t)INT32_MAX)
        return MF_ERROR(MF_ERR_INTERNAL, "a particle packs into %zu bytes", row);
    int rc = 0, nrecv = 0;
    char *send = malloc(n * row + 1), *recv = NULL;
    uint8_t *gone = calloc(p->n_owned + 1, 1);
    ZOLTAN_COMM_OBJ *plan = NULL;
    /* One agreement: a rank that failed to allocate still takes part in the
     * plan (sending nothing) and reports after it. */
    if (!send || !gone) {
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory packing %zu migrating particles", n);
        n = 0;
    } else {
        mf_particles_pack(p, idx, n, send);
    }
    if (Zoltan_Comm_Create(&plan, (int)n, dest, par->comm, MF_TAG_MIGRATE, &nrecv) != ZOLTAN_OK &&
        rc == 0)
        rc = MF_ERROR(MF_ERR_LIBRARY, "Zoltan_Comm_Create failed (migration of %zu particles)",
                      n);
    if (rc == 0 && !(recv = malloc((size_t)nrecv * row + 1)))
        rc = MF_ERROR(MF_ERR_MEMORY, "out of memory receiving %d migrating particles", nrecv);
    MF_CALL_GOTO(rc, mf_parallel_agree(par, rc), done);
    if (Zoltan_Comm_Do(plan, MF_TAG_MIGRATE + 1, send, (int)row, recv) != ZOLTAN_OK)
        rc = MF_ERROR(MF_ERR_LIBRARY, "Zoltan_Comm_Do failed (migration)");
    MF_CALL_GOTO(rc, rc, done);
    for (size_t k = 0; k < n; k++)
        gone[idx[k]] = 1;
    size_t removed = 0;
    MF_CALL_GOTO(rc, mf_particles_remove(p, gone, &removed), done);
    MF_CALL_GOTO(rc, mf_particles_append_packed(p, recv, (size_t)nrecv), done);
    *moved += n;
done:
    if (plan)
        Zoltan_Comm_Destroy(&plan);
    free(send);
    free(recv);
    free(gone);
    return rc;
}

int mf_parallel_owner_of(const mf_parallel *par, const double x[3])
{
    if (!par || !par->partitioned)
        return 0;
    int proc = 0;
    double c[3] = {x[0], x[1], x[2]};
    if (Zoltan_LB_Point_Assign(par->zz, c, &proc) != ZOLTAN_OK)
        return par->rank;
    return proc;
}

static int migrate(mf_parallel *par, mf_particles *p, bool all_kinds);

void mf_parallel_set_margin(mf_parallel *par, double margin)
{
    if (par)
        par->margin = margin > 0 ? margin : 0;
}

/* x inside this rank's box grown by the margin. */
static bool in_box(const mf_parallel *par, const double *x, int dim)
{
    for (int c = 0; c < dim; c++)
        if (x[c] < par->box[c] - par->margin || x[c] > par->box[3 + c] + par->margin)
            return false;
    return true;
}

/* Zoltan's partition of the owned particles, then the exports sent. */
static int partition(mf_parallel *par, mf_particles *p, const uint8_t *walls)
{
    const double t0 = now();
    MF_CALL(zoltan_setup(par, p->dim));
    par->zp = p;
    par->zwalls = walls;
    int changes = 0, ngid = 0, nlid = 0, nimp = 0, nexp = 0;
    ZOLTAN_ID_PTR imp_gid = NULL, imp_lid = NULL, exp_gid = NULL, exp_lid = NULL;
    int *imp_proc = NULL, *imp_part = NULL, *exp_proc = NULL, *exp_part = NULL;
    int zrc = Zoltan_LB_Partition(par->zz, &changes, &ngid, &nlid, &nimp, &imp_gid, &imp_lid,
                                  &imp_proc, &imp_part, &nexp, &exp_gid, &exp_lid, &exp_proc,
                                  &exp_part);
    int rc = zrc == ZOLTAN_OK || zrc == ZOLTAN_WARN
                 ? 0
                 : MF_ERROR(MF_ERR_LIBRARY, "Zoltan_LB_Partition failed (code %d)", zrc);
    size_t *idx = NULL;
    if (rc == 0 && nexp > 0) {
        idx = malloc((size_t)nexp * sizeof *idx);
        if (!idx)
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory");
        for (int k = 0; rc == 0 && k < nexp; k++)
            idx[k] = exp_lid[(size_t)nlid * k];
    }
    rc = mf_parallel_agree(par, rc);
    if (rc == 0)
        rc = exchange(par, p, idx, exp_proc, (size_t)(nexp > 0 ? nexp : 0),
                      &par->stats.repartitioned);
    free(idx);
    Zoltan_LB_Free_Part(&imp_gid, &imp_lid, &imp_proc, &imp_part);
    Zoltan_LB_Free_Part(&exp_gid, &exp_lid, &exp_proc, &exp_part);
    par->zp = NULL;
    par->zwalls = NULL;
    MF_CALL(rc);
    par->partitioned = true;
    double *b = par->box;
    int ndim = 0;
    par->has_box = par->s.method == MF_DECOMPOSE_RCB &&
                   Zoltan_RCB_Box(par->zz, par->rank, &ndim, &b[0], &b[1], &b[2], &b[3], &b[4],
                                  &b[5]) == ZOLTAN_OK;
    /* Zoltan may split particles that sit exactly on a cut (a lattice row)
     * between both sides; Zoltan_LB_Point_Assign, which later migrations
     * ask, puts them on one. Follow it now, so that ownership is always
     * what Point_Assign says. */
    MF_CALL(migrate(par, p, true));
    par->stats.rebalances++;
    par->stats.t_rebalance += now() - t0;
    return 0;
}

/* Particles whose position is now in another rank's region go there.
 * Walls and dummies never move: only the others are looked at, unless
 * all_kinds is set (after a new partition). */
static int migrate(mf_parallel *par, mf_particles *p, bool all_kinds)
{
    const double t0 = now();
    size_t n = 0, cap = 0;
    size_t *idx = NULL;
    int *dest = NULL;
    int rc = 0;
    for (size_t i = 0; i < p->n_owned && rc == 0; i++) {
        if (!all_kinds && (p->kind[i] == MF_WALL || p->kind[i] == MF_DUMMY))
            continue;
        if (par->has_box && par->margin > 0 && in_box(par, &p->pos[3 * i], p->dim))
            continue;
        const int owner = mf_parallel_owner_of(par, &p->pos[3 * i]);
        if (owner == par->rank)
            continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 256;
            size_t *gi = realloc(idx, cap * sizeof *gi);
            if (gi)
                idx = gi;
            int *gd = gi ? realloc(dest, cap * sizeof *gd) : NULL;
            if (gd)
                dest = gd;
            if (!gi || !gd) {
                rc = MF_ERROR(MF_ERR_MEMORY, "out of memory listing migrating particles");
                break;
            }
        }
        idx[n] = i;
        dest[n++] = owner;
    }
    rc = mf_parallel_agree(par, rc);
    if (rc == 0)
        rc = exchange(par, p, idx, dest, n,
                      all_kinds ? &par->stats.repartitioned : &par->stats.migrated);
    free(idx);
    free(dest);
    MF_CALL(rc);
    par->stats.migrations++;
    par->stats.t_migrate += now() - t0;
    return 0;
}

/* ---- the public calls -------------------------------------------------------- */

double mf_parallel_imbalance(mf_parallel *par, const mf_particles *p, const uint8_t *walls)
{
    if (!par)
        return 1.0;
    double load[2] = {0, 0};
    for (size_t i = 0; i < p->n_owned; i++) {
        load[0] += load_of(par, p, walls, i);
        load[1] += row_of(p, walls, i);
    }
    double total[2] = {load[0], load[1]}, heaviest[2] = {load[0], load[1]};
    mf_parallel_sum(par, total, 2);
    mf_parallel_max(par, heaviest, 2);
    double ratio[2];
    for (int c = 0; c < 2; c++) {
        const double mean = total[c] / par->size;
        ratio[c] = mean > 0 ? heaviest[c] / mean : 1.0;
    }
    par->stats.imbalance_rows = two_criteria(par) ? ratio[1] : 1.0;
    par->stats.imbalance = fmax(ratio[0], par->stats.imbalance_rows);
    return par->stats.imbalance;
}

int mf_parallel_migrate(mf_parallel *par, mf_particles *p)
{
    if (!par || !par->partitioned)
        return 0;
    if (p->n != p->n_owned)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_parallel_migrate: drop the halo first");
    MF_CALL(migrate(par, p, false));
    return 0;
}

int mf_parallel_rebalance(mf_parallel *par, mf_particles *p, bool force, const uint8_t *walls)
{
    if (!par)
        return 0;
    if (p->n != p->n_owned)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_parallel_rebalance: drop the halo first");
    const double imbalance = mf_parallel_imbalance(par, p, walls);
    /* The threshold, or when the last partition could not get below it (a
     * small scene's lattice planes, two criteria), the threshold's margin
     * over what it achieved: otherwise every step would partition anew. */
    const double limit = fmax(par->s.imbalance_threshold,
                              par->s.imbalance_threshold * par->stats.imbalance_after);
    if (par->partitioned && !force && imbalance <= limit)
        return 0;
    par->stats.imbalance_before = imbalance;
    MF_CALL(partition(par, p, walls));
    /* The walls' marks moved with the particles: the caller may measure
     * again with its new marks. */
    par->stats.imbalance_after = mf_parallel_imbalance(par, p, NULL);
    return 0;
}

int mf_parallel_balance(mf_parallel *par, mf_particles *p, bool force)
{
    MF_CALL(mf_parallel_migrate(par, p));
    MF_CALL(mf_parallel_rebalance(par, p, force, NULL));
    return 0;
}

int mf_parallel_distribute(mf_parallel *par, mf_particles *p, int64_t first_new_id)
{
    if (!par)
        return 0;
    if (p->n != p->n_owned)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_parallel_distribute: drop the halo first");
    /* Keep this rank's contiguous share of the common particles. */
    const size_t n = p->n_owned, lo = n * (size_t)par->rank / (size_t)par->size,
                 hi = n * (size_t)(par->rank + 1) / (size_t)par->size;
    uint8_t *drop = malloc(n + 1);
    int rc = drop ? 0 : MF_ERROR(MF_ERR_MEMORY, "out of memory distributing %zu particles", n);
    if (rc == 0) {
        for (size_t i = 0; i < n; i++)
            drop[i] = i < lo || i >= hi;
        rc = mf_particles_remove(p, drop, NULL);
    }
    free(drop);
    MF_CALL(mf_parallel_agree(par, rc));
    mf_particles_set_id_block(p, first_new_id, par->rank, par->size);
    if (par->s.first_partition)
        MF_CALL(mf_parallel_balance(par, p, true));
    else
        mf_parallel_imbalance(par, p, NULL);
    return 0;
}

int mf_parallel_gather(mf_parallel *par, const mf_particles *p, int root, mf_particles **out)
{
    *out = NULL;
    if (!par)
        return MF_ERROR(MF_ERR_INTERNAL, "mf_parallel_gather on a serial run");
    const size_t row = mf_particles_packed_bytes(p);
    const size_t n = p->n_owned;
    size_t *idx = malloc((n + 1) * sizeof *idx);
    char *send = malloc(n * row + 1), *recv = NULL;
    int *counts = NULL, *displs = NULL;
    int rc = idx && send ? 0 : MF_ERROR(MF_ERR_MEMORY, "out of memory gathering particles");
    long long total = 0;
    if (rc == 0 && n * row > (size_t)INT32_MAX)
        rc = MF_ERROR(MF_ERR_INPUT, "%zu particles are too many to gather on one rank", n);
    MF_CALL_GOTO(rc, mf_parallel_agree(par, rc), done);
    for (size_t i = 0; i < n; i++)
        idx[i] = i;
    mf_particles_pack(p, idx, n, send);
    int mine = (int)(n * row);
    if (par->rank == root) {
        counts = malloc((size_t)par->size * sizeof *counts);
        displs = malloc((size_t)par->size * sizeof *displs);
    }
    MPI_Gather(&mine, 1, MPI_INT, counts, 1, MPI_INT, root, par->comm);
    if (par->rank == root) {
        for (int r = 0; r < par->size; r++) {
            displs[r] = (int)total;
            total += counts[r];
        }
        if (total > INT32_MAX)
            rc = MF_ERROR(MF_ERR_INPUT, "%lld bytes of particles are too many to gather", total);
        else if (!(recv = malloc((size_t)total + 1)))
            rc = MF_ERROR(MF_ERR_MEMORY, "out of memory gathering %lld bytes", total);
    }
    MF_CALL_GOTO(rc, mf_parallel_agree(par, rc), done);
    MPI_Gatherv(send, mine, MPI_BYTE, recv, counts, displs, MPI_BYTE, root, par->comm);
    if (par->rank == root) {
        /* A store with the same fields in the same order: the packed rows fit. */
        mf_particles *q = NULL;
        rc = mf_particles_create(p->dim, (size_t)(total / (long long)row) + 1, &q);
        for (int f = 0; rc == 0 && f < p->nfields; f++)
            rc = mf_particles_request_field(q, p->field[f].name, p->field[f].ncomp,
                                            p->field[f].type, p->field[f].output, NULL);
        if (rc == 0)
            rc = mf_particles_append_packed(q, recv, (size_t)(total / (long long)row));
        if (rc == 0) {
            q->next_id = p->next_id;
            *out = q;
        } else {
            mf_particles_destroy(q);
        }
    }
done:
    free(idx);
    free(send);
    free(recv);
    free(counts);
    free(displs);
    return rc;
}
