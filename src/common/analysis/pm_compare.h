/* pm_compare: one scene run by several methods, one after the other, each
 * displacement field mapped onto one lattice by moving least squares, and
 * the methods tabulated against each other and against the references. */
#ifndef PM_COMPARE_H
#define PM_COMPARE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "pm_error.h"

#define PM_COMPARE_MAX_METHODS 8
#define PM_COMPARE_LATTICE 9 /* default points along the shortest axis */
#define PM_COMPARE_NAME_MAX 64
#define PM_COMPARE_MESSAGE_MAX 1024

/* One method's figures, for callers that tabulate several comparisons
 * (pointmech bench).  NaN where there is no such figure. */
typedef struct {
  char name[PM_COMPARE_NAME_MAX];   /* its label */
  char method[PM_COMPARE_NAME_MAX]; /* the method it ran */
  char status[32];                  /* pm_status_name, "refused", "not-run" */
  char message[PM_COMPARE_MESSAGE_MAX]; /* why it failed ("" if it did not) */
  bool ran;                             /* it has a run's figures */
  long points, steps, flagged;
  double h;
  double wall_seconds;  /* its setup's and its run's (summary.json's
                           wall_seconds is the run's alone) */
  double setup_seconds; /* its setup's: before the run, as the backend
                           made its model */
  double cpu_seconds;   /* the process's CPU time (user + system, every
                           thread) over the run's setup and time loop */
  size_t memory_bytes;
  /* NRMSE against the analytic field, the FE lattice, a reference run;
   * the loaded face's reaction and the mean SED against FE's (relative);
   * a traction case's tip displacement against FE's (pm_fe_tip). */
  double e_analytic, e_fe, e_run, reaction_fe, sed_fe, tip_fe;
  double loaded_reaction, min_jacobian;
} pm_compare_row;

typedef struct {
  const char *scene; /* scene file */
  /* Comma-separated methods: "fpm,mpm"; LABEL=METHOD runs METHOD under
   * LABEL (its folder, rows and --set scope): "paper=fpm,best=fpm". */
  const char *methods;
  /* Overrides: "KEY=VALUE" for every method, "METHOD:KEY=VALUE" for that
   * method alone (after the others).  Each method's scene is the file with
   * method=METHOD, then these. */
  int n_sets;
  const char *const *sets;
  /* NULL: the scene's analytic field (reference.displacement) and its FE
   * referee (reference.fe), those it has.  "analytic": the analytic field
   * alone.  "fe:DIR" or a folder holding ladder.csv: that FE referee (and
   * the analytic field).  Otherwise the folder of an earlier run, mapped
   * onto the lattice like the methods (and the analytic field). */
  const char *reference;
  /* The regular lattice's points along the shortest axis of the bodies'
   * box (the others at the same spacing); 0: PM_COMPARE_LATTICE.  Unused
   * with an FE referee, whose lattice is taken. */
  long lattice;
  const char *out_dir; /* NULL: out/NAME-compare */
  bool quiet;
  bool overwrite; /* replace the files of an earlier comparison's runs */
  /* NULL, or room for PM_COMPARE_MAX_METHODS rows: filled with each
   * method's figures once the tables are written (*n_rows of them). */
  pm_compare_row *rows;
  int *n_rows;
} pm_compare_options;

/* Run the scene once per method into OUT/METHOD (pm_run_sim, in this
 * process, one at a time), map every displacement field and von Mises
 * stress onto the lattice (a lattice point without enough neighbours is
 * flagged and left out), and write OUT/compare.md, OUT/compare.csv (a row
 * per method, a row per pair) and OUT/midplane.csv (the lattice's middle
 * plane: every method's and reference's displacement, for
 * tools/plot-compare.py).  Prints progress and the tables to out (may be
 * NULL).  Bad options, a scene that does not load as given, and a
 * reference that cannot be read fail before anything runs (PM_ERR_SCENE,
 * PM_ERR_IO, ...).  A method whose scene is refused or whose run fails is
 * tabulated with its status and message and the others still run; the
 * return is then the first such error (the tables are still written).
 * The output folder is copied into dir (size bytes) as soon as it is
 * known ("" before). */
pm_err pm_compare_run(const pm_compare_options *o, FILE *out, char *dir,
                      size_t size);

/* Table helpers shared by the reports (compare, bench): a number with
 * digits significant digits ("" when it is not finite) into b; a CSV
 * field quoted, its quotes doubled and line breaks made blanks; a
 * Markdown table cell's text without '|' and line breaks. */
#define PM_TABLE_NUMBER 32
const char *pm_table_number(char b[PM_TABLE_NUMBER], double v, int digits);
void pm_csv_text(FILE *f, const char *s);
void pm_md_text(FILE *f, const char *s);

#endif
