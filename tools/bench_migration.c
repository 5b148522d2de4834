/* What a step's particle migration costs across ranks, two ways, on the
 * same particles: n a rank, each with the arrays of an MPM solid particle
 * (one-process index; X0, mass, V0, x, v, volume, sigma: 21 doubles; F: 9
 * more, a kind's array), of which `moving` a step leave for the next rank
 * (rank + 1, cyclically: on 2 ranks each rank's neighbour), so the ranks
 * keep their counts:
 *   swarm   PETSc's DMSwarm (DMSWARM_BASIC), each array a registered field,
 *           the leaving particles' DMSwarmField_rank set and DMSwarmMigrate
 *           with the sent removed (a removed particle's place is taken by
 *           the last, arrivals are appended: the order changes);
 *   records what src/mpm/mpm_par does: the counts exchanged with the
 *           neighbours (MPI_Neighbor_alltoall on a graph communicator),
 *           the leaving particles packed a record each, the records
 *           exchanged (MPI_Neighbor_alltoallv), those that arrive sorted
 *           by one-process index and merged with those that stay, every
 *           array permuted into that order (one process's order kept).
 * Both find which particles leave by the same scan (a flag per particle,
 * standing for the cell lookup).  Prints per way and moving count the
 * median and the fastest seconds of a step over STEPS steps, and checks
 * that each way keeps every particle's values.  Usage (under mpirun):
 *   bench-migration N STEPS MOVING...
 * Links PETSc and MPI only. */
#include <mpi.h>
#include <petscdmswarm.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { NA = 8, REC = 1 + 21 + 9 };
static const int ncomp[NA] = {3, 1, 1, 3, 3, 1, 9, 9}; /* 30 doubles */
static const char *fname[NA] = {"X0", "mass", "V0",    "x",
                                "v",  "vol",  "sigma", "F"};

static int rank, size;

static void die(const char *what) {
  fprintf(stderr, "bench-migration: rank %d: %s\n", rank, what);
  MPI_Abort(MPI_COMM_WORLD, 1);
}
#define CHK(call)                                                              \
  do {                                                                         \
    if ((call) != 0) die(#call);                                               \
  } while (0)

/* A particle's value c of array a: a function of its index alone. */
static double value(long gid, int a, int c) {
  return (double)gid * 1e-3 + a + 0.01 * c;
}

/* Does particle k of n leave in step s?  `moving` of them, spread out. */
static int leaves(long k, long n, long moving, int s) {
  if (moving <= 0) return 0;
  const long stride = n / moving;
  return (k + s) % stride == 0 && (k + s) / stride < moving;
}

static int by_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *t, int n) {
  qsort(t, (size_t)n, sizeof *t, by_double);
  return t[n / 2];
}

/* The values a particle holds are its index's: 0 when every one does. */
static long wrong(long n, const long *gid, double *const *arr) {
  long bad = 0;
  for (long k = 0; k < n; k++)
    for (int a = 0; a < NA; a++)
      for (int c = 0; c < ncomp[a]; c++)
        bad += arr[a][k * ncomp[a] + c] != value(gid[k], a, c);
  return bad;
}

/* ---- records: mpm_par's protocol ---------------------------------------- */

typedef struct {
  MPI_Comm near;
  long n, room;
  long *gid;
  double *arr[NA];
  long *order;
  double *sbuf, *rbuf, *tmp;
  int *dest;
} records;

static void records_step(records *R, long moving, int s) {
  int scount[2] = {0, 0}, rcount[2], sdisp[3], rdisp[3];
  /* 2 ranks: one neighbour; more: the ranks before and after */
  const int nn = size == 2 ? 1 : 2;
  const int slot = size == 2 ? 0 : 1; /* the rank after, in the graph */
  long leaving = 0;
  for (long k = 0; k < R->n; k++) {
    R->dest[k] = leaves(k, R->n, moving, s) ? slot : -1;
    leaving += R->dest[k] >= 0;
  }
  scount[slot] = (int)leaving;
  MPI_Neighbor_alltoall(scount, 1, MPI_INT, rcount, 1, MPI_INT, R->near);
  long arriving = 0;
  for (int k = 0; k < nn; k++) arriving += rcount[k];
  sdisp[0] = rdisp[0] = 0;
  for (int k = 0; k < nn; k++) {
    sdisp[k + 1] = sdisp[k] + scount[k] * REC;
    rdisp[k + 1] = rdisp[k] + rcount[k] * REC;
    scount[k] *= REC;
    rcount[k] *= REC;
  }
  long j = 0;
  for (long k = 0; k < R->n; k++) {
    if (R->dest[k] < 0) continue;
    double *q = R->sbuf + j++ * REC;
    q[0] = (double)R->gid[k];
    int off = 1;
    for (int a = 0; a < NA; a++) {
      memcpy(q + off, R->arr[a] + k * ncomp[a], ncomp[a] * sizeof(double));
      off += ncomp[a];
    }
  }
  MPI_Neighbor_alltoallv(R->sbuf, scount, sdisp, MPI_DOUBLE, R->rbuf, rcount,
                         rdisp, MPI_DOUBLE, R->near);
  if (leaving == 0 && arriving == 0) return;
  qsort(R->rbuf, (size_t)arriving, REC * sizeof(double), by_double);
  const long n_new = R->n - leaving + arriving;
  if (n_new > R->room) die("records: room");
  /* the new order: those that stay and those that came, by index */
  long p = 0, k = 0;
  j = 0;
  while (p < R->n || k < arriving) {
    if (p < R->n && R->dest[p] >= 0) {
      p++;
      continue;
    }
    const int old =
        k >= arriving || (p < R->n && (double)R->gid[p] < R->rbuf[k * REC]);
    R->order[j++] = old ? p++ : -(k++ + 1);
  }
  for (j = 0; j < n_new; j++) {
    const long o = R->order[j];
    R->tmp[j] = o >= 0 ? (double)R->gid[o] : R->rbuf[(-o - 1) * REC];
  }
  for (j = 0; j < n_new; j++) R->gid[j] = (long)R->tmp[j];
  int off = 1;
  for (int a = 0; a < NA; a++) {
    const int nc = ncomp[a];
    for (j = 0; j < n_new; j++) {
      const long o = R->order[j];
      const double *src =
          o >= 0 ? R->arr[a] + o * nc : R->rbuf + (-o - 1) * REC + off;
      for (int c = 0; c < nc; c++) R->tmp[j * nc + c] = src[c];
    }
    memcpy(R->arr[a], R->tmp, sizeof(double) * (size_t)(n_new * nc));
    off += nc;
  }
  R->n = n_new;
}

static void run_records(long n, int steps, long moving, double *t) {
  records R = {.n = n, .room = 2 * n};
  int nb[2], weight[2] = {1, 1}; /* weights as mpm_par gives them */
  const int nn = size == 2 ? 1 : 2;
  nb[0] = (rank + size - 1) % size;
  nb[1] = (rank + 1) % size;
  CHK(MPI_Dist_graph_create_adjacent(MPI_COMM_WORLD, nn, nb, weight, nn, nb,
                                     weight, MPI_INFO_NULL, 0, &R.near));
  R.gid = malloc(sizeof(long) * R.room);
  R.order = malloc(sizeof(long) * R.room);
  R.dest = malloc(sizeof(int) * R.room);
  R.sbuf = malloc(sizeof(double) * REC * (moving + 1));
  R.rbuf = malloc(sizeof(double) * REC * (2 * moving + 1));
  R.tmp = malloc(sizeof(double) * 9 * R.room);
  for (int a = 0; a < NA; a++)
    R.arr[a] = malloc(sizeof(double) * ncomp[a] * R.room);
  for (long k = 0; k < n; k++) {
    R.gid[k] = rank * n + k;
    for (int a = 0; a < NA; a++)
      for (int c = 0; c < ncomp[a]; c++)
        R.arr[a][k * ncomp[a] + c] = value(R.gid[k], a, c);
  }
  for (int s = 0; s < steps; s++) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime();
    records_step(&R, moving, s);
    t[s] = MPI_Wtime() - t0;
  }
  if (wrong(R.n, R.gid, R.arr)) die("records: a particle's values changed");
  for (long k = 1; k < R.n; k++)
    if (R.gid[k] <= R.gid[k - 1]) die("records: not in one-process order");
  long total = R.n;
  MPI_Allreduce(MPI_IN_PLACE, &total, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  if (total != n * size) die("records: particles lost");
  for (int a = 0; a < NA; a++) free(R.arr[a]);
  free(R.gid);
  free(R.order);
  free(R.dest);
  free(R.sbuf);
  free(R.rbuf);
  free(R.tmp);
  MPI_Comm_free(&R.near);
}

/* ---- swarm: PETSc's DMSwarm --------------------------------------------- */

static void run_swarm(long n, int steps, long moving, double *t) {
  DM sw;
  CHK(DMCreate(PETSC_COMM_WORLD, &sw));
  CHK(DMSetType(sw, DMSWARM));
  CHK(DMSwarmSetType(sw, DMSWARM_BASIC));
  CHK(DMSwarmRegisterPetscDatatypeField(sw, "gid", 1, PETSC_LONG));
  for (int a = 0; a < NA; a++)
    CHK(DMSwarmRegisterPetscDatatypeField(sw, fname[a], ncomp[a],
                                          PETSC_DOUBLE));
  CHK(DMSwarmFinalizeFieldRegister(sw));
  CHK(DMSwarmSetLocalSizes(sw, (PetscInt)n, (PetscInt)(n / 2 + 1)));
  long *gid;
  double *arr[NA];
  CHK(DMSwarmGetField(sw, "gid", NULL, NULL, (void **)&gid));
  for (int a = 0; a < NA; a++)
    CHK(DMSwarmGetField(sw, fname[a], NULL, NULL, (void **)&arr[a]));
  for (long k = 0; k < n; k++) {
    gid[k] = rank * n + k;
    for (int a = 0; a < NA; a++)
      for (int c = 0; c < ncomp[a]; c++)
        arr[a][k * ncomp[a] + c] = value(gid[k], a, c);
  }
  for (int a = 0; a < NA; a++)
    CHK(DMSwarmRestoreField(sw, fname[a], NULL, NULL, (void **)&arr[a]));
  CHK(DMSwarmRestoreField(sw, "gid", NULL, NULL, (void **)&gid));
  const int to = (rank + 1) % size;
  for (int s = 0; s < steps; s++) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime();
    PetscInt nl, *dest;
    CHK(DMSwarmGetLocalSize(sw, &nl));
    CHK(DMSwarmGetField(sw, DMSwarmField_rank, NULL, NULL, (void **)&dest));
    for (long k = 0; k < nl; k++)
      dest[k] = leaves(k, nl, moving, s) ? to : rank;
    CHK(DMSwarmRestoreField(sw, DMSwarmField_rank, NULL, NULL, (void **)&dest));
    CHK(DMSwarmMigrate(sw, PETSC_TRUE));
    t[s] = MPI_Wtime() - t0;
  }
  PetscInt nl;
  CHK(DMSwarmGetLocalSize(sw, &nl));
  CHK(DMSwarmGetField(sw, "gid", NULL, NULL, (void **)&gid));
  for (int a = 0; a < NA; a++)
    CHK(DMSwarmGetField(sw, fname[a], NULL, NULL, (void **)&arr[a]));
  if (wrong(nl, gid, arr)) die("swarm: a particle's values changed");
  for (int a = 0; a < NA; a++)
    CHK(DMSwarmRestoreField(sw, fname[a], NULL, NULL, (void **)&arr[a]));
  CHK(DMSwarmRestoreField(sw, "gid", NULL, NULL, (void **)&gid));
  long total = nl;
  MPI_Allreduce(MPI_IN_PLACE, &total, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  if (total != n * size) die("swarm: particles lost");
  CHK(DMDestroy(&sw));
}

int main(int argc, char **argv) {
  CHK(PetscInitialize(&argc, &argv, NULL, NULL));
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (argc < 4 || size < 2) {
    if (!rank)
      fprintf(stderr,
              "usage: mpirun -np 2 bench-migration N STEPS MOVING...\n");
    PetscFinalize();
    return 2;
  }
  const long n = atol(argv[1]);
  const int steps = atoi(argv[2]);
  for (int i = 3; i < argc; i++)
    if (atol(argv[i]) < 0 || atol(argv[i]) > n / 2 || steps < 1)
      die("MOVING from 0 to N / 2 and STEPS at least 1");
  double *t = malloc(sizeof(double) * steps);
  if (!rank)
    printf("%-8s %6s %9s %9s %12s %12s\n", "way", "ranks", "per rank", "moving",
           "median s", "fastest s");
  for (int i = 3; i < argc; i++) {
    const long moving = atol(argv[i]);
    for (int way = 0; way < 2; way++) {
      (way ? run_swarm : run_records)(n, steps, moving, t);
      MPI_Allreduce(MPI_IN_PLACE, t, steps, MPI_DOUBLE, MPI_MAX,
                    MPI_COMM_WORLD);
      double fast = t[0];
      for (int s = 1; s < steps; s++) fast = t[s] < fast ? t[s] : fast;
      if (!rank)
        printf("%-8s %6d %9ld %9ld %12.3e %12.3e\n", way ? "swarm" : "records",
               size, n, moving, median(t, steps), fast);
    }
  }
  free(t);
  CHK(PetscFinalize());
  return 0;
}
