/* What a frame costs across ranks, written three ways: the particles of a
 * lattice (x fastest) shared by ranks as the MPM decomposition shares them
 * (cut along x: each rank's particles are runs of a row, interleaved with
 * the other ranks' in the one-process order), each with the fields of an
 * MPM frame (position, displacement, velocity: 3; stress: 9; strain
 * energy density, J, pressure: 1 each; 21 doubles a particle), as
 * pm_output writes a frame (one HDF5 file a frame, its datasets in
 * one-process order, synced to disk, renamed when whole):
 *   gather      every rank's particles to rank 0 (MPI_Gatherv, one field at
 *               a time), placed in one-process order, written by rank 0
 *               (what pointmech does);
 *   per-rank    each rank writes a file of its own particles and their
 *               one-process indices, and rank 0 an XDMF index of the
 *               pieces (the frame is whole when every rank's is);
 *   collective  one file through MPI-IO (parallel HDF5, collective
 *               transfers), each rank writing its runs at their places;
 *   coll-block  the same, each rank's particles one block after the ranks'
 *               before it, with their one-process indices beside (a
 *               reader's permutation);
 *   pieces      per-rank's files, joined by rank 0's frame file of HDF5
 *               virtual datasets (a block a rank, the indices beside), as
 *               pm_results_join_pieces writes a frame across ranks.
 * Prints, per way, the median and the fastest of REPS frames (seconds) and
 * the bytes of a frame.  WAYS: the ways to run, comma-separated (all by
 * default).  Usage (under mpirun):
 *   bench-parallel-output DIR NX NY NZ [REPS [WAYS]]
 * The HDF5 is Debian's openmpi build (libhdf5-openmpi-dev, which PETSc
 * brings); the program links nothing else of pointmech's. */
#define _POSIX_C_SOURCE 200809L
#include <fcntl.h>
#include <hdf5.h>
#include <mpi.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum { NFIELDS = 7, WIDTH = 21 };
static const char *names[NFIELDS] = {
    "position", "displacement", "velocity", "stress", "strain_energy_density",
    "jacobian", "pressure"};
static const int ncomp[NFIELDS] = {3, 3, 3, 9, 1, 1, 1};

static int rank, size;

static void fail(const char *what) {
  fprintf(stderr, "bench-parallel-output: rank %d: %s\n", rank, what);
  MPI_Abort(MPI_COMM_WORLD, 1);
}

/* fsync of a file by name (the frame on disk before it is renamed). */
static void sync_file(const char *path) {
  int fd = open(path, O_RDONLY);
  if (fd < 0 || fsync(fd) != 0) fail("fsync");
  close(fd);
}

/* Field f's values of this rank's particles (n of them, one-process indices
 * gid): any values, the same for the same particle whatever the way. */
static void fill(double *v, const long *gid, long n, int f) {
  for (long k = 0; k < n; k++)
    for (int c = 0; c < ncomp[f]; c++)
      v[k * ncomp[f] + c] = (double)gid[k] * 1e-3 + f + 0.1 * c;
}

static hid_t create_dataset(hid_t file, int f, hsize_t n) {
  hsize_t dims[2] = {n, (hsize_t)ncomp[f]};
  hid_t space = H5Screate_simple(ncomp[f] > 1 ? 2 : 1, dims, NULL);
  hid_t d = H5Dcreate2(file, names[f], H5T_IEEE_F64LE, space, H5P_DEFAULT,
                       H5P_DEFAULT, H5P_DEFAULT);
  H5Sclose(space);
  if (d < 0) fail("H5Dcreate2");
  return d;
}

/* The gather: rank 0 writes the whole frame in one-process order. */
static void frame_gather(const char *dir, long N, long n, const long *gid,
                         double *mine, double *all, double *ordered,
                         long *allgid, int *counts, int *displs) {
  int cnt = (int)n;
  MPI_Gather(&cnt, 1, MPI_INT, counts, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (rank == 0) {
    displs[0] = 0;
    for (int r = 0; r < size; r++) displs[r + 1] = displs[r] + counts[r];
  }
  MPI_Gatherv(gid, cnt, MPI_LONG, allgid, counts, displs, MPI_LONG, 0,
              MPI_COMM_WORLD);
  char tmp[512], path[512];
  snprintf(tmp, sizeof tmp, "%s/gather.h5.tmp", dir);
  snprintf(path, sizeof path, "%s/gather.h5", dir);
  hid_t file = -1;
  if (rank == 0) {
    file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file < 0) fail("H5Fcreate");
  }
  for (int f = 0; f < NFIELDS; f++) {
    const int nc = ncomp[f];
    fill(mine, gid, n, f);
    int c2 = cnt * nc, *cn = counts + size + 1, *dn = displs + size + 1;
    MPI_Gather(&c2, 1, MPI_INT, cn, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (rank == 0) {
      dn[0] = 0;
      for (int r = 0; r < size; r++) dn[r + 1] = dn[r] + cn[r];
    }
    MPI_Gatherv(mine, c2, MPI_DOUBLE, all, cn, dn, MPI_DOUBLE, 0,
                MPI_COMM_WORLD);
    if (rank != 0) continue;
    for (long k = 0; k < N; k++)
      memcpy(ordered + allgid[k] * nc, all + k * nc, nc * sizeof(double));
    hid_t d = create_dataset(file, f, (hsize_t)N);
    if (H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, ordered) <
        0)
      fail("H5Dwrite");
    H5Dclose(d);
  }
  if (rank == 0) {
    H5Fclose(file);
    sync_file(tmp);
    if (rename(tmp, path) != 0) fail("rename");
  }
  MPI_Bcast(&cnt, 1, MPI_INT, 0, MPI_COMM_WORLD); /* the frame is whole */
}

/* Rank 0's frame file of virtual datasets joining the pieces (all[r]
 * particles in rank r's), a block a rank. */
static void join_pieces(const char *dir, const long *all) {
  char tmp[512], path[512], src[64];
  snprintf(tmp, sizeof tmp, "%s/joined.h5.tmp", dir);
  snprintf(path, sizeof path, "%s/joined.h5", dir);
  hid_t file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file < 0) fail("H5Fcreate");
  long N = 0;
  for (int r = 0; r < size; r++) N += all[r];
  for (int f = -1; f < NFIELDS; f++) {
    const int nc = f < 0 ? 1 : ncomp[f];
    hsize_t dims[2] = {(hsize_t)N, (hsize_t)nc}, start[2] = {0, 0};
    hid_t vs = H5Screate_simple(nc > 1 ? 2 : 1, dims, NULL);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    for (int r = 0; r < size; r++) {
      hsize_t block[2] = {(hsize_t)all[r], (hsize_t)nc};
      if (!all[r]) continue;
      H5Sselect_hyperslab(vs, H5S_SELECT_SET, start, NULL, block, NULL);
      hid_t ss = H5Screate_simple(nc > 1 ? 2 : 1, block, NULL);
      snprintf(src, sizeof src, "piece_%04d.h5", r);
      if (H5Pset_virtual(dcpl, vs, src, f < 0 ? "index" : names[f], ss) < 0)
        fail("H5Pset_virtual");
      H5Sclose(ss);
      start[0] += block[0];
    }
    H5Sselect_all(vs);
    hid_t d = H5Dcreate2(file, f < 0 ? "index" : names[f],
                         f < 0 ? H5T_STD_I64LE : H5T_IEEE_F64LE, vs,
                         H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (d < 0) fail("H5Dcreate2 (virtual)");
    H5Dclose(d);
    H5Pclose(dcpl);
    H5Sclose(vs);
  }
  H5Fclose(file);
  sync_file(tmp);
  if (rename(tmp, path) != 0) fail("rename");
}

/* Per rank: each rank's own file, then rank 0's XDMF index of the pieces
 * (or, joined, its frame file of virtual datasets). */
static void frame_per_rank(const char *dir, long n, const long *gid,
                           double *mine, bool joined) {
  char tmp[512], path[512];
  snprintf(tmp, sizeof tmp, "%s/piece_%04d.h5.tmp", dir, rank);
  snprintf(path, sizeof path, "%s/piece_%04d.h5", dir, rank);
  hid_t file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file < 0) fail("H5Fcreate");
  hsize_t dims[1] = {(hsize_t)n};
  hid_t space = H5Screate_simple(1, dims, NULL);
  hid_t d = H5Dcreate2(file, "index", H5T_STD_I64LE, space, H5P_DEFAULT,
                       H5P_DEFAULT, H5P_DEFAULT);
  if (H5Dwrite(d, H5T_NATIVE_LONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, gid) < 0)
    fail("H5Dwrite");
  H5Dclose(d);
  H5Sclose(space);
  for (int f = 0; f < NFIELDS; f++) {
    fill(mine, gid, n, f);
    d = create_dataset(file, f, (hsize_t)n);
    if (H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, mine) < 0)
      fail("H5Dwrite");
    H5Dclose(d);
  }
  H5Fclose(file);
  sync_file(tmp);
  if (rename(tmp, path) != 0) fail("rename");
  long *all = rank == 0 ? malloc(sizeof(long) * (size_t)size) : NULL;
  MPI_Gather(&n, 1, MPI_LONG, all, 1, MPI_LONG, 0, MPI_COMM_WORLD);
  if (rank != 0) return;
  if (joined) {
    join_pieces(dir, all);
    free(all);
    return;
  }
  snprintf(tmp, sizeof tmp, "%s/pieces.xdmf.tmp", dir);
  snprintf(path, sizeof path, "%s/pieces.xdmf", dir);
  FILE *x = fopen(tmp, "w");
  if (!x) fail("fopen");
  fprintf(x, "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\"><Domain>\n"
             "<Grid Name=\"frame\" GridType=\"Collection\" "
             "CollectionType=\"Spatial\">\n");
  for (int r = 0; r < size; r++) {
    fprintf(x,
            "<Grid Name=\"rank%d\"><Topology TopologyType=\"Polyvertex\" "
            "NumberOfElements=\"%ld\"/><Geometry GeometryType=\"XYZ\">"
            "<DataItem Dimensions=\"%ld 3\" Format=\"HDF\">piece_%04d.h5:/"
            "position</DataItem></Geometry>\n",
            r, all[r], all[r], r);
    for (int f = 1; f < NFIELDS; f++)
      fprintf(x,
              "<Attribute Name=\"%s\" Center=\"Node\"><DataItem "
              "Dimensions=\"%ld %d\" Format=\"HDF\">piece_%04d.h5:/%s"
              "</DataItem></Attribute>\n",
              names[f], all[r], ncomp[f], r, names[f]);
    fprintf(x, "</Grid>\n");
  }
  fprintf(x, "</Grid></Domain></Xdmf>\n");
  fflush(x);
  fsync(fileno(x));
  fclose(x);
  if (rename(tmp, path) != 0) fail("rename");
  free(all);
}

/* Collective: one file by MPI-IO, each rank's runs at their places (in
 * one-process order), or (blocks) each rank's particles as one block after
 * the ranks' before it, with their one-process indices beside. */
static void frame_collective(const char *dir, long N, long n, const long *gid,
                             double *mine, bool blocks) {
  char tmp[512], path[512];
  snprintf(tmp, sizeof tmp, "%s/collective%s.h5.tmp", dir,
           blocks ? "-blocks" : "");
  snprintf(path, sizeof path, "%s/collective%s.h5", dir,
           blocks ? "-blocks" : "");
  hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_fapl_mpio(fapl, MPI_COMM_WORLD, MPI_INFO_NULL);
  hid_t file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  H5Pclose(fapl);
  if (file < 0) fail("H5Fcreate (MPI-IO)");
  hid_t xfer = H5Pcreate(H5P_DATASET_XFER);
  H5Pset_dxpl_mpio(xfer, H5FD_MPIO_COLLECTIVE);
  long first = 0;
  MPI_Exscan(&n, &first, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  if (rank == 0) first = 0;
  for (int f = blocks ? -1 : 0; f < NFIELDS; f++) {
    if (f < 0) { /* the one-process indices, as doubles */
      for (long k = 0; k < n; k++) mine[k] = (double)gid[k];
      hsize_t dims[1] = {(hsize_t)N};
      hid_t space = H5Screate_simple(1, dims, NULL);
      hid_t d = H5Dcreate2(file, "index", H5T_IEEE_F64LE, space, H5P_DEFAULT,
                           H5P_DEFAULT, H5P_DEFAULT);
      hsize_t start[1] = {(hsize_t)first}, count[1] = {(hsize_t)n};
      H5Sselect_none(space);
      if (n > 0)
        H5Sselect_hyperslab(space, H5S_SELECT_SET, start, NULL, count, NULL);
      hid_t ms = H5Screate_simple(1, count, NULL);
      if (n == 0) H5Sselect_none(ms);
      if (H5Dwrite(d, H5T_NATIVE_DOUBLE, ms, space, xfer, mine) < 0)
        fail("H5Dwrite (collective)");
      H5Sclose(ms);
      H5Sclose(space);
      H5Dclose(d);
      continue;
    }
    fill(mine, gid, n, f);
    hid_t d = create_dataset(file, f, (hsize_t)N);
    hid_t fs = H5Dget_space(d);
    H5Sselect_none(fs);
    if (blocks) {
      hsize_t start[2] = {(hsize_t)first, 0},
              count[2] = {(hsize_t)n, (hsize_t)ncomp[f]};
      if (n > 0)
        H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL);
    } else {
      /* this rank's runs of consecutive indices */
      for (long k = 0; k < n;) {
        long e = k + 1;
        while (e < n && gid[e] == gid[e - 1] + 1) e++;
        hsize_t start[2] = {(hsize_t)gid[k], 0},
                count[2] = {(hsize_t)(e - k), (hsize_t)ncomp[f]};
        H5Sselect_hyperslab(fs, H5S_SELECT_OR, start, NULL, count, NULL);
        k = e;
      }
    }
    hsize_t mdims[2] = {(hsize_t)n, (hsize_t)ncomp[f]};
    hid_t ms = H5Screate_simple(ncomp[f] > 1 ? 2 : 1, mdims, NULL);
    if (n == 0) H5Sselect_none(ms);
    if (H5Dwrite(d, H5T_NATIVE_DOUBLE, ms, fs, xfer, mine) < 0)
      fail("H5Dwrite (collective)");
    H5Sclose(ms);
    H5Sclose(fs);
    H5Dclose(d);
  }
  H5Pclose(xfer);
  H5Fflush(file, H5F_SCOPE_GLOBAL);
  H5Fclose(file);
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank == 0) {
    sync_file(tmp);
    if (rename(tmp, path) != 0) fail("rename");
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

/* Whether way is in the comma-separated list only (NULL: every way). */
static bool chosen(const char *only, const char *way) {
  if (!only) return true;
  const size_t n = strlen(way);
  for (const char *p = only; (p = strstr(p, way)); p += n)
    if ((p == only || p[-1] == ',') && (p[n] == ',' || p[n] == '\0'))
      return true;
  return false;
}

static int by_value(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (argc < 5) {
    if (rank == 0)
      fprintf(stderr, "usage: bench-parallel-output DIR NX NY NZ [REPS]\n");
    MPI_Finalize();
    return 2;
  }
  const char *dir = argv[1];
  const long nx = atol(argv[2]), ny = atol(argv[3]), nz = atol(argv[4]);
  const int reps = argc > 5 ? atoi(argv[5]) : 5;
  const char *only = argc > 6 ? argv[6] : NULL;
  const long N = nx * ny * nz;
  /* Rank r: the particles with x in [nx r / size, nx (r + 1) / size). */
  const long x0 = nx * rank / size, x1 = nx * (rank + 1) / size;
  const long n = (x1 - x0) * ny * nz;
  long *gid = malloc(sizeof(long) * (size_t)(n + 1));
  double *mine = malloc(sizeof(double) * (size_t)(WIDTH * n + 1));
  long k = 0;
  for (long q = 0; q < N; q++)
    if (q % nx >= x0 && q % nx < x1) gid[k++] = q;
  double *all = NULL, *ordered = NULL;
  long *allgid = NULL;
  int *counts = malloc(sizeof(int) * 2 * (size_t)(size + 1)),
      *displs = malloc(sizeof(int) * 2 * (size_t)(size + 2));
  if (rank == 0) {
    all = malloc(sizeof(double) * 9 * (size_t)N);
    ordered = malloc(sizeof(double) * 9 * (size_t)N);
    allgid = malloc(sizeof(long) * (size_t)N);
  }
  if (!gid || !mine || !counts || !displs || (rank == 0 && !allgid))
    fail("out of memory");
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  enum { WAYS = 5 };
  static const char *ways[WAYS] = {"gather", "per-rank", "collective",
                                   "coll-block", "pieces"};
  double *t = malloc(sizeof(double) * WAYS * (size_t)reps);
  /* The ways take turns, so that the machine's drift falls on all. */
  for (int r = 0; r < reps; r++)
    for (int w = 0; w < WAYS; w++) {
      if (!chosen(only, ways[w])) continue;
      MPI_Barrier(MPI_COMM_WORLD);
      double t0 = MPI_Wtime();
      if (w == 0)
        frame_gather(dir, N, n, gid, mine, all, ordered, allgid, counts,
                     displs);
      else if (w == 1 || w == 4)
        frame_per_rank(dir, n, gid, mine, w == 4);
      else
        frame_collective(dir, N, n, gid, mine, w == 3);
      MPI_Barrier(MPI_COMM_WORLD);
      t[w * reps + r] = MPI_Wtime() - t0;
    }
  if (rank == 0) {
    printf("%-10s %5s %11s %9s %11s %11s\n", "way", "ranks", "particles", "MB",
           "median s", "fastest s");
    for (int w = 0; w < WAYS; w++) {
      if (!chosen(only, ways[w])) continue;
      double *v = t + w * reps;
      qsort(v, (size_t)reps, sizeof *v, by_value);
      printf("%-10s %5d %11ld %9.1f %11.4f %11.4f\n", ways[w], size, N,
             (double)N * WIDTH * 8 / 1e6, v[reps / 2], v[0]);
    }
  }
  free(t);
  free(gid);
  free(mine);
  free(all);
  free(ordered);
  free(allgid);
  free(counts);
  free(displs);
  MPI_Finalize();
  return 0;
}
