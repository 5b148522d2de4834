/* pm_backend: the interface every method implements (FPM, MPM, and next the
 * implicit MPM), its figures with one meaning for every method, and the
 * registry the program fills.  The command line and the scene loader know a
 * method only through its entry. */
#ifndef PM_BACKEND_H
#define PM_BACKEND_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "pm_checkpoint.h"
#include "pm_error.h"
#include "pm_files.h"
#include "pm_keys.h"
#include "pm_output.h"
#include "pm_progress.h"
#include "pm_scene.h"

typedef enum {
  PM_STATUS_NOT_RUN = 0,
  PM_STATUS_COMPLETED,     /* reached time.end or time.max_steps */
  PM_STATUS_CONVERGED,     /* quasi-static: residual below the tolerance */
  PM_STATUS_NOT_CONVERGED, /* quasi-static: ran out of time or steps */
  PM_STATUS_UNSTABLE,      /* stopped on a numerical failure */
  PM_STATUS_FAILED,        /* any other failure (I/O, memory) */
  PM_STATUS_INTERRUPTED    /* stopped by SIGINT or SIGTERM after a step */
} pm_status;

/* "completed", "converged", "not-converged", "unstable", "failed",
 * "interrupted", "not-run". */
const char *pm_status_name(pm_status s);

/* The status of a solve by load steps that returned e: converged,
 * unstable, not-converged, or failed. */
pm_status pm_static_status(pm_err e);

/* A backend's own top-level scene section ("fpm:", "mpm:"): its keys, each
 * with its default, into an options struct of `size` bytes that the loader
 * allocates (zeroed), fills and keeps in the scene. */
typedef struct {
  const char *name;
  const pm_key *keys;
  size_t size;
  /* Checks across the section's keys once the shared vocabulary is read
   * (may be NULL); fails with pm_scene_fail naming the key. */
  pm_err (*check)(const struct pm_scene *s, void *opts);
} pm_section;

/* Boundary conditions whose reactions a run reports. */
#define PM_FIGURES_MAX_BCS 64

/* Support speeds, as fractions of the slowest shear wave speed, in a
 * quasi-static run by relaxation or damping: past the first a failure
 * during the ramp is put down to the ramp (and plan says so); the second
 * is the speed the advice aims at (F3 200% at 13289 points: a point
 * inverted during the ramp at 0.37 and passed it at 0.19). */
#define PM_QS_SUPPORT_SPEED_FAST 0.25
#define PM_QS_SUPPORT_SPEED_HELD 0.2

/* What a run reports.  Every figure has one meaning for every method: in
 * summary.json, in history.csv and in convergence tables. */
typedef struct {
  pm_status status;
  int dim;
  long points; /* FPM points, MPM particles */
  long steps;
  double time;      /* simulated time reached, s */
  double h;         /* resolution: FPM mean edge length, MPM cell size, m */
  double dt;        /* the last step taken, s */
  double dt_stable; /* the method's stable step at setup, without
                       time.dt_safety, s */
  double residual;  /* quasi-static: out-of-balance force over the
                       reactions (0 in dynamics) */
  /* Quasi-static by relaxation or damping: the fastest a prescribed
   * motion moves while the ramps run, m/s (0 otherwise, or not known; FPM
   * gives it), against pm_scene_shear_wave_speed. */
  double support_speed;
  /* Energies, J (per unit thickness in 2D). */
  double kinetic, strain, internal, interface;
  double external_work, dissipated;
  double energy0;          /* kinetic + strain + internal at t = 0 */
  double energy_error;     /* pm_energy_error of these */
  double max_energy_error; /* largest |energy_error| where it was checked */
  /* Smallest volume ratio J over the whole run, and its step. */
  double min_jacobian;
  long min_jacobian_step;
  /* Fields at the end. */
  double mean_sed;      /* sum V0 W / sum V0 over the solids, J/m^3 */
  double max_von_mises; /* of the Cauchy stress, Pa */
  double max_von_mises_at[3];
  double end_min_jacobian; /* smallest J at the end, and where */
  double end_min_jacobian_at[3];
  /* Where a backend gives them (tension true): the solids' largest
   * hydrostatic tension tr(sigma)/3 at the end, Pa, and where; the largest
   * ratio of a point's tension to its material's cavitation load
   * (pm_cavitation_load), where, and that load (0: no material has one). */
  bool tension;
  double max_tension, max_tension_at[3];
  double cavitation_ratio, cavitation_ratio_at[3], cavitation_load;
  /* Reactions of each boundary condition (N; per unit thickness in 2D):
   * the force the supports apply on the body. */
  double reaction[PM_FIGURES_MAX_BCS][3];
  /* Cost. */
  double setup_seconds; /* discretization and operators */
  double wall_seconds;  /* the time loop with output */
  double step_seconds;  /* the step's stages alone (throughput) */
  size_t memory_bytes;  /* state, operators and workspace */
} pm_figures;

/* Energy-balance error: (E - E0 + D - W) / max(|E0|, |W|), with E the
 * energy held, D the energy dissipated and W the external work; over E + D
 * when both E0 and W are 0 (energy from nothing); 0 when nothing moves. */
double pm_energy_error(double E0, double E, double D, double W);

/* What a backend reports after each step of its time loop. */
typedef struct {
  long step;
  double t;
  double residual; /* quasi-static residual (0 in dynamics) */
  double progress; /* fraction of the run done, in [0, 1] */
  bool last;       /* the run's last step: it ends after it */
} pm_step_report;

/* The run's observer: called after every step (frame false) and on frame
 * steps and the last step (frame true).  A non-success return stops the
 * run with that error. */
struct pm_view_pieces;

typedef struct {
  void *ctx;
  pm_err (*step)(void *ctx, const pm_step_report *r, bool frame);
  /* Whether step, called next with the same report, will read the
   * simulation (a frame, a history row, a checkpoint, the last frame of a
   * signal), which it then decides for good: across ranks, the state is
   * gathered only then.  May be NULL (frame steps only). */
  bool (*wants)(void *ctx, const pm_step_report *r, bool frame);
  /* The results folder (NULL: none), and the index of the frame that
   * step, called next with the same report, writes (-1: none), decided
   * for good: across ranks with frames in pieces, every rank writes its
   * piece of it first.  frame_index may be NULL (frames written whole). */
  const char *dir;
  long (*frame_index)(void *ctx, const pm_step_report *r, bool frame);
} pm_observer;

/* A step of a run across MPI ranks (pm_par.h; collective): rank 0, which
 * holds the run's observer obs (NULL on the others, or none) and the
 * step's report r, asks the observer whether it will read the simulation;
 * if so every rank calls gather(ctx), which brings the state rank 0 reads
 * into its view; then rank 0 reports.  Every rank returns the observer's
 * answer, or gather's failure (which gather agrees on).  On one process:
 * gather where the observer wants it, then the report. */
pm_err pm_observer_share(const pm_observer *obs, const pm_step_report *r,
                         bool frame, pm_err (*gather)(void *ctx), void *ctx);

/* Columns of a backend's own history (beyond the shared ones). */
#define PM_HISTORY_MAX 128

typedef struct pm_backend {
  const char *method;        /* scene name: "fpm" */
  const char *description;   /* one line: "explicit total-Lagrangian
                                Fragile Points Method" */
  const pm_section *section; /* its scene section, or NULL */
  double dt_safety;          /* its default time.dt_safety */
  bool ranks;                /* runs across MPI ranks (pm_par.h): the scene
                                loader refuses it under mpirun otherwise */
  /* Refuse what this method cannot honour in a scene that names it
   * (fluids in FPM, tractions in MPM, ...), naming the key through
   * pm_scene_fail.  Called by the loader. */
  pm_err (*check)(const struct pm_scene *s);
  /* Set up the discretization, operators and state of a loaded scene
   * (borrowed until destroy).  *sim is the backend's own. */
  pm_err (*create)(const struct pm_scene *s, void **sim);
  /* The bytes create and run will hold (operators, state, workspace, and
   * the mesh or grid they are built from), estimated from the scene alone
   * without allocating: an upper bound within a factor of about 2.  Sets
   * *points to the points (particles) it counts.  May be NULL (no
   * estimate); the run driver refuses scenes estimated past the memory
   * available (pm_memory). */
  size_t (*estimate_bytes)(const struct pm_scene *s, long *points);
  /* Across ranks (pm_memory_rank_estimate): the layers of ghost points
   * around a rank's share (NULL: every rank may hold the whole run), and
   * whether the setup builds the whole model on every rank before each
   * takes its share (else only where pm_view_keeps_whole). */
  double (*ghost_layers)(const struct pm_scene *s);
  bool setup_whole;
  /* The part of estimate_bytes the rank that meshes (rank 0) holds whole
   * at setup even where it keeps no whole model (FPM: the mesh and its
   * cells; the other ranks hold their part of it), or NULL (none). */
  size_t (*geometry_bytes)(const struct pm_scene *s);
  /* The layers of the part of the geometry a rank that does not mesh
   * receives and builds its share from, held with the share at setup
   * (FPM: its ghosts' rings and two more), or NULL (none). */
  double (*part_layers)(const struct pm_scene *s);
  void (*destroy)(void *sim);
  /* Print the pipeline, counts, time step, steps, memory and an estimated
   * run time, without running. */
  pm_err (*plan)(void *sim, FILE *out);
  /* Run the time loop from the current state to the end (or the
   * quasi-static state), reporting every step to obs, as a frame every
   * output.every steps and at the last step.  The initial state is step 0,
   * reported as a frame; a state read from a checkpoint is not reported
   * again, and the steps that follow are those the first run would have
   * taken, bit for bit on the same thread count.  Returns
   * PM_ERR_UNSTABLE (message: step, time, point, position, cause) on a
   * numerical failure and PM_SUCCESS otherwise (not converging is a
   * status, see figures). */
  pm_err (*run)(void *sim, const pm_observer *obs);
  /* The points the results are written on (pm_points, pm_output.h). */
  void (*points)(void *sim, pm_points *p);
  /* The fields of the current state (PM_FIELD_* mask wanted; a backend may
   * add its own, e.g. fluid pressure) into out[0..max); returns how many.
   * The data stay valid until the next call. */
  int (*fields)(void *sim, unsigned wanted, pm_field *out, int max);
  /* The current displacement of every point, [n][3], borrowed. */
  const double *(*displacement)(void *sim);
  /* Figures of the current state and run.  With fields false, only what is
   * cheap (energies, residual, reactions, J over the run, step counts):
   * every frame's history row; with true, the field figures too. */
  void (*figures)(void *sim, pm_figures *f, bool fields);
  /* The backend's own history columns: names (borrowed) into names[0..max),
   * returns how many; and their values now. */
  int (*history_names)(void *sim, const char **names, int max);
  void (*history_values)(void *sim, double *values);
  /* Its own members of summary.json, after the shared ones (may be
   * NULL). */
  pm_err (*summary)(void *sim, pm_json *j);
  /* Its stage timers (printed after a run, summed in summary.json). */
  const pm_timers *(*timers)(void *sim);
  /* The state a resumed run needs and what the run reports over all its
   * steps, as checkpoint items (pm_checkpoint.h): the same items in the
   * same order for a writer (between steps) and a reader (after create,
   * before run).  Fails with PM_ERR_ARG naming what cannot be
   * checkpointed.  NULL: the method has no checkpoints. */
  pm_err (*checkpoint)(void *sim, pm_ckpt *ck);
  /* Across ranks with output.ranks: pieces: the frame its ranks last wrote
   * in pieces (pm_view.h), which the driver joins, or NULL where it writes
   * a frame whole (one process).  NULL: frames are always written whole
   * (the loader refuses pieces across ranks). */
  const struct pm_view_pieces *(*pieces)(void *sim);
  /* Whether a run of scene s across ranks with frames in pieces writes its
   * checkpoints in pieces too (pm_view.ckpt_piece), so that no rank keeps
   * the whole model for them (pm_view_whole_needed).  NULL: never. */
  bool (*ckpt_pieces)(const pm_scene *s);
  /* Whether frames of scene s across ranks go in pieces where the scene
   * leaves output.ranks to the method (auto).  NULL: wherever the method
   * writes pieces. */
  bool (*pieces_apply)(const pm_scene *s);
  /* Across ranks without the whole model (pm_view_whole_needed false):
   * the NRMSE of each component of the scene's reference field (NAN where
   * it has none) and of the field (as pm_run_compute_errors takes them)
   * into nrmse and *vector, from the sums over the shares at the last
   * gather (pm_view), and true; false where the driver computes them from
   * the whole displacement.  NULL: a reference field keeps the whole model
   * on rank 0. */
  bool (*errors)(void *sim, double nrmse[3], double *vector);
} pm_backend;

/* ---- registry ------------------------------------------------------------ */

/* Register b (idempotent; at most PM_BACKENDS_MAX).  The program registers
 * its backends before loading a scene. */
#define PM_BACKENDS_MAX PM_SCENE_SECTIONS
pm_err pm_backend_register(const pm_backend *b);
int pm_backend_count(void);
const pm_backend *pm_backend_at(int k);
/* The backend of a method name, or NULL. */
const pm_backend *pm_backend_find(const char *method);
/* The registered methods' names, comma-separated, into buf. */
void pm_backend_names(char *buf, size_t size);

#endif
