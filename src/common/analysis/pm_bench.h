/* pm_bench: the comparative benchmark as users run it.  A suite file lists
 * scenes, the methods (each a label, a method and its overrides) and the
 * resolutions; every case runs as one comparison per resolution
 * (pm_compare), one after the other, and the suite's report tabulates
 * every run's error against the FE referee or the analytic field beside
 * its wall time and memory, with the FE referee's own ladder.
 *
 * Suite file (YAML; scene paths relative to the suite file):
 *
 *   name: standard
 *   methods:                        # the variants the cases name
 *     - {label: fpm-paper, method: fpm}
 *     - {label: mpm, method: mpm, set: [mpm.fbar=cell]}
 *   cases:
 *     - name: f3-60
 *       scene: ../fpm/f3-extension-60.yaml
 *       methods: [fpm-paper, mpm]     # default: every method of the suite
 *       resolutions: [2e-2, 1e-2]     # discretization.mesh_size; default
 *                                     # the scene's own
 *       set: [time.end=5, "mpm:time.quasi_static.tolerance=1e-4"]
 *       fe: {ladder: [2, 4, 8], threads: 2}  # CalculiX on these meshes,
 *                                     # timed beside the methods (rows "fe")
 */
#ifndef PM_BENCH_H
#define PM_BENCH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "pm_error.h"

typedef struct {
  const char *suite; /* suite file */
  const char *only;  /* NULL, or run only the cases whose name holds one of
                        these comma-separated names */
  int n_sets;        /* overrides for every run, after the suite's */
  const char *const *sets;
  const char *out_dir; /* NULL: out/NAME-bench */
  bool quiet;          /* the runs' own progress off (the suite's stays) */
  bool overwrite;      /* replace an earlier bench's runs */
  const char *fe_tool; /* tools/fe-referee.py, which runs a case's FE
                          ladder (key fe); NULL: the FE rows say so */
} pm_bench_options;

/* Read the suite (every problem in it fails before anything runs, at its
 * FILE:LINE:COL), then run each case at each resolution into
 * OUT/CASE/h-RES by pm_compare_run, printing a line per run and one per
 * method as they finish; then the case's FE ladder (key fe) by CalculiX
 * into OUT/CASE/fe, each mesh a row "fe" beside the methods' (a missing
 * ccx is said in those rows, not a failure).  A case whose comparison fails or
 * whose methods fail is listed with its diagnosis and the suite goes on. Writes
 * OUT/bench.md (the table, the failures, the definitions) and
 * OUT/bench.csv (a row per method run and per FE ladder level, for
 * tools/plot-bench.py), and returns the first failure (the report is
 * written all the same).  The output folder is copied into dir. */
pm_err pm_bench_run(const pm_bench_options *o, FILE *out, char *dir,
                    size_t size);

#endif
