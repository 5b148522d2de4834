/* pm_par: MPI started only under a launcher; collectives that reduce to the
 * identity on one process. */
#include "pm_par.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_par_mpi.h"

static int par_rank = 0, par_size = 1, par_host_ranks = 1;
#ifdef PM_HAVE_MPI
static MPI_Comm par_comm = MPI_COMM_NULL; /* NULL until pm_par_attach */
#endif
static double par_sent = 0; /* bytes */

/* An MPI launcher's mark in the environment. */
static bool launched(void) {
  return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMI_SIZE") ||
         (getenv("PMIX_RANK") && getenv("PMIX_NAMESPACE"));
}

#ifdef PM_HAVE_MPI
static void par_finalize(void) {
  int done = 0;
  MPI_Finalized(&done);
  if (!done) MPI_Finalize();
}
#endif

pm_err pm_par_init(int *argc, char ***argv) {
#ifdef PM_HAVE_MPI
  int ready = 0;
  MPI_Initialized(&ready);
  if (!ready) {
    if (!launched()) return PM_SUCCESS;
    int provided = 0;
    PM_CHECK(MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) ==
                 MPI_SUCCESS,
             PM_ERR_INTERNAL, "MPI_Init_thread failed");
    atexit(par_finalize);
  }
  return PM_SUCCESS;
#else
  (void)argc;
  (void)argv;
  /* Several copies of the whole run would write the same files. */
  const char *n = getenv("OMPI_COMM_WORLD_SIZE");
  if (!n) n = getenv("PMI_SIZE");
  PM_CHECK(!launched() || !n || atoi(n) <= 1, PM_ERR_UNSUPPORTED,
           "this pointmech was built without MPI (PM_MPI=OFF): mpirun "
           "started %s copies of one process; run it without mpirun, or "
           "build with -DPM_MPI=ON",
           n);
  return PM_SUCCESS;
#endif
}

void pm_par_singleton_quiet(void) {
  if (launched()) return;
  /* (overwrite 0: the user's own settings stand) */
  setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
  setenv("OMPI_MCA_pml", "ob1", 0);
}

pm_err pm_par_attach(MPI_Comm comm) {
#ifndef PM_HAVE_MPI
  (void)comm; /* a build without MPI is one process */
  return PM_SUCCESS;
#else
  int ready = 0;
  MPI_Initialized(&ready);
  if (!ready) return PM_SUCCESS; /* no launcher: one process */
  PM_CHECK(comm != MPI_COMM_NULL, PM_ERR_INTERNAL,
           "pm_par_attach: the communicator is MPI_COMM_NULL");
  par_comm = comm;
  MPI_Comm_rank(comm, &par_rank);
  MPI_Comm_size(comm, &par_size);
  /* The ranks that share this one's machine (its memory). */
  MPI_Comm host;
  MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &host);
  MPI_Comm_size(host, &par_host_ranks);
  MPI_Comm_free(&host);
  return PM_SUCCESS;
#endif
}

MPI_Comm pm_par_comm(void) {
#ifdef PM_HAVE_MPI
  return par_comm;
#else
  return MPI_COMM_NULL;
#endif
}

int pm_par_rank(void) { return par_rank; }
int pm_par_size(void) { return par_size; }

#ifdef PM_HAVE_MPI
static void reduce(void *v, int n, MPI_Datatype type, MPI_Op op) {
  if (par_size == 1 || n <= 0) return;
  MPI_Allreduce(MPI_IN_PLACE, v, n, type, op, par_comm);
  par_sent += (double)n * (type == MPI_LONG ? sizeof(long) : sizeof(double));
}
#endif

void pm_par_sum(double *v, int n) {
#ifdef PM_HAVE_MPI
  reduce(v, n, MPI_DOUBLE, MPI_SUM);
#else
  (void)v, (void)n;
#endif
}

void pm_par_sum_long(long *v, int n) {
#ifdef PM_HAVE_MPI
  reduce(v, n, MPI_LONG, MPI_SUM);
#else
  (void)v, (void)n;
#endif
}

void pm_par_max(double *v, int n) {
#ifdef PM_HAVE_MPI
  reduce(v, n, MPI_DOUBLE, MPI_MAX);
#else
  (void)v, (void)n;
#endif
}

void pm_par_min(double *v, int n) {
#ifdef PM_HAVE_MPI
  reduce(v, n, MPI_DOUBLE, MPI_MIN);
#else
  (void)v, (void)n;
#endif
}

void pm_par_max_long(long *v, int n) {
#ifdef PM_HAVE_MPI
  reduce(v, n, MPI_LONG, MPI_MAX);
#else
  (void)v, (void)n;
#endif
}

long pm_par_offset(long n) {
#ifdef PM_HAVE_MPI
  if (par_size == 1) return 0;
  long before = 0;
  MPI_Exscan(&n, &before, 1, MPI_LONG, MPI_SUM, par_comm);
  par_sent += sizeof(long);
  return par_rank == 0 ? 0 : before;
#else
  (void)n;
  return 0;
#endif
}

void pm_par_bcast(void *p, size_t n) {
#ifdef PM_HAVE_MPI
  if (par_size == 1 || n == 0) return;
  MPI_Bcast(p, (int)n, MPI_BYTE, 0, par_comm);
  if (par_rank == 0) par_sent += (double)n;
#else
  (void)p, (void)n;
#endif
}

void pm_par_gather_double(double v, double *all) {
#ifdef PM_HAVE_MPI
  if (par_size > 1) {
    MPI_Gather(&v, 1, MPI_DOUBLE, all, 1, MPI_DOUBLE, 0, par_comm);
    par_sent += sizeof(double);
    return;
  }
#endif
  all[0] = v;
}

int pm_par_host_ranks(void) { return par_host_ranks; }

pm_err pm_par_agree(pm_err e) { return pm_par_agree_first(e, 0); }

pm_err pm_par_agree_first(pm_err e, long key) {
#ifdef PM_HAVE_MPI
  if (par_size == 1) return e;
  struct {
    long key;
    int rank;
  } first = {e != PM_SUCCESS ? key : LONG_MAX, par_rank};
  if (e != PM_SUCCESS && key == LONG_MAX) /* the successes' mark */
    first.key = LONG_MAX - 1;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_LONG_INT, MPI_MINLOC, par_comm);
  if (first.key == LONG_MAX) return PM_SUCCESS;
  struct {
    int code;
    char text[1024];
  } what = {0};
  if (par_rank == first.rank) {
    what.code = (int)e;
    snprintf(what.text, sizeof what.text, "%s", pm_error_message());
  }
  MPI_Bcast(&what, (int)sizeof what, MPI_BYTE, first.rank, par_comm);
  if (par_rank == first.rank) return e;
  return pm_error_set((pm_err)what.code, __FILE__, __LINE__, __func__, "%s",
                      what.text);
#else
  (void)key;
  return e;
#endif
}

static int plan_ranks = 1;
void pm_par_set_plan_ranks(int n) { plan_ranks = n > 1 ? n : 1; }
int pm_par_plan_ranks(void) { return plan_ranks; }

void pm_par_count_sent(double bytes) { par_sent += bytes; }
double pm_par_sent(void) { return par_sent; }

void pm_par_abort(int code, const char *msg) {
  fprintf(stderr, "pointmech: rank %d of %d: %s\n", par_rank, par_size,
          msg ? msg : "");
  fflush(stderr);
#ifdef PM_HAVE_MPI
  if (par_size > 1) MPI_Abort(par_comm, code);
#endif
  exit(code);
}
