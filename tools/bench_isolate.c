/* bench-isolate: the cost of reading files in a child process
 * (pm_isolate.h): a gmsh file meshed by gm_gmsh_load and a checkpoint
 * vetted by pm_ckpt_vet, each repeated, in the process (PM_ISOLATE=0) and
 * in a child, with the CPU seconds of the process and of its children, the
 * wall seconds, and the process's peak resident memory after each way.
 *
 *   bench-isolate MESH H CHECKPOINT_DIR REPEATS
 *
 * (benchmarks/bench-isolate.sh runs it on the project's files). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>

#include "gm_gmsh.h"
#include "pm_h5_vet.h"

static double seconds(struct timeval t) { return t.tv_sec + 1e-6 * t.tv_usec; }

/* CPU seconds of who (RUSAGE_SELF or RUSAGE_CHILDREN). */
static double cpu(int who) {
  struct rusage u;
  getrusage(who, &u);
  return seconds(u.ru_utime) + seconds(u.ru_stime);
}

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

static long peak_kb(void) {
  struct rusage u;
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

/* One way of reading (isolated or not), repeats times each read. */
static int measure(const char *mesh, double h, const char *ckpt, int repeats,
                   int isolated) {
  setenv("PM_ISOLATE", isolated ? "1" : "0", 1);
  const char *way = isolated ? "child" : "process";
  long nodes = 0;
  double c0 = cpu(RUSAGE_SELF), k0 = cpu(RUSAGE_CHILDREN), w0 = now();
  for (int r = 0; r < repeats; r++) {
    gm_gmsh_mesh m;
    if (gm_gmsh_load(mesh, 3, h, GM_SIZES_REPLACE, false, &m) != PM_SUCCESS) {
      fprintf(stderr, "bench-isolate: %s\n", pm_error_message());
      return 1;
    }
    nodes = m.n_nodes;
    gm_gmsh_mesh_free(&m);
  }
  double c1 = cpu(RUSAGE_SELF), k1 = cpu(RUSAGE_CHILDREN), w1 = now();
  printf("| mesh (%ld nodes) | %s | %.4f | %.4f | %.4f | %ld |\n", nodes, way,
         (c1 - c0) / repeats, (k1 - k0) / repeats, (w1 - w0) / repeats,
         peak_kb());
  for (int r = 0; r < repeats; r++)
    if (pm_ckpt_vet(ckpt) != PM_SUCCESS) {
      fprintf(stderr, "bench-isolate: %s\n", pm_error_message());
      return 1;
    }
  double c2 = cpu(RUSAGE_SELF), k2 = cpu(RUSAGE_CHILDREN), w2 = now();
  printf("| checkpoint vetted | %s | %.4f | %.4f | %.4f | %ld |\n", way,
         (c2 - c1) / repeats, (k2 - k1) / repeats, (w2 - w1) / repeats,
         peak_kb());
  return 0;
}

int main(int argc, char **argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: bench-isolate MESH H CHECKPOINT_DIR REPEATS\n");
    return 2;
  }
  const double h = atof(argv[2]);
  const int repeats = atoi(argv[4]);
  printf("| read | where | CPU s, process | CPU s, children | wall s | "
         "peak RSS of the process, kB |\n|---|---|---|---|---|---|\n");
  /* The child first: the process's peak is then the parent's own. */
  if (measure(argv[1], h, argv[3], repeats, 1)) return 1;
  return measure(argv[1], h, argv[3], repeats, 0);
}
