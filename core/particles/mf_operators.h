/* mf_operators.h: the MPS differential operators (section 3.1).
 *
 * Each operator loops over owned particles i (those with imask[i] != 0, or
 * all when imask is NULL) and their neighbours j in a list (those with
 * jmask[j] != 0, or all when jmask is NULL). The pair terms are the small
 * inline functions of mf_kernel.h. Loops run in parallel (OpenMP).
 * Particles outside imask are left untouched in the output. */
#ifndef MF_OPERATORS_H
#define MF_OPERATORS_H

#include <stdbool.h>
#include <stdint.h>

#include "mf_kernel.h"
#include "mf_neighbours.h"
#include "mf_particles.h"

/* n_i = sum_j w(|r_ij|) with the list's own radius as re. */
void mf_number_density(const mf_particles *p, const mf_nlist *nl, const uint8_t *imask,
                       const uint8_t *jmask, double *n);

/* eq. 5: <grad f>_i = d/n0 sum_j (f_j - f_i') r_ij/|r_ij|^2 w(|r_ij|), where
 * f_i' = f_i, or with use_min the minimum of f over i and its (jmask)
 * neighbours (Koshizuka et al. 1998: keeps the pressure force repulsive).
 * out has 3 entries per particle. */
void mf_gradient(const mf_particles *p, const mf_nlist *nl, const mf_kernel *k, const double *f,
                 bool use_min, const uint8_t *imask, const uint8_t *jmask, double *out);

/* eq. 7: <lap f>_i = 2d/(lambda n0) sum_j (f_j - f_i) w(|r_ij|) for a field
 * of ncomp interleaved components (1 or 3). */
void mf_laplacian(const mf_particles *p, const mf_nlist *nl, const mf_kernel *k, const double *f,
                  int ncomp, const uint8_t *imask, const uint8_t *jmask, double *out);

/* eq. 6: <div u>_i = d/n0 sum_j (u_j - u_i).r_ij/|r_ij|^2 w(|r_ij|). */
void mf_divergence(const mf_particles *p, const mf_nlist *nl, const mf_kernel *k, const double *u,
                   const uint8_t *imask, const uint8_t *jmask, double *out);

/* eq. 18: flag[i] = 1 where n[i] < beta n0 (free surface), else 0. */
void mf_free_surface(const double *n, size_t count, double beta, double n0, uint8_t *flag);

#endif
