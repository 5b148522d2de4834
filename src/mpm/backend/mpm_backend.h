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

/* Rank 0's figures of a run across ranks without the whole model: what
 * the history rows and the end read, summed (or the extreme taken) over
 * the ranks' shares. */
typedef struct {
  double kinetic, strain, internal;
  /* per scene body (MPM_SUMS_BODY each): the sum of mass times
   * displacement (3), of mass, of pressure times volume and of volume */
  double *body;
  /* the end's fields: the solids' sum of V0 times the strain energy
   * density and of V0; the largest von Mises stress and the smallest J,
   * and where they are */
  double sed_volume, volume0;
  double max_von_mises, max_von_mises_at[3];
  double min_jacobian, min_jacobian_at[3];
  /* the NRMSE of each reference component and of the field (NAN: none) */
  double nrmse[3], nrmse_vector;
  long n;          /* particles */
  long grid_nodes; /* of the whole grid */
  double *buf;     /* what a rank sums: room made at setup */
} mpm_sums;
#define MPM_SUMS_BODY 6

/* A checkpoint in pieces (mpm_ckpt_pieces.c) as its index names it: its
 * folder, id and pieces, each's count and checksum (2 longs) and record
 * (PM_VIEW_CKPT_VALUES doubles), and the run's values (no arrays); on
 * until the state is read from the pieces. */
typedef struct {
  bool on;
  long id;
  int n;
  long *counts;
  double *values;
  mpm_state vals;
  char dir[PM_PATH_MAX + 1];
} mpm_ckpt_pieces;

/* A prepared simulation.  Fields are read-only for callers.  Across MPI
 * ranks (mpm_par.h) the time loop steps this rank's share (local_*), and
 * model, state and work are rank 0's view of the whole run, gathered into
 * when the run writes (NULL on the other ranks); work then holds only the
 * figures of the last step and the timers.  Without the whole model
 * (whole false) rank 0's model is NULL and its state holds the run's
 * scalars alone, its figures in sums. */
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
   * the bytes of linked points' ghosts, summed; the busiest rank's
   * particles and the mean summed over the looks at the balance; the
   * slowest rank's seconds cutting the boxes anew */
  double ranks_counts[12];
  /* across ranks, per rank: the particles it held at the end and the most
   * it held after a migration (2 a rank), NULL on one process */
  long *ranks_held;
  /* read from a checkpoint: the ranks of the run that wrote it and their
   * energy accounts (MPM_PAR_ACCOUNTS each) */
  int ckpt_ranks;
  double *ckpt_accounts;
  /* and the cut of its boxes, when it had as many ranks as this run
   * (mpm_decomp_pack's; NULL: none, or another count) */
  long *ckpt_cut;
  mpm_ckpt_pieces ckpt_pieces;
  /* Rank 0 without the whole model reading a whole checkpoint: its state
   * of the run's scalars, put back once the shares are cut. */
  mpm_state *ckpt_scalars;
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
  /* Across ranks, whether rank 0 keeps the whole model (its view,
   * pm_view_whole_needed; the same on every rank).  Without it rank 0's
   * state holds the run's scalars alone, and its figures come from sums
   * over the shares (mpm_view_sums.c). */
  bool whole;
  double *mesh_x0; /* rank 0, until the run starts: every reference
                      position, in one process's order (results' mesh) */
  mpm_sums sums;
  pm_view view; /* the run's observer, and rank 0's view across ranks */
} mpm_sim;

/* Model, initial state, workspace and output buffer of scene s.  Failures
 * as mpm_model_create; *out NULL then. */
pm_err mpm_sim_create(const pm_scene *s, mpm_sim **out);
/* Release a simulation and all it holds (NULL accepted). */
void mpm_sim_destroy(mpm_sim *r);

#endif
