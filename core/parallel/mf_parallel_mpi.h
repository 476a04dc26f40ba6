/* mf_parallel_mpi.h: the communicator of a -parallel run, for the layers
 * that hand it to an MPI library themselves (parallel HDF5 output, the
 * hypre solve). Everything else uses mf_parallel.h, which keeps MPI out. */
#ifndef MF_PARALLEL_MPI_H
#define MF_PARALLEL_MPI_H

#include <mpi.h>

#include "mf_parallel.h"

/* The run's communicator (a duplicate of MPI_COMM_WORLD); MPI_COMM_SELF
 * for a serial run (par NULL). */
MPI_Comm mf_parallel_comm(const mf_parallel *par);

#endif
