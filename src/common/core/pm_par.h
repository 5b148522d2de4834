/* pm_par: the processes of a run.  One process unless the program was
 * started by an MPI launcher (mpirun), in which case MPI is started once
 * and every rank runs the same program on its share of the work.  A build
 * without MPI (PM_MPI off) and a run of one rank behave as one process:
 * every function here is then the identity, and nothing else changes.
 *
 * The collectives here are called by every rank in the same order; those
 * that agree on an error let a failure found on one rank stop all of them
 * together, with that rank's message, instead of leaving the others
 * waiting. */
#ifndef PM_PAR_H
#define PM_PAR_H

#include <stdbool.h>
#include <stddef.h>

#include "pm_error.h"

/* Start MPI when an MPI launcher started this process (its environment
 * says so: OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_RANK with a size), with
 * threads funnelled to the main one; registers MPI_Finalize at exit.
 * Without a launcher, or in a build without MPI, nothing is started.
 * The run stays one process until the program attaches its communicator
 * (pm_par_attach, pm_par_mpi.h).  Idempotent.  PM_ERR_INTERNAL when MPI
 * cannot start. */
pm_err pm_par_init(int *argc, char ***argv);

/* Before a library starts MPI in a process no launcher started (PETSc, for
 * a static solve of one process): ask Open MPI for a singleton that starts
 * no daemon and probes no network (ess_singleton_isolated, pml ob1), as a
 * process alone needs.  Its start then takes 0.03 s instead of 0.34 on
 * this machine.  Settings already in the environment are kept; under a
 * launcher nothing is changed. */
void pm_par_singleton_quiet(void);

/* This process's rank and the number of ranks (0 and 1 without MPI). */
int pm_par_rank(void);
int pm_par_size(void);
/* More than one rank: the run is shared among them. */
static inline bool pm_par_active(void) { return pm_par_size() > 1; }
/* Rank 0: the one that writes files and prints. */
static inline bool pm_par_root(void) { return pm_par_rank() == 0; }

/* Sums, maxima and minima over the ranks, in place (n values). */
void pm_par_sum(double *v, int n);
void pm_par_sum_long(long *v, int n);
void pm_par_max(double *v, int n);
void pm_par_min(double *v, int n);
void pm_par_max_long(long *v, int n);
/* The sum of n over the ranks before this one (0 on rank 0): where this
 * rank's share starts in a numbering of every rank's in rank order. */
long pm_par_offset(long n);
/* Rank 0's n bytes at p on every rank. */
void pm_par_bcast(void *p, size_t n);

/* Every rank's v into all[rank] on rank 0 (all: pm_par_size() values
 * there; ignored on the other ranks). */
void pm_par_gather_double(double v, double *all);
/* The ranks on this machine (those that share its memory), this one
 * among them; 1 on one process. */
int pm_par_host_ranks(void);

/* Every rank's e: the same answer on all of them.  PM_SUCCESS when every
 * rank has it; else the failure of the lowest rank that failed, whose
 * message every rank then records as its own (so rank 0 reports it). */
pm_err pm_par_agree(pm_err e);
/* The same with an order among the failures: key places this rank's
 * failure in the order one process would meet it (the failing point's
 * index on one process, say); the failure of smallest key wins (the lowest
 * rank's among equal keys), so that every rank reports what one process
 * would have.  key is ignored where e is PM_SUCCESS. */
pm_err pm_par_agree_first(pm_err e, long key);

/* The ranks a plan made on one process is for (pointmech plan --ranks N;
 * 1 unless set). */
void pm_par_set_plan_ranks(int n);
int pm_par_plan_ranks(void);

/* Bytes moved between ranks by this process so far (sent, by the
 * collectives and exchanges that count them): the scaling model's
 * communication volume. */
void pm_par_count_sent(double bytes);
double pm_par_sent(void);

/* Stop every rank at once (a failure that the others cannot agree on, such
 * as one outside any collective): prints msg with the rank and exits. */
void pm_par_abort(int code, const char *msg);

#endif
