/* pm_bench_fe: a bench case's finite-element ladder run by CalculiX
 * (tools/fe-referee.py), each mesh timed and measured against the case's
 * referee, so that FE's cost sits beside every method's. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_bench_impl.h"
#include "pm_fe.h"
#include "pm_files.h"
#include "pm_metrics.h"
#include "pm_spawn.h"

#define PYTHON "/usr/bin/python3"

/* Whether an executable named name is on PATH. */
static bool on_path(const char *name) {
  const char *path = getenv("PATH");
  char file[PM_PATH_MAX + 1];
  for (const char *p = path ? path : ""; *p;) {
    const char *e = strchr(p, ':');
    size_t n = e ? (size_t)(e - p) : strlen(p);
    if (n &&
        snprintf(file, sizeof file, "%.*s/%s", (int)n, p, name) <
            (int)sizeof file &&
        access(file, X_OK) == 0)
      return true;
    p += n + (e ? 1 : 0);
  }
  return false;
}

/* ccx's threads: the case's, else OMP_NUM_THREADS (the methods'), else
 * the cores online. */
static int threads_of(const pm_bench_case *C) {
  if (C->fe_threads > 0) return C->fe_threads;
  const char *env = getenv("OMP_NUM_THREADS");
  int n = env ? atoi(env) : 0;
  if (n > 0) return n;
  long cores = sysconf(_SC_NPROCESSORS_ONLN);
  return cores > 0 ? (int)cores : 1;
}

/* The last non-empty line of the file at path into buf (empty when none):
 * the tool's own diagnosis when it stops. */
static void last_line(const char *path, char *buf, size_t size) {
  char line[512];
  FILE *f = fopen(path, "r");
  buf[0] = 0;
  if (!f) return;
  while (fgets(line, sizeof line, f)) {
    line[strcspn(line, "\n")] = 0;
    if (line[0]) snprintf(buf, size, "%.*s", (int)size - 1, line);
  }
  fclose(f);
}

/* Runs tool on case name with the ladder, output to log; 0 when it ran
 * and exited 0, its exit status when it exited, -1 when it did not run. */
static int spawn_tool(const char *tool, const char *name, const char *ladder,
                      int threads, const char *out, const char *work,
                      const char *log) {
  char th[16];
  snprintf(th, sizeof th, "%d", threads);
  char *const args[] = {
      (char *)PYTHON, (char *)tool, (char *)name, "--run",  "--ladder",
      (char *)ladder, "--out",      (char *)out,  "--work", (char *)work,
      "--threads",    th,           "--lattices", NULL};
  return pm_spawn_wait(args, log);
}

/* The index of the referee's finest mesh that reached the load (-1:
 * none). */
static int referee_finest(const pm_bench_fe *F) {
  int f = -1;
  for (int k = 0; k < F->n; k++)
    if (F->rows[k].converged) f = k;
  return f;
}

/* Level L (row r of the ladder just run, its lattice in dir) against the
 * referee F, whose lattice ref holds (NULL: no NRMSE). */
static void measure(const pm_bench_fe *F, const pm_fe_reference *ref,
                    const pm_fe_row *r, const char *dir, pm_bench_fe_level *L) {
  const int finest = referee_finest(F);
  L->n = r->n;
  L->nodes = r->nodes;
  L->increments = r->increments;
  snprintf(L->element, sizeof L->element, "%s", r->element);
  L->h = r->h;
  L->wall_seconds = r->wall_seconds;
  L->cpu_seconds = r->cpu_seconds;
  L->memory_bytes = r->memory_bytes;
  L->error = L->nrmse = NAN;
  snprintf(L->status, sizeof L->status, "%s",
           r->converged ? "converged" : "stopped");
  if (!r->converged) return;
  /* The referee's own mesh (or a finer one of the same family) stands for
   * the solution: it is not measured against itself. */
  if (finest >= 0 && r->n >= F->rows[finest].n &&
      strcmp(r->element, F->rows[finest].element) == 0) {
    snprintf(L->status, sizeof L->status, "reference");
    return;
  }
  const double v = F->tip ? r->tip_u : r->reaction[F->axis];
  L->error = (v - F->reaction) / F->reaction;
  char name[32], path[PM_PATH_MAX + 1];
  long n = 0;
  double *x = NULL, *u = NULL;
  snprintf(name, sizeof name, "lattice-N%d.csv", r->n);
  if (ref && pm_path_join(path, sizeof path, dir, name) == PM_SUCCESS &&
      pm_fe_read_lattice(path, &n, &x, &u) == PM_SUCCESS && n == ref->n) {
    bool same = true;
    for (long j = 0; j < 3 * n && same; j++)
      same = fabs(x[j] - ref->x[j]) <= 1e-9;
    if (same) L->nrmse = pm_nrmse_vector(n, ref->dim == 2 ? 3u : 7u, u, ref->u);
  }
  pm_error_clear();
  free(x);
  free(u);
}

void pm_bench_fe_ladder(const pm_bench_case *C, pm_bench_fe *F,
                        const char *tool, const char *dir, FILE *out) {
  char ladder[BENCH_FE_LEVELS * 4 + 1], work[PM_PATH_MAX + 1];
  char folder[PM_PATH_MAX + 1], path[PM_PATH_MAX + 1], log[PM_PATH_MAX + 1];
  pm_fe_row *rows = NULL;
  pm_fe_reference *ref = NULL;
  int n_rows = 0;
  size_t used = 0;
  F->n_levels = 0;
  F->message[0] = 0;
  F->threads = threads_of(C);
  if (C->n_fe == 0) return;
  const char *why = NULL;
  if (!F->have)
    why = "the scene names no FE referee (reference.fe) to measure the "
          "ladder against";
  else if (!on_path("ccx"))
    why = "CalculiX (ccx) is not on PATH (apt-get install calculix-ccx): "
          "no FE rows";
  else if (!tool || access(tool, R_OK) != 0 || access(PYTHON, X_OK) != 0)
    why = "no " PYTHON " or no tools/fe-referee.py here: no FE rows";
  if (why) {
    snprintf(F->message, sizeof F->message, "%s", why);
    if (out) fprintf(out, "    fe             %s\n", why);
    return;
  }
  for (int k = 0; k < C->n_fe; k++)
    used += (size_t)snprintf(ladder + used, sizeof ladder - used, "%s%d",
                             k ? "," : "", C->fe_ladder[k]);
  const char *name = strrchr(F->dir, '/');
  name = name ? name + 1 : F->dir;
  if (pm_path_join(F->run_dir, sizeof F->run_dir, dir, "fe") != PM_SUCCESS ||
      pm_path_join(work, sizeof work, F->run_dir, "work") != PM_SUCCESS ||
      pm_path_join(log, sizeof log, F->run_dir, "fe-referee.log") !=
          PM_SUCCESS ||
      pm_path_join(folder, sizeof folder, F->run_dir, name) != PM_SUCCESS ||
      pm_path_join(path, sizeof path, folder, "ladder.csv") != PM_SUCCESS ||
      pm_mkdir_p(F->run_dir) != PM_SUCCESS) {
    snprintf(F->message, sizeof F->message, "%s", pm_error_message());
    pm_error_clear();
    return;
  }
  remove(path); /* an earlier bench's ladder is not this one's */
  if (out) {
    fprintf(out, "    fe             CalculiX %s, N = %s, %d thread%s...\n",
            name, ladder, F->threads, F->threads > 1 ? "s" : "");
    fflush(out);
  }
  const int rc =
      spawn_tool(tool, name, ladder, F->threads, F->run_dir, work, log);
  if (pm_fe_read_ladder(path, &rows, &n_rows) != PM_SUCCESS || n_rows == 0) {
    char tail[256];
    last_line(log, tail, sizeof tail);
    snprintf(F->message, sizeof F->message,
             "tools/fe-referee.py exited %d and wrote no ladder (%.400s): "
             "%.200s",
             rc, log, tail[0] ? tail : pm_error_message());
    pm_error_clear();
    if (out) fprintf(out, "    fe             %s\n", F->message);
    free(rows);
    return;
  }
  /* rc 1: fewer than two meshes reached the load (no claim of its own,
   * which the bench does not need); the levels are read all the same. */
  if (pm_fe_load(F->dir, &ref) != PM_SUCCESS) ref = NULL;
  pm_error_clear();
  for (int k = 0; k < n_rows && k < BENCH_FE_LEVELS; k++) {
    pm_bench_fe_level *L = &F->levels[F->n_levels++];
    measure(F, ref, &rows[k], folder, L);
    if (!out) continue;
    fprintf(out, "    fe N %-3d      %-10s %6ld nodes", L->n, L->status,
            L->nodes);
    if (isfinite(L->nrmse)) fprintf(out, ", NRMSE %.3g (FE)", L->nrmse);
    if (isfinite(L->error))
      fprintf(out, ", %s %+.3f%% of FE", F->tip ? "tip" : "reaction",
              100 * L->error);
    fprintf(out, ", %.2f s wall, %.2f s CPU\n", L->wall_seconds,
            L->cpu_seconds);
  }
  if (rc != 0 && rc != 1) {
    char tail[256];
    last_line(log, tail, sizeof tail);
    snprintf(F->message, sizeof F->message,
             "tools/fe-referee.py exited %d (%.400s): %.200s", rc, log, tail);
  }
  pm_fe_free(ref);
  free(rows);
}
