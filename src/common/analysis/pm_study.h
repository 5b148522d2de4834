/* pm_study: a ladder of runs of one scene (a resolution or a parameter
 * ladder), each compared with the scene's analytic field, a reference run
 * or a finite-element reference, tabulated with its wall time and the
 * observed rate. */
#ifndef PM_STUDY_H
#define PM_STUDY_H

#include <stdbool.h>
#include <stdio.h>

#include "pm_error.h"
#include "pm_run.h"
#include "pm_scene.h"

#define PM_STUDY_MAX_KEYS 8
#define PM_STUDY_MAX_LEVELS 32

typedef struct {
  const char *scene; /* scene file */
  int n_sets;        /* --set overrides for every level */
  const char *const *sets;
  int n_keys; /* ladder keys and their comma-separated values */
  const char *ladder[PM_STUDY_MAX_KEYS]; /* "key=v1,v2,..." */
  /* NULL: the scene's reference.fe if it names one, else "analytic" if
   * the scene has a reference field, else "last".  "analytic", "last"
   * (the last level is the reference run), "fe:DIR" or a directory holding
   * ladder.csv (a finite-element reference, pm_fe: each level's error is
   * the NRMSE at its lattice, with the reaction and mean strain energy
   * density errors and the reaction error's rate beside), or the directory
   * of an earlier run. */
  const char *reference;
  const char *out_dir; /* NULL: out/NAME-convergence */
  bool quiet;
  bool overwrite; /* replace the files of an earlier study's levels */
} pm_study_options;

/* Run the ladder; write OUT/convergence.csv and OUT/convergence.md and the
 * runs under OUT/level-K (and OUT/reference).  Prints progress and the table to
 * out (may be NULL). Bad ladders and scenes fail with PM_ERR_SCENE before
 * anything runs.  A level that fails numerically is tabulated with its status;
 * the return is then that level's error (the tables are still written). */
pm_err pm_study_run(const pm_study_options *o, FILE *out);

#endif
