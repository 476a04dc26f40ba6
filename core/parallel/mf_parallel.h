/* mf_parallel.h: the distributed particle set (one case on N MPI ranks).
 *
 * `mpirun -np N mpsflow -parallel -case DIR`: each rank owns the particles
 * of one subdomain, [0, n_owned) of its mf_particles, and holds copies of
 * the particles within the largest operator radius of its subdomain after
 * them, [n_owned, n) (mf_halo.h); the neighbour loops read them without
 * knowing. This header is the small interface behind which every MPI and
 * Zoltan call sits:
 *   - reductions (sums, maxima, an agreed status) for the time loop, the
 *     watch, the reports;
 *   - the decomposition: Zoltan's recursive coordinate bisection (RCB) or
 *     Hilbert space-filling curve (HSFC) partition of the particles,
 *     weighted by kind; migration of the particles that crossed into
 *     another rank's region, every array and optional field with them; a
 *     new partition when the load imbalance passes a threshold.
 *
 * A serial run has no mf_parallel (NULL): every function here then does
 * nothing and returns at once (no MPI call, no Zoltan call), so one code
 * path serves both and the serial run pays one pointer test.
 *
 * Collective calls (everything below that takes a non-NULL mf_parallel,
 * except the queries) must be made by every rank in the same order.
 * Errors that one rank finds alone are agreed on (mf_parallel_agree) at the
 * phase boundaries of a step, so that no rank waits in a collective call
 * that another has left.
 */
#ifndef MF_PARALLEL_H
#define MF_PARALLEL_H
#pragma GCC visibility push(default) /* the plugin API (an installed header) */

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mf_particles.h"

typedef struct mf_parallel mf_parallel;

typedef enum { MF_DECOMPOSE_RCB = 0, MF_DECOMPOSE_HSFC = 1 } mf_decompose_method;

typedef struct mf_parallel_settings {
    mf_decompose_method method;
    /* A new partition when the heaviest rank's load exceeds this multiple of
     * the mean (1.1: 10% above). */
    double imbalance_threshold;
    /* Load of one particle of each kind, relative to a fluid particle (the
     * walls and dummies of a scene do less work a step than its fluid). */
    double weight[MF_NKINDS];
    /* Added for a wall particle that is an unknown of the pressure equation
     * (walls beside the fluid; the others only count in neighbour lists). */
    double weight_pressure_wall;
    /* Balance two criteria (Zoltan's multi-criteria RCB): the load above and
     * the pressure equation's rows (fluid, inlet and outlet particles and
     * the walls in the equation). The step is a sequence of phases each
     * ended by a collective call, so its time is the sum over phases of the
     * slowest rank: one total load balanced can leave every row of the
     * solve on one rank. */
    bool multi_criteria;
    /* false: mf_parallel_distribute leaves each rank its contiguous share of
     * the particles in the order they were built, and the first step makes
     * the first partition (a deliberately unbalanced start, for tests). */
    bool first_partition;
} mf_parallel_settings;

void mf_parallel_default_settings(mf_parallel_settings *s);

/* What the decomposition and the halos did, for the log and the benchmarks
 * (this rank's share; sums and maxima over ranks are the caller's). */
typedef struct mf_parallel_stats {
    long migrations, rebalances;
    size_t migrated;        /* particles this rank sent away by migration (between partitions) */
    size_t repartitioned;   /* particles this rank sent away with new partitions */
    double imbalance;       /* heaviest load / mean load at the last check (the larger
                               of the two criteria's when multi_criteria) */
    double imbalance_rows;  /* of the pressure rows alone (1 without multi_criteria) */
    double imbalance_before; /* the same before the last new partition */
    double imbalance_after; /* right after it: what the partition could achieve (a
                               caller that weighs by the pressure walls sets it
                               with theirs) */
    double t_migrate, t_rebalance, t_halo; /* wall seconds */
    double t_halo_wait;     /* of t_halo: in the first collective call of a build,
                               where a rank waits for the slowest (load imbalance) */
    long halo_builds, halo_updates;
    size_t halo_particles;  /* copies received, summed over builds */
    size_t halo_sent_bytes; /* bytes sent by halo builds and updates */
    size_t owned_at_builds; /* owned particles, summed over builds */
    /* The linear solves through the pressure modules (the PPE and the
     * implicit viscosity's systems; core/host's mf_pressure_solve_rows
     * counts them): solves, the preconditioner set-ups they made
     * (mf_solve_report.setups: 0 when a kept hierarchy served), and their
     * set-up (assembly included) and iteration wall seconds. */
    long solves, solve_setups;
    double t_solve_setup, t_solve_iterate;
} mf_parallel_stats;

/* MPI must be initialised. On one rank *out is NULL (the serial run). */
int mf_parallel_create(const mf_parallel_settings *s, mf_parallel **out);
void mf_parallel_destroy(mf_parallel *par);

/* Rank and size of MPI_COMM_WORLD as the MPI library sees it (1 and 0
 * without MPI initialised): the driver's check that a run under mpirun was
 * asked for with -parallel. */
int mf_parallel_world_size(void);
int mf_parallel_world_rank(void);

int mf_parallel_rank(const mf_parallel *par); /* 0 when par is NULL */
int mf_parallel_size(const mf_parallel *par); /* 1 when par is NULL */
static inline bool mf_parallel_is_root(const mf_parallel *par)
{
    return mf_parallel_rank(par) == 0;
}
mf_parallel_stats *mf_parallel_statistics(mf_parallel *par); /* NULL when par is NULL */

/* ---- reductions (in place; nothing happens when par is NULL) ------------ */
void mf_parallel_sum(const mf_parallel *par, double *v, int n);
void mf_parallel_max(const mf_parallel *par, double *v, int n);
void mf_parallel_min(const mf_parallel *par, double *v, int n);
void mf_parallel_sum_i64(const mf_parallel *par, int64_t *v, int n);
void mf_parallel_max_i64(const mf_parallel *par, int64_t *v, int n);
/* Sum of v over the ranks before this one (0 on rank 0): the first global
 * row of this rank's rows. */
int64_t mf_parallel_exscan(const mf_parallel *par, int64_t v);
/* The largest value over the ranks and the rank that holds it (the lowest
 * such rank on a tie). */
void mf_parallel_maxloc(const mf_parallel *par, double *v, int *rank);
/* A particle as every rank learns of it (the fastest, the thinnest, ...). */
typedef struct mf_particle_info {
    bool found;
    int kind;
    int64_t id;
    double x[3], v[3];
} mf_particle_info;
/* Particle i of this rank (SIZE_MAX: none) with *value; on return *value is
 * the largest over the ranks and *out describes that rank's particle, on
 * every rank (serial: particle i itself). */
void mf_parallel_argmax(const mf_parallel *par, double *value, const mf_particles *p, size_t i,
                        mf_particle_info *out);
/* Copy bytes from rank `root` to every rank. */
void mf_parallel_bcast(const mf_parallel *par, void *buf, size_t bytes, int root);
/* bytes from each rank, concatenated in rank order into all (size * bytes). */
void mf_parallel_allgather(const mf_parallel *par, const void *mine, size_t bytes, void *all);
/* bytes (this rank's, any number) from each rank, concatenated in rank
 * order into a new buffer *all (free it) of *total bytes; one rank: a copy.
 * Collective. */
int mf_parallel_allgatherv(const mf_parallel *par, const void *mine, size_t bytes, void **all,
                           size_t *total);
/* Collective: 0 when rc is 0 on every rank; otherwise this rank's rc (its
 * message already recorded) or, on a rank that did not fail itself, the
 * most severe status of the others with a message naming the rank that
 * failed and its message (sent by it). Keeps every rank on the same path. */
int mf_parallel_agree(const mf_parallel *par, int rc);
/* Stop every rank (MPI_Abort) after printing the current error: for a
 * failure on one rank that the others cannot be told of. */
void mf_parallel_abort(const mf_parallel *par, int rc);

/* ---- decomposition (mf_decompose.c) --------------------------------------- */

/* Every rank holds the same particles (the scene built on each, or a
 * snapshot read by each): rank r keeps its share of them and the first
 * partition moves each particle to its subdomain. Ids from here on come
 * from the rank's block after first_new_id. */
int mf_parallel_distribute(mf_parallel *par, mf_particles *p, int64_t first_new_id);
/* Before a step (no halo may be present): particles that left this rank's
 * region go to the rank whose region holds them (mf_parallel_migrate);
 * then a new partition when the imbalance passes the threshold, or always
 * when force is set (mf_parallel_rebalance). pressure_walls (may be NULL)
 * marks the owned walls that are unknowns of the pressure equation (their
 * load is larger), for the particles as they are after the migration.
 * mf_parallel_balance is the two with pressure_walls NULL. */
int mf_parallel_migrate(mf_parallel *par, mf_particles *p);
int mf_parallel_rebalance(mf_parallel *par, mf_particles *p, bool force,
                          const uint8_t *pressure_walls);
int mf_parallel_balance(mf_parallel *par, mf_particles *p, bool force);
/* The imbalance of the weighted load (heaviest rank over the mean; 1 when
 * par is NULL). Collective. */
double mf_parallel_imbalance(mf_parallel *par, const mf_particles *p,
                             const uint8_t *pressure_walls);
/* Hysteresis of migration (RCB): a particle within this distance outside
 * its rank's box stays there, so that a lattice row lying on a cut does not
 * cross it back and forth with every rounding of its positions (0: none,
 * the default). The halos do not depend on it. */
void mf_parallel_set_margin(mf_parallel *par, double margin);
/* The rank whose region holds x under the current partition (0 when par is
 * NULL or before the first partition). */
int mf_parallel_owner_of(const mf_parallel *par, const double x[3]);

/* Every rank's owned particles (every array and field), gathered on rank
 * `root` into a new store *out (in rank order); NULL on the other ranks.
 * For the post-processing that needs the whole fluid at once (the surface
 * function object). Collective. */
int mf_parallel_gather(mf_parallel *par, const mf_particles *p, int root, mf_particles **out);

#pragma GCC visibility pop
#endif
