/* pm_load_steps.h: load stepping over a pm_newton solver (what it did,
 * its state between steps, checkpoints of it).  Included by pm_newton.h,
 * whose types it uses: include that. */
#ifndef PM_LOAD_STEPS_H
#define PM_LOAD_STEPS_H

/* What load stepping did. */
typedef struct {
  int steps;          /* converged load steps */
  int cuts;           /* step halvings, over all steps */
  double lambda;      /* the load reached (1 on success) */
  double dlambda_min; /* smallest step converged */
  int newton_iterations;
  int linear_iterations;
  double time_residual, time_assembly, time_linear, time_total;
  double time_setup; /* of time_linear: preconditioner set-ups */
  int pc_setups;     /* their number */
  /* Of time_linear: matrix-free products; CPU seconds (all threads) of
   * the parts; counts of residuals, linearisations and products (those
   * of the relaxation fallback not included). */
  double time_apply;
  double cpu_residual, cpu_assembly, cpu_linear, cpu_setup, cpu_apply;
  long residual_evaluations, jacobians, jacobian_applications;
  pm_newton_report last; /* the last Newton solve (the failing one on
                            failure) */
  /* The relaxation fallback: relaxations run, steps they let converge,
   * their iterations (one residual each) and wall seconds. */
  int relaxations, relaxed_steps;
  long relax_iterations;
  double time_relax;
  /* The pseudo-transient fallback: continuations run, steps they let
   * converge, their iterations (one linear solve each), wall seconds, and
   * the smallest curvature dx.J dx / dx.M dx met along their increments
   * (negative: an indefinite tangent; 0 before any). */
  int ptc_runs, ptc_steps;
  long ptc_iterations;
  double time_ptc, ptc_curvature;
  /* The tangent's lowest mode at the converged state before each
   * continuation (pm_load_branch.c): how many were computed, the smallest
   * eigenvalue of K v = q M v met (negative: that state is unstable, past
   * a bifurcation), the continuations started off the state along the
   * mode that let their step converge (branch switches), and the last
   * mode's line. */
  int mode_runs, branch_switches;
  double mode_eigenvalue;
  char mode_note[400];
  /* Arc-length continuations (pm_load_arc.c; where the lowest eigenvalue
   * is not negative: a limit point) run, those that passed the fold, their
   * arcs and corrector iterations, and wall seconds. */
  int arc_runs, arc_passes;
  long arc_steps, arc_iterations;
  double time_arc;
  /* Steps carried past a limit point by relaxation (options.follow_fold
   * false): their number, the highest load the last one's path reached
   * (the limit point's, to the arcs' resolution), the lowest eigenvalue
   * at the state before it, and the lines of all (as they fit); fallbacks
   * stopped by options.fallback_seconds. */
  int snap_steps;
  double snap_lambda, snap_eigenvalue;
  char snap_note[1024];
  int fallbacks_timed_out;
  /* Newton solves run again for pm_newton_problem.settle, and the steps
   * that failed as their set did not settle. */
  int resolves, unsettled;
} pm_load_report;

/* Loads from lambda = 0 (x converged there) to 1 in options.load_steps
 * steps: each sets the load, solves by Newton from the last converged
 * state (or the predictor), and calls on_step.  A step that fails (any
 * reason of pm_newton_solve but a hard failure) is halved and retried from
 * the last converged state, up to max_cuts halvings in a row and no
 * smaller than min_dlambda; after relax_after cuts in a row, and at the
 * smallest step, dynamic relaxation within the step is tried first (see
 * relax_after).  x receives the last converged state, and the load is left
 * set to its lambda.  report (may be NULL) is filled in either case.  On
 * failure returns PM_ERR_NOT_CONVERGED or PM_ERR_UNSTABLE with a message
 * naming the step, the loads and the cause, and the problem's diagnose
 * line of the last state tried, e.g. "load step 7 (lambda 0.4375 ->
 * 0.46875): Newton did not converge in 25 iterations (residual 3.2e-04
 * from 1.1e+00); relaxation: ...; cut 6 times to dlambda 1e-04: giving up;
 * at the last state tried: ...". */
pm_err pm_load_steps(pm_newton *s, double *x, pm_load_report *report);

/* What load stepping carries from one step to the next: the load factor
 * reached and the one before, the next step's size, the converged steps
 * since the last cut (for regrowth), and the last two converged states.
 * At on_step it is exactly the state the next step starts from, which a
 * checkpoint writes. */
typedef struct {
  double lambda, lambda_prev, dl;
  long good;
  long have_prev; /* xprev holds a converged state */
  double *xc;     /* n: the last converged state */
  double *xprev;  /* n: the one before */
  /* options.pc_reuse_its: the factorisation or preconditioner kept then,
   * built (1) or not (0) at the state pc_x (n values) under the load
   * pc_lambda, and the iterations of the last linear solve it served and
   * whether that failed.  A resume builds it anew there, so that the
   * steps that follow repeat the first run's. */
  long pc_built, pc_its, pc_failed;
  double pc_lambda;
  double *pc_x;
  long pc_first_its; /* pc_reuse_cost: the kept one's first solve's its */
  /* The fallbacks' linear solver kept since a step fell back
   * (pm_newton_set_fallback_linear with keep): 1, else 0. */
  long fallback_kept;
  /* options.relax_first: the last step was carried by relaxation, so the
   * next is relaxed first (1), else 0. */
  long relax_first;
  /* options.relax_first: relaxation has carried a step of this run (1),
   * so a step that falls back tries it ahead of the continuations, else
   * 0. */
  long relax_carried;
  /* The report as it stood when the last step converged: the counts a
   * checkpoint keeps, so that a run stopped inside a step and resumed
   * counts that step's attempts once. */
  pm_load_report done;
} pm_load_state;

/* Allocate a state's arrays for a problem of n unknowns, zeroed (lambda 0:
 * a start from rest).  PM_ERR_MEMORY. */
pm_err pm_load_state_init(pm_load_state *state, long n);
void pm_load_state_free(pm_load_state *state);

/* pm_load_steps keeping its state in state (caller-owned, of the
 * problem's n).  With state->lambda > 0 (a checkpoint's), it continues
 * from that state instead of from x at lambda = 0, and report's counters
 * (steps, cuts, iterations, dlambda_min) go on from their values in
 * *report; the steps that follow are those the first run would have
 * taken. */
pm_err pm_load_steps_from(pm_newton *s, double *x, pm_load_state *state,
                          pm_load_report *report);

/* Write or read load stepping's state (st, over n unknowns; NULL: none;
 * n = 0: its figures without the states xc, xprev and pc_x, which the
 * caller keeps in a form of its own, and without the kept factorisation's
 * figures) and the counters of rep, as checkpoint items
 * named PREFIX.lambda, ... (pm_checkpoint.h: the same calls write and
 * read). */
pm_err pm_load_checkpoint(pm_ckpt *ck, const char *prefix, long n,
                          pm_load_state *st, pm_load_report *rep);

#endif
