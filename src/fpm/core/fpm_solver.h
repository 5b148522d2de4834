/* fpm_solver: central-difference time stepping of an FPM model, with
 * optional damping or dynamic relaxation to a quasi-static state. */
#ifndef FPM_SOLVER_H
#define FPM_SOLVER_H

#include <stdbool.h>

#include "fpm_model.h"

typedef struct {
  double dt;               /* time step, s */
  double t_end;            /* stop at this time */
  long max_steps;          /* 0: no limit */
  pm_qs_method qs;         /* quasi-static method */
  double qs_tolerance;     /* relative residual to stop at (quasi-static) */
  double damping;          /* fixed damping (1/s) for PM_QS_DAMPING */
  long frame_every;        /* call on_step with frame = true every N steps */
  double min_jacobian;     /* stop when some J <= this (>= 0) */
  double max_energy_error; /* stop when energy_error exceeds this */
} fpm_run_options;

/* What a step reports to the observer. */
typedef struct {
  long step;
  double t;
  double kinetic;       /* 1/2 sum m v^2 */
  double strain;        /* sum V W */
  double penalty;       /* interface energy (penalty; SIPG: and flux) */
  double external_work; /* work of reactions and tractions so far */
  double dissipated;    /* energy taken by damping so far */
  double residual;      /* |f| on free dofs / (|reactions| + |f_ext|) */
  double damping;       /* current damping coefficient, 1/s */
  double min_jacobian;  /* smallest volume ratio J over the points */
  double energy_error;  /* fpm_energy_error of these figures */
  bool energy_checked;  /* the balance is held to its bound at this step */
  bool converged;
  bool last; /* the run's last step */
} fpm_step_info;

/* Called with the initial state (step 0) and after every step: frame is
 * true at step 0, every frame_every steps and at the last step.  A
 * non-success return stops the run. */
typedef pm_err (*fpm_observer)(void *ctx, const fpm_model *m,
                               const fpm_state *st, const fpm_step_info *info,
                               bool frame);

/* Run from the state: with st->step 0, from its u and v (normally zero)
 * at t = 0, reporting the initial state; otherwise from the step, time and
 * loop figures it holds (a checkpoint's), without reporting them again:
 * the steps that follow are those the first run would have taken.  On a
 * numerical failure returns PM_ERR_UNSTABLE with the step, time, point id,
 * position and cause; the observer has already seen every good frame.
 * info receives the last step's figures.  Allocates nothing. */
pm_err fpm_run(const fpm_model *m, fpm_state *st, const fpm_run_options *opt,
               fpm_observer observer, void *ctx, fpm_step_info *info,
               double stage_seconds[2]);

/* Largest eigenvalue of M^-1 K (K the tangent stiffness at u = 0, free
 * dofs) by power iteration on finite differences of the force, and the
 * step 2 / sqrt(lambda) it allows.  Uses st and work (3 n doubles) as work
 * space and leaves u = v = 0.  A measured figure to compare with the bound
 * of eqs. 24-26. */
double fpm_spectral_dt(const fpm_model *m, fpm_state *st, int iterations,
                       double *work, double *lambda);

/* Energy-balance error of a step's figures (pm_energy_error from rest:
 * (kinetic + strain + interface + dissipated - external work) over
 * |external work|, over the energy held while no work has been done yet;
 * signed, 0 when nothing moves). */
double fpm_energy_error(const fpm_step_info *s);

/* The supports' forces (force on prescribed dofs, boundary consistency
 * flux) of the state, remembered as the start of the next increment. */
void fpm_support_start(const fpm_model *m, fpm_state *st);

/* Work of the supports over an increment du * scale and of the tractions
 * since the last call (both by the trapezoidal rule between the remembered
 * forces and the state's, which are remembered next); *rr (may be NULL)
 * receives the sum of the squared forces on prescribed dofs. */
double fpm_support_work(const fpm_model *m, fpm_state *st, const double *du,
                        double scale, double *rr);

/* Reaction force: sum of f over the prescribed dofs of boundary condition
 * b, per component (3). */
void fpm_reaction(const fpm_model *m, const fpm_state *st, int b, double R[3]);

#endif
