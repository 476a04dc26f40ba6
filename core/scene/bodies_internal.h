/* bodies_internal.h: the state of a rigid body (mf_bodies.h), shared by
 * rigid_bodies.c (its dynamics) and body_contact.c (its contacts). */
#ifndef MF_BODIES_INTERNAL_H
#define MF_BODIES_INTERNAL_H

#include <stdbool.h>
#include <stdio.h>

#include "mf_bodies.h"

typedef struct mf_body {
    double mass;
    double Ib[9], Ib_inv[9];  /* inertia about the centre of mass, body axes */
    /* committed state at t^n */
    double x[3], v[3], R[9], L[3], w[3];
    /* the impulses of the step that ended at t^n: J = F dt, H = T dt */
    double J[3], H[3];
    /* the step being tried (mf_bodies_set_trial) */
    double xt[3], vt[3], Rt[9], Lt[3], wt[3];
    /* the surface its wall particles stand for (mf_body_surface_prepare):
     * per box face (xmin xmax ymin ymax zmin zmax) or 3-D cylinder face
     * (side, cap at -h, cap at +h), or of a round shape (disk, sphere) or a
     * 3-D mesh, the area of the surface per wall particle within l0 of it */
    bool surface_ready;
    double face_area[6], round_area;
    FILE *csv;
} mf_body;

/* The trial state from b->vt and b->Lt (committed x, R): w, x, R at t^{n+1}
 * and the wall's rigid state. */
void mf_body_finish_trial(mf_wall *w, int dim, double dt);

/* The contacts of the bodies at their trial states (body_contact.c). */
int mf_bodies_contact(mf_walls *ws, const mf_particles *p, double dt);

#endif
