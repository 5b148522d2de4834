/* pm_study: a ladder of runs of one scene (a resolution or a parameter
 * ladder), each compared with the scene's analytic field or with a
 * reference run, tabulated with its wall time and the observed rate. */
#ifndef PM_STUDY_H
#define PM_STUDY_H

#include <stdbool.h>
#include <stdio.h>

#include "pm_error.h"
#include "pm_scene.h"

#define PM_STUDY_MAX_KEYS 8
#define PM_STUDY_MAX_LEVELS 32

/* What a backend reports about one finished run. */
typedef struct {
  const char *status; /* "converged", "completed", "unstable", ... */
  int dim;
  long points, steps;
  double h;           /* mean point spacing (mean edge), m */
  double wall, setup; /* run and setup wall time, s */
  double nrmse;       /* against the scene's analytic field; NaN if none */
  double mean_sed;    /* mean strain energy density, J/m^3 */
  double max_von_mises;
  double reaction;     /* loaded face, along its largest prescribed value */
  double min_jacobian; /* smallest J seen during the run */
  double energy_error; /* final energy-balance error */
} pm_run_figures;

/* Run scene s, writing to out_dir; fill fig even when the run fails
 * (fig->status says how).  Returns the run's error code. */
typedef pm_err (*pm_study_runner)(void *ctx, const pm_scene *s,
                                  const char *out_dir, bool quiet,
                                  pm_run_figures *fig);

typedef struct {
  const char *scene; /* scene file */
  int n_sets;        /* --set overrides for every level */
  const char *const *sets;
  int n_keys; /* ladder keys and their comma-separated values */
  const char *ladder[PM_STUDY_MAX_KEYS]; /* "key=v1,v2,..." */
  /* NULL: "analytic" if the scene has a reference field, else "last".
   * "analytic", "last" (the last level is the reference run), or the
   * directory of an earlier run. */
  const char *reference;
  const char *out_dir; /* NULL: out/NAME-convergence */
  bool quiet;
} pm_study_options;

/* Run the ladder; write OUT/convergence.csv and OUT/convergence.md and the
 * runs under OUT/level-K (and OUT/reference).  Prints progress and the table to
 * out (may be NULL). Bad ladders and scenes fail with PM_ERR_SCENE before
 * anything runs.  A level that fails numerically is tabulated with its status;
 * the return is then that level's error (the tables are still written). */
pm_err pm_study_run(const pm_study_options *o, pm_study_runner run, void *ctx,
                    FILE *out);

#endif
