/* fpm_driver: a whole FPM simulation of a scene: meshing, subdomains,
 * operators, the time loop, results, history, summary, and the plan. */
#ifndef FPM_DRIVER_H
#define FPM_DRIVER_H

#include <stdio.h>

#include "fpm_model.h"
#include "fpm_solver.h"
#include "gm_dual.h"
#include "pm_progress.h"
#include "pm_scene.h"

typedef enum {
  FPM_STATUS_NOT_RUN = 0,
  FPM_STATUS_COMPLETED,     /* reached time.end / max_steps (dynamics) */
  FPM_STATUS_CONVERGED,     /* quasi-static residual below tolerance */
  FPM_STATUS_NOT_CONVERGED, /* quasi-static, ran out of time or steps */
  FPM_STATUS_UNSTABLE,      /* stopped on a numerical failure */
  FPM_STATUS_FAILED         /* other failure (I/O, ...) */
} fpm_status;

/* A prepared simulation.  Fields are read-only for callers. */
typedef struct {
  const pm_scene *scene; /* borrowed */
  gm_mesh *mesh;
  gm_dual *dual;
  fpm_model *model;
  fpm_state *state;
  double dt;          /* the step used, s */
  double dt_stable;   /* stable step of the scene's rule, s */
  double dt_paper;    /* bound of eqs. 24-26, s */
  double dt_spectral; /* 2 / sqrt(lambda_max(M^-1 K)), s; 0 if not
                         measured */
  long dt_point;      /* point that sets the paper's bound */
  double mean_edge;   /* mean mesh edge length, m */
  pm_timers timers;
  int tm_mesh, tm_dual, tm_operators, tm_force, tm_update, tm_output;
  /* after a run */
  fpm_status status;
  fpm_step_info last;
  double wall;             /* run wall time (time loop + output), s */
  double setup_wall;       /* mesh + dual + operators, s */
  int n_ref;               /* reference components compared */
  double nrmse[3];         /* eq. 28 per component, NaN if no reference */
  double nrmse_vector;     /* of the whole reference field (one component:
                              that component's) */
  double *scratch;         /* 9 n: output and metrics buffer */
  double *ref;             /* 3 n: reference displacement, or NULL */
  bool ref_time_dependent; /* some reference component uses t */
  char message[1024];      /* failure message, if any */
  double run_min_jacobian; /* smallest J seen at any step of the run */
  long run_min_jacobian_step;
  double run_max_energy_error; /* largest |energy-balance error| over the
                                  steps where it is checked */
} fpm_sim;

/* Figures of the current fields. */
typedef struct {
  double mean_strain_energy_density; /* sum V W / sum V, J/m^3 */
  double max_von_mises;              /* of the Cauchy stress, Pa */
  long max_von_mises_point;
  double min_jacobian;
  long min_jacobian_point;
  long ill_conditioned; /* supports above the condition bound, deformed */
  double max_condition;
  long max_condition_point;
} fpm_field_figures;

/* Mesh the scene's domain, build subdomains, operators and state, and pick
 * dt: time.dt if set, else dt_safety times the stable step of
 * time.dt_rule (the paper's bound, or the measured spectral radius). */
pm_err fpm_sim_create(const pm_scene *s, fpm_sim **out);
void fpm_sim_destroy(fpm_sim *sim);

/* Run to the end (or to the quasi-static state).  With out_dir non-NULL,
 * writes results.h5 + results.xdmf, history.csv and summary.json there
 * (each atomically); with quiet false, shows a progress line on a terminal
 * and prints the stage timing table to stderr.  Returns PM_ERR_UNSTABLE on a
 * numerical failure (outputs keep the frames up to it and summary.json says
 * so) and PM_ERR_NOT_CONVERGED if a quasi-static run did not converge. */
pm_err fpm_sim_run(fpm_sim *sim, const char *out_dir, bool quiet);

/* Print the plan: pipeline, counts, dt, steps, memory and an estimated run
 * time from timing a few force evaluations. */
pm_err fpm_sim_plan(fpm_sim *sim, FILE *out);

/* Measure dt_spectral (power iteration) if not done yet. */
void fpm_sim_measure_spectrum(fpm_sim *sim);

const char *fpm_status_name(fpm_status s);

/* Field figures of the current state (uses sim->scratch). */
void fpm_sim_field_figures(fpm_sim *sim, fpm_field_figures *ff);

/* Number of points whose support, in the current configuration, has a
 * moment matrix with condition number above FPM_COND_MAX. */
long fpm_sim_conditioning(const fpm_sim *sim, double *worst, long *worst_point);

#endif
