/* A frame across ranks written in pieces (pm_results_write_piece on every
 * rank, pm_results_join_pieces on rank 0) against the same frame gathered
 * to rank 0 and written whole (pm_results_write_frame, what a run across
 * ranks does): run under mpirun, on the particles of an NX x NY x NZ
 * lattice (x fastest) cut along x as the MPM decomposition cuts them, so
 * that each rank's particles are runs of every row, with the fields of an
 * MPM frame (position, displacement, velocity, stress, von_mises,
 * strain_energy_density, jacobian: 21 doubles a particle).
 *
 * Checks that both ways' frames read back (through results.h5, rank 0),
 * put in one-process order by the pieces' index, hold the same values bit
 * for bit, and the pieces' frame is each rank's particles in rank order.
 * With REPS > 0, the two ways take turns REPS times and rank 0 prints the
 * median and the fastest wall seconds of a frame of each, and the CPU
 * seconds of the slowest rank summed over the frames.
 * Usage: ranks_output DIR NX NY NZ [REPS]; exits 0 when all checks hold. */
#include <hdf5.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "frame_read.h"
#include "pm_output.h"
#include "pm_par.h"
#include "pm_par_mpi.h"

enum { NF = 7 };
static const char *names[NF] = {
    "position",  "displacement",          "velocity", "stress",
    "von_mises", "strain_energy_density", "jacobian"};
static const int ncomp[NF] = {3, 3, 3, 9, 1, 1, 1};

static int rank, size, failures;

static void expect(bool ok, const char *what) {
  if (!ok) {
    printf("FAIL: rank %d: %s\n", rank, what);
    failures++;
  }
}

static void ok_or_die(pm_err e, const char *what) {
  if (e == PM_SUCCESS) return;
  fprintf(stderr, "ranks_output: rank %d: %s: %s\n", rank, what,
          pm_error_message());
  MPI_Abort(MPI_COMM_WORLD, 1);
}

/* Field f's values of the n particles gid (any values, the same for the
 * same particle and frame k). */
static void fill(double *v, const long *gid, long n, int f, long k) {
  for (long p = 0; p < n; p++)
    for (int c = 0; c < ncomp[f]; c++)
      v[p * ncomp[f] + c] = (double)gid[p] * 1e-3 + f + 0.1 * c + 7.0 * k;
}

static double cpu_seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Main's way: every field gathered to rank 0, placed in one-process order
 * and written whole by rank 0.  all, ordered, allgid: rank 0's. */
static void frame_gather(pm_results *r, long N, long n, const long *gid,
                         double *mine, double *all, double *ordered,
                         long *allgid, long k, long step) {
  int cnt = (int)n, *counts = malloc(sizeof(int) * 2 * (size_t)size);
  int *displs = counts + size;
  MPI_Gather(&cnt, 1, MPI_INT, counts, 1, MPI_INT, 0, pm_par_comm());
  if (rank == 0)
    for (int q = 0, at = 0; q < size; at += counts[q++]) displs[q] = at;
  MPI_Gatherv(gid, cnt, MPI_LONG, allgid, counts, displs, MPI_LONG, 0,
              pm_par_comm());
  pm_field f[NF];
  size_t off = 0;
  for (int i = 0; i < NF; i++) {
    const int nc = ncomp[i];
    fill(mine, gid, n, i, k);
    int c2 = cnt * nc;
    MPI_Gather(&c2, 1, MPI_INT, counts, 1, MPI_INT, 0, pm_par_comm());
    if (rank == 0)
      for (int q = 0, at = 0; q < size; at += counts[q++]) displs[q] = at;
    MPI_Gatherv(mine, c2, MPI_DOUBLE, all, counts, displs, MPI_DOUBLE, 0,
                pm_par_comm());
    if (rank != 0) continue;
    double *dst = ordered + off;
    off += (size_t)nc * (size_t)N;
    for (long p = 0; p < N; p++)
      memcpy(dst + allgid[p] * nc, all + p * nc, sizeof(double) * nc);
    f[i] = (pm_field){names[i], nc, dst};
  }
  free(counts);
  pm_err e = rank == 0 ? pm_results_write_frame(r, step, 0.1 * step, NF, f) : 0;
  ok_or_die(pm_par_agree(e), "the gathered frame");
}

/* The pieces: every rank its own, then rank 0 joins them (every frame's
 * step its index among the frames). */
static void frame_pieces(pm_results *r, const char *dir, long n,
                         const long *gid, double *mine, long *counts, long k,
                         long step) {
  pm_field f[NF];
  double *at = mine;
  for (int i = 0; i < NF; i++) {
    fill(at, gid, n, i, k);
    f[i] = (pm_field){names[i], ncomp[i], at};
    at += ncomp[i] * n;
  }
  ok_or_die(pm_par_agree(pm_results_write_piece(dir, step, rank, n, gid, step,
                                                0.1 * step, NF, f)),
            "a piece");
  MPI_Gather(&n, 1, MPI_LONG, counts, 1, MPI_LONG, 0, pm_par_comm());
  pm_err e = rank == 0 ? pm_results_join_pieces(r, step, 0.1 * step, size,
                                                counts, NF, f)
                       : PM_SUCCESS;
  ok_or_die(pm_par_agree(e), "the joined frame");
}

/* Dataset name of frame k through results.h5 (rank 0) into out. */
static void read_frame(const char *dir, long k, const char *name, hid_t mtype,
                       void *out) {
  expect(pm_test_read_frame(dir, k, name, mtype, out), name);
}

/* Rank 0: frame kp (pieces) in one-process order equals frame kg (gathered)
 * bit for bit, its rows rank by rank. */
static void compare(const char *dir, long N, long kg, long kp,
                    const long *counts) {
  long *index = malloc(sizeof(long) * (size_t)N);
  double *g = malloc(sizeof(double) * 9 * (size_t)N),
         *p = malloc(sizeof(double) * 9 * (size_t)N),
         *o = malloc(sizeof(double) * 9 * (size_t)N);
  read_frame(dir, kp, PM_PIECE_INDEX, H5T_NATIVE_LONG, index);
  /* Rank q's rows: its particles, increasing. */
  long row = 0;
  for (int q = 0; q < size; q++)
    for (long j = 0; j < counts[q]; j++, row++)
      if (row > 0 && j > 0 && index[row] <= index[row - 1]) {
        expect(false, "a piece's rows in one-process order");
        break;
      }
  char *seen = calloc((size_t)N, 1);
  for (long i = 0; i < N; i++)
    if (index[i] >= 0 && index[i] < N) seen[index[i]]++;
  long once = 0;
  for (long i = 0; i < N; i++) once += seen[i] == 1;
  expect(once == N, "every particle in one piece, once");
  for (int i = 0; i < NF && once == N; i++) {
    const int nc = ncomp[i];
    read_frame(dir, kg, names[i], H5T_NATIVE_DOUBLE, g);
    read_frame(dir, kp, names[i], H5T_NATIVE_DOUBLE, p);
    for (long j = 0; j < N; j++)
      memcpy(o + index[j] * nc, p + j * nc, sizeof(double) * nc);
    expect(memcmp(o, g, sizeof(double) * nc * (size_t)N) == 0, names[i]);
  }
  free(seen);
  free(index);
  free(g);
  free(p);
  free(o);
}

static int by_value(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

int main(int argc, char **argv) {
  if (argc < 5) {
    fprintf(stderr, "usage: ranks_output DIR NX NY NZ [REPS]\n");
    return 2;
  }
  if (pm_par_init(&argc, &argv) || pm_par_attach(MPI_COMM_WORLD)) {
    fprintf(stderr, "%s\n", pm_error_message());
    return 2;
  }
  rank = pm_par_rank();
  size = pm_par_size();
  const char *dir = argv[1];
  const long nx = atol(argv[2]), ny = atol(argv[3]), nz = atol(argv[4]);
  const int reps = argc > 5 ? atoi(argv[5]) : 0;
  const long N = nx * ny * nz;
  const long x0 = nx * rank / size, x1 = nx * (rank + 1) / size;
  const long n = (x1 - x0) * ny * nz;
  long *gid = malloc(sizeof(long) * (size_t)(n + 1)), m = 0;
  for (long q = 0; q < N; q++)
    if (q % nx >= x0 && q % nx < x1) gid[m++] = q;
  double *mine = malloc(sizeof(double) * 21 * (size_t)(n + 1));
  double *all = NULL, *ordered = NULL, *x = NULL;
  long *allgid = NULL, *counts = malloc(sizeof(long) * (size_t)size);
  pm_results *r = NULL;
  if (rank == 0) {
    all = malloc(sizeof(double) * 9 * (size_t)N);
    ordered = malloc(sizeof(double) * 21 * (size_t)N);
    allgid = malloc(sizeof(long) * (size_t)N);
    x = calloc(3 * (size_t)N, sizeof(double));
    mkdir(dir, 0755);
    const pm_points pts = {.n = N, .x = x, .nodes_per_cell = 1};
    ok_or_die(pm_results_create_ex(dir, 3, &pts, "", "", &r), "the results");
  }
  ok_or_die(pm_par_agree(PM_SUCCESS), "setup");
  /* The checks: frame 0 gathered, frame 1 in pieces, of the same values. */
  frame_gather(r, N, n, gid, mine, all, ordered, allgid, 0, 0);
  frame_pieces(r, dir, n, gid, mine, counts, 0, 1);
  if (rank == 0) compare(dir, N, 0, 1, counts);
  double *t = malloc(sizeof(double) * 2 * (size_t)(reps + 1)), cpu[2] = {0, 0};
  for (int k = 0; k < reps; k++)
    for (int w = 0; w < 2; w++) {
      MPI_Barrier(pm_par_comm());
      const double t0 = MPI_Wtime(), c0 = cpu_seconds();
      if (w == 0)
        frame_gather(r, N, n, gid, mine, all, ordered, allgid, k, 2 + 2 * k);
      else
        frame_pieces(r, dir, n, gid, mine, counts, k, 3 + 2 * k);
      MPI_Barrier(pm_par_comm());
      cpu[w] += cpu_seconds() - c0;
      t[w * reps + k] = MPI_Wtime() - t0;
    }
  pm_par_max(cpu, 2);
  if (rank == 0 && reps > 0) {
    printf("%-8s %5s %11s %11s %11s %13s\n", "way", "ranks", "particles",
           "median s", "fastest s", "cpu s/frame");
    for (int w = 0; w < 2; w++) {
      double *v = t + w * reps;
      qsort(v, (size_t)reps, sizeof *v, by_value);
      printf("%-8s %5d %11ld %11.4f %11.4f %13.4f\n", w ? "pieces" : "gather",
             size, N, v[reps / 2], v[0], cpu[w] / reps);
    }
  }
  long bad = failures;
  pm_par_sum_long(&bad, 1);
  if (rank == 0) {
    pm_results_close(r, true);
    printf("%s: %ld particles on %d ranks, a frame in pieces read back as "
           "the gathered one\n",
           bad ? "FAIL" : "ok", N, size);
  }
  void *held[] = {t, gid, mine, all, ordered, allgid, x, counts};
  for (size_t i = 0; i < sizeof held / sizeof *held; i++) free(held[i]);
  MPI_Finalize();
  return bad ? 1 : 0;
}
