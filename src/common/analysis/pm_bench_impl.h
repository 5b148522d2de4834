/* pm_bench_impl: a bench suite as read, its comparisons and FE referees,
 * and the functions the files of pm_bench share; not for callers of
 * pm_bench.h. */
#ifndef PM_BENCH_IMPL_H
#define PM_BENCH_IMPL_H

#include <stdbool.h>
#include <stdio.h>

#include "pm_bench.h"
#include "pm_compare.h"
#include "pm_fe.h"
#include "pm_files.h"
#include "pm_scene_doc.h"

#define BENCH_NAME PM_COMPARE_NAME_MAX
#define BENCH_METHODS 16 /* variants a suite defines */
#define BENCH_CASES 64
#define BENCH_RES 8   /* resolutions of a case */
#define BENCH_SETS 32 /* overrides of a method or a case */
#define BENCH_FE_ROWS 16
#define BENCH_FE_LEVELS 12 /* meshes of the FE ladder a case runs */
#define MIB (1024.0 * 1024.0)

typedef struct {
  char label[BENCH_NAME], method[BENCH_NAME];
  int n_sets;
  const char *sets[BENCH_SETS]; /* the suite document's text */
} pm_bench_method;

typedef struct {
  char name[BENCH_NAME];
  char scene[PM_PATH_MAX + 1];
  int n_methods;
  int method[PM_COMPARE_MAX_METHODS]; /* suite methods, or -1 - backend */
  char plain[PM_COMPARE_MAX_METHODS][BENCH_NAME]; /* a method by name */
  int n_res;
  double res[BENCH_RES]; /* discretization.mesh_size (none: the scene's) */
  int n_sets;
  const char *sets[BENCH_SETS];
  int n_fe; /* the FE ladder CalculiX solves (key fe; 0: none) */
  int fe_ladder[BENCH_FE_LEVELS];
  int fe_threads; /* ccx's threads (0: OMP_NUM_THREADS, else the cores) */
} pm_bench_case;

/* One comparison: a case at a resolution. */
typedef struct {
  int c;
  double res; /* NaN: the scene's own */
  char dir[PM_PATH_MAX + 1];
  pm_err err;
  char message[PM_COMPARE_MESSAGE_MAX]; /* when no method ran */
  int n_rows;
  pm_compare_row rows[PM_COMPARE_MAX_METHODS];
  double seconds; /* the comparison's wall time */
} pm_bench_comparison;

/* A mesh of the FE ladder a bench ran, measured against the case's
 * referee. */
typedef struct {
  int n; /* elements per edge */
  long nodes, increments;
  char element[PM_FE_TEXT_MAX];
  char status[32]; /* converged, stopped, or reference (the referee's own
                      mesh or a finer one: not measured against itself) */
  double h, wall_seconds, cpu_seconds, memory_bytes;
  double error; /* the reaction's (a traction case's: the tip's) relative
                   error against the referee's figure; NaN when none */
  double nrmse; /* the displacement at the referee's lattice */
} pm_bench_fe_level;

/* The FE referee of a case: its ladder's reactions and times. */
typedef struct {
  bool have;
  char dir[PM_PATH_MAX + 1];
  int n;
  pm_fe_row rows[BENCH_FE_ROWS];
  double reaction; /* the referee's loaded reaction, N; a traction case's
                      (tip): its tip displacement, m (pm_fe_tip) */
  double tol;      /* its relative tolerance on that (NaN: none) */
  int axis;
  bool tip; /* a traction case: judged by the tip displacement */
  /* The ladder the bench ran (the case's key fe): its levels, ccx's
   * threads, where it ran, and why it did not when it did not. */
  int n_levels, threads;
  pm_bench_fe_level levels[BENCH_FE_LEVELS];
  char run_dir[PM_PATH_MAX + 1];
  char message[PM_COMPARE_MESSAGE_MAX];
} pm_bench_fe;

/* Runs case C's FE ladder (C->fe_ladder) by CalculiX through tool
 * (tools/fe-referee.py, under /usr/bin/python3) into dir/fe, each mesh
 * timed (wall, CPU, peak memory of ccx alone, threads as F->threads), and
 * measures each level against the case's referee F (loaded by the
 * caller): reaction (tip) error and lattice NRMSE; a level at or finer than
 * the referee's finest mesh is marked "reference", not measured against
 * itself.  Never fails: when ccx, the tool or python is missing or the
 * tool stops, F->message says why (and the levels it reached stay).
 * Prints a line per level to out (NULL: none). */
void pm_bench_fe_ladder(const pm_bench_case *C, pm_bench_fe *F,
                        const char *tool, const char *dir, FILE *out);

/* A run's error against the FE referee's figure (relative): the loaded
 * reaction's, or a traction case's tip displacement's. */
double pm_bench_fe_error(const pm_compare_row *r);

typedef struct {
  pm_sdoc doc;
  char *text;
  char path[PM_PATH_MAX + 1], folder[PM_PATH_MAX + 1];
  char name[BENCH_NAME];
  int n_methods;
  pm_bench_method m[BENCH_METHODS];
  int n_cases;
  pm_bench_case c[BENCH_CASES];
} pm_bench_suite;

/* Reads and checks the suite file path into S (zeroed by the caller; its
 * document and text are S's to free).  PM_ERR_SCENE naming the key on a
 * bad one, PM_ERR_IO when it cannot be read. */
pm_err pm_bench_read_suite(const char *path, pm_bench_suite *S);

/* The NRMSE a run is judged by, and against what (*against: "FE",
 * "analytic", "run", or "" with NaN). */
double pm_bench_judged(const pm_compare_row *r, const char **against);

/* A resolution as text: the number, or "scene" for NaN (the scene's). */
void pm_bench_res_text(char *b, size_t size, double res);

/* Writes dir/bench.md and dir/bench.csv of the n_runs comparisons (fe: the
 * referee of each case), seconds their wall time, and a line naming them
 * to out (NULL: none).  PM_ERR_IO when a file cannot be written. */
pm_err pm_bench_write_report(const char *dir, const pm_bench_suite *S,
                             const pm_bench_comparison *runs, int n_runs,
                             const pm_bench_fe *fe, double seconds, FILE *out);

#endif
