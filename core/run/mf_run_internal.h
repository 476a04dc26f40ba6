/* mf_run_internal.h: between the time loop (run.c) and its run control
 * (run_control.c). Not installed. */
#ifndef MF_RUN_INTERNAL_H
#define MF_RUN_INTERNAL_H

#include <stdbool.h>

#include "mf_run.h"

/* The first write time (or step) after now. */
double mf_run_first_write(const mf_run *run);
/* After an accepted step (`wrote`: a snapshot was written at it): apply a
 * modified controlDict (run->modified; *next_write is rescheduled when the
 * write interval changed), then signals and stopAt. *stop: end the loop
 * now; *write: write a snapshot first. */
int mf_run_between_steps(mf_run *run, bool wrote, double *next_write, bool *stop, bool *write);
/* After a snapshot: purgeWrite. */
int mf_run_after_write(mf_run *run);

#endif
