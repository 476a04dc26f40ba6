/* body_cases.h: the rigid-body case that test_bodies checks serially and
 * test_mpi on several ranks (one definition, so that both run the same). */
#ifndef TC_BODY_CASES_H
#define TC_BODY_CASES_H

#include <stdbool.h>
#include <stddef.h>

/* The momentum case: a free blob of water 0.2 m square (no gravity) around
 * a neutrally buoyant box body 0.06 m square set moving at u (m/s) along x,
 * in a closed tank 0.4 m square, at spacing l0: its constant/geometry. */
void tc_momentum_geometry(char *out, size_t len, double l0, double u);

/* Its system/solverDict: the scheme whose pair forces are all antisymmetric
 * (gradient corrected, the eq. 7 Laplacian, no collision model, no
 * shifting), so that fluid and body exchange momentum exactly. */
#define TC_MOMENTUM_SOLVER                                                                 \
    "solver MPS;\n"                                                                         \
    "MPSCoeffs { gradient corrected; laplacian paper; collision no; shifting none; }\n"     \
    "pressure { solver PCG_BoomerAMG; tolerance 1e-10; }\n"

/* The 20 numbers of a row of postProcessing/<body>/bodyState.csv (time,
 * x y z, qw qx qy qz, vx vy vz, wx wy wz, Fx Fy Fz, Tx Ty Tz); false: a
 * comment or the header. */
bool tc_body_csv_row(const char *line, double c[20]);

/* Rows of postProcessing/<body>/bodyState.csv: time, centre, velocity,
 * force (3 each). */
typedef struct tc_body_track {
    size_t n;
    double *t, *x, *v, *f; /* n, 3n, 3n, 3n */
    double mass;
} tc_body_track;

int tc_body_track_read(const char *dir, const char *body, tc_body_track *tr);
void tc_body_track_free(tc_body_track *tr);

#endif
