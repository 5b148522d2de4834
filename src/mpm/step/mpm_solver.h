/* mpm_solver: the explicit MPM time loop, with an observer that sees every
 * step (output, progress and history live with the caller). */
#ifndef MPM_SOLVER_H
#define MPM_SOLVER_H

#include <stdbool.h>

#include "mpm_state.h"

typedef struct {
  double t_end;     /* stop at this time, s */
  long max_steps;   /* 0: no limit */
  long frame_every; /* frame = true every N steps (0: never) */
} mpm_run_options;

/* What a step reports to the observer. */
typedef struct {
  long step;
  double t, dt;
  double residual;  /* quasi-static residual (0 in dynamics) */
  int iter_max;     /* most iterations of a constitutive update */
  long iter_capped; /* particles whose iterations hit the cap */
  bool last;        /* the run's last step */
  bool converged;   /* quasi-static: residual below time.quasi_static
                       tolerance, with the loads applied */
} mpm_step_info;

/* Called after every step; frame is true every frame_every steps and on
 * the last step (converged, at t_end or at max_steps).  A non-success
 * return stops the run with it. */
typedef pm_err (*mpm_observer)(void *ctx, const mpm_model *m,
                               const mpm_state *s, const mpm_work *w,
                               const mpm_step_info *info, bool frame);

/* Step from the state as it is until t_end, max_steps or (quasi-static
 * models) convergence; with a fixed time.dt the last step is cut to end at
 * t_end.  Across ranks (m->xc) every rank calls it: after each step the
 * particles that left a rank's cells migrate (which changes m's particle
 * ranges), and the observer sees the rank's share.  Returns
 * PM_ERR_UNSTABLE on a numerical failure (the observer has
 * seen every step before it), or the observer's error.  *last (may be
 * NULL) receives the last step's figures.  Allocates nothing. */
pm_err mpm_solve(mpm_model *m, mpm_state *s, mpm_work *w,
                 const mpm_run_options *opt, mpm_observer observer, void *ctx,
                 mpm_step_info *last);

#endif
