/* pm_run: running a scene through its backend, the same way for every
 * method: results.h5 + results.xdmf (a frame every output.every steps and
 * at the end), history.csv (shared columns, the backend's own, reactions
 * and the error against the scene's reference field), summary.json (one
 * writer), the progress line and the stage-time table. */
#ifndef PM_RUN_H
#define PM_RUN_H

#include <stdbool.h>
#include <stdio.h>

#include "pm_backend.h"
#include "pm_scene.h"

/* What a finished run gives its caller. */
typedef struct {
  pm_figures fig;         /* status, counts, energies, fields, cost */
  double nrmse[3];        /* against reference.displacement, per component
                             (NaN where the scene gives none) */
  double nrmse_vector;    /* of the reference field (one component: its) */
  double loaded_reaction; /* on the loaded face: the condition with the
                             largest prescribed displacement at the end,
                             along that component (NaN if none) */
  int loaded_axis;        /* that component (0, 1, 2; -1 if none) */
  char message[1024];     /* why it stopped, when not a success */
} pm_outcome;

/* Run the simulation sim that s->backend created from s.  With out_dir
 * non-NULL, writes the files there (each committed atomically; the frames
 * before a numerical failure are kept); with quiet false, shows a progress
 * line on a terminal and prints the stage times to stderr.  Fills *o even
 * on failure.  Returns PM_ERR_UNSTABLE on a numerical failure,
 * PM_ERR_NOT_CONVERGED when a quasi-static run did not reach its
 * tolerance, and I/O errors as they come. */
pm_err pm_run_sim(const pm_scene *s, void *sim, const char *out_dir, bool quiet,
                  pm_outcome *o);

/* Create the backend's simulation of s, run it as pm_run_sim, destroy it.
 * A scene estimated past the memory available is refused first with
 * PM_ERR_MEMORY (pm_memory_check), before anything is allocated. */
pm_err pm_run_scene(const pm_scene *s, const char *out_dir, bool quiet,
                    pm_outcome *o);

/* Create the simulation and print its plan with the memory estimate (the
 * same refusal first). */
pm_err pm_plan_scene(const pm_scene *s, FILE *out);

#endif
