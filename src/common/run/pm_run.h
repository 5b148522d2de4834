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

/* How a run goes (a bit mask; true is PM_RUN_QUIET). */
enum {
  PM_RUN_QUIET = 1u << 0,    /* no progress line, no stage-time table */
  PM_RUN_OVERWRITE = 1u << 1 /* replace another run's files in out_dir */
};

/* Run the simulation sim that s->backend created from s.  With out_dir
 * non-NULL: claims the folder (created if missing; refused when another
 * pointmech runs there, or, without PM_RUN_OVERWRITE, when it holds another
 * run's files), writes every frame as it comes (pm_output.h: crash-safe),
 * history.csv rows synced with each frame, summary.json with status
 * "running" and then the outcome, and checkpoints as output.checkpoint
 * asks.  SIGINT and SIGTERM end the run after the current step with a last
 * frame and a checkpoint.  Unless PM_RUN_QUIET, shows a progress line on a
 * terminal and prints the stage times to stderr.  Fills *o even on
 * failure.  Returns PM_ERR_UNSTABLE on a numerical failure,
 * PM_ERR_NOT_CONVERGED when a quasi-static run did not reach its
 * tolerance, PM_ERR_INTERRUPTED after a signal, and I/O errors as they
 * come. */
pm_err pm_run_sim(const pm_scene *s, void *sim, const char *out_dir,
                  unsigned flags, pm_outcome *o);

/* Create the backend's simulation of s, run it as pm_run_sim, destroy it.
 * A scene estimated past the memory available is refused first with
 * PM_ERR_MEMORY (pm_memory_check), before anything is allocated or the
 * output folder is claimed.  Across MPI ranks (pm_par.h) every rank calls
 * it: rank 0 claims the folder and writes every output, the others step
 * their share; all return the same error. */
pm_err pm_run_scene(const pm_scene *s, const char *out_dir, unsigned flags,
                    pm_outcome *o);

/* pm_run_scene with the caller's observer also (NULL: none), told of
 * every step after the driver has written what the step writes (on rank 0
 * across ranks; the shares gathered where its wants asks), and the
 * simulation kept: *sim, the backend's, for the caller to read and destroy
 * (s->backend->destroy), NULL when the setup failed. */
pm_err pm_run_scene_observed(const pm_scene *s, const char *out_dir,
                             unsigned flags, const pm_observer *also,
                             void **sim, pm_outcome *o);

/* Continue the run in out_dir from its checkpoint.h5: the scene is loaded
 * again from the file and overrides the checkpoint names (refused when its
 * text changed, when the checkpoint comes from another program version, or
 * when it is damaged, with the reason), frames and history rows written
 * after the checkpoint are dropped, and the run goes on appending to the
 * same results, history and summary.  On the thread count of the first run
 * it ends bit-identical to an uninterrupted run.  Across ranks every rank
 * calls it: rank 0 claims the folder and writes, every rank reads the
 * checkpoint. */
pm_err pm_resume(const char *out_dir, unsigned flags, pm_outcome *o);

/* Create the simulation and print its plan with the memory estimate (the
 * same refusal first).  Across ranks every rank calls it, and rank 0's
 * out is the one that is read. */
pm_err pm_plan_scene(const pm_scene *s, FILE *out);

/* The label of boundary condition b of s, as history.csv (reaction
 * columns) and summary.json (reactions) name it: its surface, or
 * "boundary.B" for a region; into buf (size bytes, truncated). */
void pm_run_bc_label(const pm_scene *s, int b, char *buf, size_t size);

#endif
