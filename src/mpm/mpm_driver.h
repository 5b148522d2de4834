/* mpm_driver: a whole explicit MPM simulation of a scene: setup, the time
 * loop (mpm_solver) with output (results.h5/xdmf, history.csv,
 * summary.json) and progress through its observer, stage timings, and the
 * plan. */
#ifndef MPM_DRIVER_H
#define MPM_DRIVER_H

#include <stdbool.h>
#include <stdio.h>

#include "mpm_state.h"
#include "pm_scene.h"

typedef enum {
  MPM_STATUS_NOT_RUN = 0,
  MPM_STATUS_COMPLETED,     /* reached time.end / max_steps */
  MPM_STATUS_CONVERGED,     /* quasi-static residual below tolerance */
  MPM_STATUS_NOT_CONVERGED, /* quasi-static, ran out of time or steps */
  MPM_STATUS_UNSTABLE,      /* stopped on a numerical failure */
  MPM_STATUS_FAILED         /* other failure (I/O, ...) */
} mpm_status;

typedef struct {
  mpm_model *model;
  mpm_state *state;
  mpm_work *work;
  const pm_scene *scene;
  mpm_status status;
  double setup_wall, wall;
  double energy0; /* kinetic + strain + internal at t = 0 */
  double kinetic, strain, internal;
  double energy_error; /* (E - E0 + dissipated - external work) / E0 */
  double nrmse[3], nrmse_vector;
  char message[1024];
  double *scratch; /* output buffer, 9 per particle */
} mpm_run;

/* Model, initial state, workspace and output buffer of scene s (which
 * must outlive the run).  Failures as mpm_model_create; *out NULL then. */
pm_err mpm_run_create(const pm_scene *s, mpm_run **out);
/* Release a run and all it holds (NULL accepted). */
void mpm_run_destroy(mpm_run *r);

/* Run to time.end (or the quasi-static state), writing to out_dir when
 * non-NULL.  Returns PM_ERR_UNSTABLE on a numerical failure (the frames
 * before it are kept, summary.json says so), PM_ERR_NOT_CONVERGED when a
 * quasi-static run did not converge. */
pm_err mpm_run_go(mpm_run *r, const char *out_dir, bool quiet);

/* Print the pipeline, counts, per-particle memory, dt, steps and an
 * estimated run time (from timing a few steps: the state is advanced, so
 * a plan is not run after). */
pm_err mpm_run_plan(mpm_run *r, FILE *out);

/* "completed", "converged", ... (a static string). */
const char *mpm_status_name(mpm_status s);

/* Figures of the current fields: mean strain energy density of the
 * particles that store strain energy (sum V0 W / sum V0, J/m^3), largest
 * von Mises stress (Pa) and the particle it is at, smallest volume ratio J
 * and its particle. */
typedef struct {
  double mean_strain_energy_density;
  double max_von_mises;
  long max_von_mises_particle;
  double min_jacobian;
  long min_jacobian_particle;
} mpm_field_figures;
/* The figures of r's current fields into ff (uses r->scratch). */
void mpm_run_field_figures(const mpm_run *r, mpm_field_figures *ff);

/* Reaction force on boundary condition b (last step), N. */
void mpm_reaction(const mpm_run *r, int b, double R[3]);

#endif
