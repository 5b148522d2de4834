/* mpm_backend: explicit MPM as an entry of the backend table: the
 * simulation of a scene (model, state, workspace), its time loop reporting
 * to the run's observer, its fields, figures and plan. */
#ifndef MPM_BACKEND_H
#define MPM_BACKEND_H

#include "mpm_solver.h"
#include "mpm_state.h"
#include "pm_backend.h"
#include "pm_view.h"
#include "pm_scene.h"

extern const pm_backend mpm_backend;
/* Quasi-static implicit MPM (mpm_implicit.h) on the same model, state,
 * fields, figures and output. */
extern const pm_backend mpm_implicit_backend;

struct mpm_implicit;

/* A prepared simulation.  Fields are read-only for callers.  Across MPI
 * ranks (mpm_par.h) the time loop steps this rank's share (local_*), and
 * model, state and work are rank 0's view of the whole run, gathered into
 * when the run writes (NULL on the other ranks); work then holds only the
 * figures of the last step and the timers. */
typedef struct {
  const pm_scene *scene; /* borrowed: must outlive the simulation */
  mpm_model *model;
  mpm_state *state;
  mpm_work *work;
  mpm_model *local_model;
  mpm_state *local_state;
  mpm_work *local_work;
  /* across ranks, at the end of the run: the exchanges' bytes and
   * particles summed over the ranks, their seconds the slowest rank's;
   * the ranks' own work (stages less exchanges), the most and the mean;
   * the bytes of linked points' ghosts, summed */
  double ranks_counts[9];
  /* read from a checkpoint: the ranks of the run that wrote it and their
   * energy accounts (MPM_PAR_ACCOUNTS each) */
  int ckpt_ranks;
  double *ckpt_accounts;
  struct mpm_implicit *imp;   /* method mpm-implicit: its solver (else NULL) */
  int imp_newton, imp_linear; /* the last load step's iterations */
  /* across ranks, at the end of an implicit run: per rank its particles,
   * own unknowns and ghost unknowns (3 each) */
  long *imp_ranks;
  double setup_wall; /* s */
  double *scratch;   /* output buffer (scratch_per_particle) */
  /* Across ranks with frames in pieces: the share's output buffer, with
   * room for share_scratch_cap particles (grown with the share). */
  double *share_scratch;
  long share_scratch_cap;
  /* history columns of its own: names (and their storage) */
  const char *hist_names[PM_HISTORY_MAX];
  char hist_store[PM_HISTORY_MAX][48];
  int n_hist;
  /* per scene body: a membrane's triangles counted from its first point
   * (those a body lies inside or outside of; else NULL) */
  long **surface;
  /* the run */
  pm_status status;
  double energy0;          /* kinetic + strain + internal at t = 0 */
  double run_min_jacobian; /* smallest J of any step's stress update */
  long run_min_jacobian_step;
  int iter_max_row; /* most iterations since the last history row */
  long iter_capped_prev;
  mpm_step_info last; /* the last step's figures */
  bool resumed;       /* the state came from a checkpoint */
  pm_view view;       /* the run's observer, and rank 0's view across ranks */
} mpm_sim;

/* Model, initial state, workspace and output buffer of scene s.  Failures
 * as mpm_model_create; *out NULL then. */
pm_err mpm_sim_create(const pm_scene *s, mpm_sim **out);
/* Release a simulation and all it holds (NULL accepted). */
void mpm_sim_destroy(mpm_sim *r);

#endif
