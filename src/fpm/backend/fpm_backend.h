/* fpm_backend: FPM as an entry of the backend table: the simulation of a
 * scene (mesh, subdomains, operators, state, stable step), its time loop
 * reporting to the run's observer, its fields, figures and plan. */
#ifndef FPM_BACKEND_H
#define FPM_BACKEND_H

#include <stdio.h>

#include "fpm_model.h"
#include "fpm_solver.h"
#include "fpm_static.h"
#include "gm_cells.h"
#include "gm_dual.h"
#include "pm_backend.h"
#include "pm_view.h"
#include "pm_progress.h"
#include "pm_scene.h"

extern const pm_backend fpm_backend;

/* Across ranks where no rank keeps the whole model (pm_view_whole_needed
 * false: frames in pieces, no checkpoints; fpm_view_sums.c): what rank 0
 * reports of the whole run, summed over the shares' own points (or their
 * extremes taken), where a gathered run reads the whole model. */
typedef struct {
  double reaction[PM_FIGURES_MAX_BCS][3]; /* of each condition */
  long ill_conditioned;          /* points whose support is past FPM_COND_MAX */
  double worst_condition;        /* the largest support condition */
  double nrmse[3], nrmse_vector; /* against the scene's reference field */
  /* the end's fields */
  double mean_sed, max_von_mises, max_von_mises_at[3];
  double end_min_jacobian, end_min_jacobian_at[3];
  double max_tension, max_tension_at[3];
  double cavitation_ratio, cavitation_ratio_at[3], cavitation_load;
  /* the whole model's counts (the summary's) */
  long cells, interfaces, facets, cdofs, qwide, qlinear, edge_cut;
} fpm_sums;

/* A prepared simulation.  Fields are read-only for callers. */
typedef struct {
  const pm_scene *scene; /* borrowed */
  gm_mesh *mesh;
  const gm_cells_builder *cells; /* the partition into subdomains */
  gm_dual *dual;
  fpm_model *model;
  fpm_state *state;
  double dt;            /* the step used, s */
  double dt_stable;     /* stable step of the scene's rule, s */
  double dt_paper;      /* bound of eqs. 24-26, s */
  double dt_spectral;   /* 2 / sqrt(lambda_max(M^-1 K)), s; 0 if not
                           measured */
  long dt_point;        /* point that sets the paper's bound */
  double support_speed; /* fpm_support_speed over the whole run, m/s, by
                           relaxation or damping; else 0 */
  double mean_edge;     /* mean mesh edge length, m */
  double far_size;      /* the mesh's size away from graded faces, m
                           (mesh_size unless refine.size_ratio) */
  double near_size;     /* its size on the graded faces, m; 0: uniform */
  pm_timers timers;
  int tm_mesh, tm_dual, tm_operators, tm_force, tm_update;
  int tm_assembly, tm_pcsetup, tm_linear; /* static solves only (else -1) */
  double setup_wall;                      /* mesh + dual + operators, s */
  double *scratch;                        /* 11 n: output buffer */
  /* the run */
  pm_status status;
  fpm_step_info last;      /* the last step's figures */
  double run_min_jacobian; /* smallest J seen at any step of the run */
  long run_min_jacobian_step;
  double run_max_energy_error; /* largest |energy-balance error| over the
                                  steps where it is checked */
  pm_view view;    /* the run's observer, and rank 0's view across ranks */
  double res0;     /* first residual after the ramps */
  double load_end; /* when every ramp has ended, s */
  fpm_static_report static_report; /* time.quasi_static.method: static */
  fpm_static_state static_state;   /* its load stepping (a checkpoint's) */
  bool resumed;                    /* the state came from a checkpoint */
  long first_step;                 /* the step this run started from */
  /* Across MPI ranks (fpm_par.h): this rank's share of the model and its
   * state, which it steps.  Only a rank that keeps the whole model
   * (pm_view_keeps_whole_for: rank 0, as the run's view, gathered into
   * where the run writes, unless the frames go in pieces and nothing else
   * reads the whole run) builds the whole model and state above; the
   * others hold no model but their share. */
  fpm_model *local_model;
  fpm_state *local_state;
  long n_whole;          /* the whole model's points (a rank without it lets the
                            whole cells, dual above, go once its share is made) */
  double ranks_costs[4]; /* summed over the ranks at the end: ghost bytes,
                            exchanges; the slowest's exchange and gather
                            seconds */
  /* A static solve across ranks: the share's load stepping (over its own
   * points' free dofs), which static_state above (the whole run's, in one
   * process's order) mirrors where the run writes, and the buffers of
   * that: 3 per own point, and on rank 0 3 per point of the whole model */
  fpm_static_state local_static;
  double *static_local, *static_whole;
  /* On every rank of a static solve: the whole run's prescribed dofs (3 per
   * point) and its free dofs, with which a rank that does not hold the
   * whole model reads a checkpoint into its share. */
  unsigned char *whole_fixed;
  long free_whole;
  bool scattered; /* the share has the checkpoint's state already */
  /* Whether a rank holds the whole model: one process, and across ranks
   * rank 0 unless no rank needs it (pm_view_whole_needed; the same on
   * every rank).  Without it rank 0 reports the sums over the shares. */
  bool whole;
  fpm_sums sums;
  /* Rank 0 without the whole model: every point's reference position in
   * one process's order, for results/mesh.h5 (let go when the run
   * starts). */
  double *mesh_x;
  /* Across ranks with frames in pieces (output.ranks: pieces, an explicit
   * run): each rank writes its own points of a frame from the share's
   * output buffer, 14 doubles per own point (position, stress and its
   * invariants). */
  bool pieces;
  double *share_scratch;
  long *own_nbr; /* without the whole model: the own points' supports
                    (the share's entries, as the conditioning reads them) */
} fpm_sim;

/* Mesh the scene's domain, build subdomains, operators and state, and pick
 * dt: time.dt if set, else dt_safety times the stable step of
 * time.dt_rule (the paper's bound, or the measured spectral radius). */
pm_err fpm_sim_create(const pm_scene *s, fpm_sim **out);
void fpm_sim_destroy(fpm_sim *sim);

/* Measure dt_spectral (power iteration) if not done yet. */
void fpm_sim_measure_spectrum(fpm_sim *sim);

/* Number of points whose support, in the current configuration, has a
 * moment matrix with condition number above FPM_COND_MAX. */
long fpm_sim_conditioning(const fpm_sim *sim, double *worst, long *worst_point);

#endif
