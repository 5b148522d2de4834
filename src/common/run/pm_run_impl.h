/* pm_run_impl: the driver's state during a run and the functions its files
 * share (history, observer, checkpoint, summary, resume); not for callers
 * of pm_run.h. */
#ifndef PM_RUN_IMPL_H
#define PM_RUN_IMPL_H

#include <signal.h>
#include <stdbool.h>

#include "pm_output.h"
#include "pm_progress.h"
#include "pm_run.h"

#define RUN_COLS (32 + PM_HISTORY_MAX + 3 * PM_FIGURES_MAX_BCS)

typedef struct {
  const pm_scene *s;
  const pm_backend *be;
  void *sim;
  pm_results *results;
  pm_history *history;
  pm_progress progress;
  bool show_progress;
  pm_points pts;
  int n_cols, n_own;
  const char *names[RUN_COLS];
  char names_buf[RUN_COLS][64];
  int react_bc[RUN_COLS], react_comp[RUN_COLS];
  double row[RUN_COLS];
  double *ref; /* 3 n reference displacement, or NULL */
  bool ref_time;
  double t_start;
  pm_timers out_timer; /* the stages this driver times */
  int tm_output, tm_checkpoint;
  pm_outcome *o;
  /* output folder, checkpoints and resuming */
  const char *out_dir;
  pm_outdir *outdir;
  long history_rows;
  long ckpt_every;       /* steps (0: never) */
  double ckpt_seconds;   /* wall time (0: never) */
  double ckpt_last_wall; /* when the last one was written */
  long ckpt_step;        /* the step of the last one (-1: none) */
  long ckpt_count;       /* checkpoints written by this process */
  long resumes;          /* how often this run was resumed */
  long resumed_from;     /* the step it was last resumed from (0: none) */
  char ckpt_note[512];   /* why no checkpoint was written, if one failed */
  bool extra_frame;      /* the last frame is a signal's, off the schedule */
  long last_step;        /* the last step observed (-1: none yet) */
  /* what wants decided for the next step: the signal it ends on (0: none)
   * and whether a checkpoint is written after it */
  bool decided;
  int decided_sig;
  bool decided_ckpt;
  const pm_observer *also; /* the caller's observer, after the driver's */
} pm_run_ctx;

/* The driver's items of a checkpoint, before the backend's: what the run
 * is (program version, method, scene file, its text and the overrides) and
 * how far its outputs go.  Reading fills h (strings malloc'd). */
typedef struct {
  char *version, *method, *scene_path, *scene_text, *overrides;
  long frames, history_rows, threads, resumes, step;
  double wall_seconds, output_seconds, checkpoint_seconds;
} pm_run_header;

/* What a resumed run starts from: the checkpoint being read (positioned
 * after the driver's items) and its header. */
typedef struct {
  pm_ckpt *ck;
  pm_run_header h;
} pm_run_resume_info;

/* ---- pm_run_history.c ---- */

/* c's history columns: the shared ones, the backend's, the reactions of
 * the prescribed conditions and the errors against the reference.
 * PM_ERR_SCENE for too many conditions. */
pm_err pm_run_setup_columns(pm_run_ctx *c);

/* c->ref = the reference field at time t (serial: an expression is not
 * thread-safe). */
void pm_run_fill_reference(pm_run_ctx *c, double t);

/* c->o's NRMSE (eq. 28) of each reference component and of the field at
 * time t (NaN without a reference). */
void pm_run_compute_errors(pm_run_ctx *c, double t);

/* Writes the frame of r's step to results.h5 and its row to history.csv. */
pm_err pm_run_write_frame(pm_run_ctx *c, const pm_step_report *r);

/* ---- pm_run_observe.c ---- */

/* Catch SIGINT and SIGTERM once each (old: the handlers before), and give
 * the old handlers back. */
void pm_run_catch_interrupts(struct sigaction old[2]);
void pm_run_release_interrupts(const struct sigaction old[2]);

/* The observer of a backend's loop (ctx = the driver's state): whether it
 * wants the state after r's step, and what it does with it (progress,
 * frame, checkpoint; PM_ERR_INTERRUPTED after a signal). */
bool pm_run_wants(void *ctx, const pm_step_report *r, bool frame);
pm_err pm_run_observe(void *ctx, const pm_step_report *r, bool frame);
/* The index of the frame pm_run_observe writes after r's step, or -1. */
long pm_run_frame_index(void *ctx, const pm_step_report *r, bool frame);

/* After the backend's loop ended with run_err: when a signal stopped it
 * inside a step (a linear solve, a Newton iteration), the checkpoint of the
 * last step observed (the last converged state, which the backend holds)
 * and the message saying so; returns run_err. */
pm_err pm_run_interrupted_inside(pm_run_ctx *c, pm_err run_err);

/* PM_ERR_INTERRUPTED (o's status so) once a run of this process was
 * interrupted; o is cleared (status failed) either way. */
pm_err pm_run_check_not_interrupted(pm_outcome *o);

/* ---- pm_run_checkpoint.c ---- */

/* A checkpoint is due after r's step (not the initial state). */
bool pm_run_checkpoint_due(const pm_run_ctx *c, const pm_step_report *r);

/* Writes OUT/checkpoint.h5 of the state after step (replacing the older
 * one).  PM_ERR_ARG when the method cannot checkpoint this scene. */
pm_err pm_run_write_checkpoint(pm_run_ctx *c, long step);

/* Reads (or, with h filled, writes) the driver's items of ck into h. */
pm_err pm_run_header_items(pm_ckpt *ck, pm_run_header *h);
void pm_run_header_free(pm_run_header *h);

/* Reads the backend's items of rs's checkpoint and checks it whole. */
pm_err pm_run_restore(pm_run_ctx *c, pm_run_resume_info *rs);

/* ---- pm_run_summary.c ---- */

/* OUT/summary.json: while running, status "running" and who runs it;
 * otherwise the outcome, figures, cost and accuracy. */
pm_err pm_run_write_summary(pm_run_ctx *c, bool running);

/* c->o's status and message from the loop's error and the figures, and
 * the loaded face's reaction. */
void pm_run_conclude(pm_run_ctx *c, pm_err run_err);

/* The outcome and the stage timings on stderr. */
void pm_run_report(pm_run_ctx *c);

/* ---- pm_run.c ---- */

/* Runs sim on rank 0 (or one process): outputs in out_dir (NULL: none),
 * outdir the folder claimed by the caller (taken over) or NULL, rs the
 * checkpoint it resumes from or NULL, also the caller's observer or
 * NULL. */
pm_err pm_run_root(const pm_scene *s, void *sim, const char *out_dir,
                   unsigned flags, pm_outcome *o, pm_outdir **outdir,
                   pm_run_resume_info *rs, const pm_observer *also);

/* A rank other than 0 of a run across ranks: steps its share. */
pm_err pm_run_worker(const pm_scene *s, void *sim, pm_outcome *o);

#endif
