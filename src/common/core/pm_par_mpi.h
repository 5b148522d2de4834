/* pm_par_mpi: the communicator of a run's ranks, for the ranks layers
 * (src/fpm/ranks, src/mpm/ranks) and the solvers on PETSc.  The program
 * names it once (pm_par_attach, with its world); no code below the program
 * takes MPI_COMM_WORLD.  Physics never includes this header: it reaches
 * other ranks through its method's exchange interface. */
#ifndef PM_PAR_MPI_H
#define PM_PAR_MPI_H

#include <mpi.h>

#include "pm_error.h"

/* Run on the ranks of comm from now on: every collective of pm_par and of
 * the ranks layers uses it.  Called by the program after pm_par_init; a
 * process that MPI did not start (no launcher) stays one process.
 * PM_ERR_INTERNAL for MPI_COMM_NULL. */
pm_err pm_par_attach(MPI_Comm comm);
/* The communicator attached; MPI_COMM_NULL before, and in a process that
 * MPI did not start. */
MPI_Comm pm_par_comm(void);

#endif
