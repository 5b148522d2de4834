/* pm_view: rank 0's view of a run shared among MPI ranks, one for every
 * backend.  Each rank steps its share of the run; rank 0 also keeps the
 * whole model and state (its view), into which the shares are gathered
 * where the run writes (frames, history, checkpoints) and where it ends,
 * so that a run across ranks writes what one process writes.  Where
 * nothing reads the whole run (pm_view_whole_needed) no rank keeps it, and
 * the backend's gather brings rank 0 the figures it reports as sums over
 * the shares instead.  On one process the run is its own view and every
 * call is the plain one. */
#ifndef PM_VIEW_H
#define PM_VIEW_H

#include <stdbool.h>

#include "pm_backend.h"
#include "pm_error.h"
#include "pm_files.h"

/* The fields a frame has at most. */
#define PM_VIEW_FIELDS 16

/* The frame the ranks last wrote in pieces (output.ranks: pieces): each
 * rank's count of points and the fields' names and sizes (their data are
 * no longer valid), for rank 0's frame file joining the pieces. */
typedef struct pm_view_pieces {
  int n;        /* pieces: the ranks */
  long *counts; /* [n], on rank 0 */
  int n_fields;
  pm_field fields[PM_VIEW_FIELDS];
} pm_view_pieces;

typedef struct pm_view {
  bool ranks; /* the run is shared among ranks */
  void *ctx;  /* the backend's simulation, passed to the callbacks */
  /* The shares' state into rank 0's view, with the figures every rank
   * shares (collective; called on every rank). */
  pm_err (*gather)(void *ctx);
  /* On a rank other than 0: let the whole model and state go (the share
   * is all that rank runs). */
  void (*release)(void *ctx);
  /* Frames in pieces (may be NULL: gathered): this rank's share of frame
   * `frame` after r's step written as piece pm_par_rank() into the results
   * folder dir (pm_results_write_piece); its points' count and the
   * fields (at most PM_VIEW_FIELDS) into *n, *n_fields, fields. */
  pm_err (*piece)(void *ctx, const char *dir, long frame,
                  const pm_step_report *r, long *n, int *n_fields,
                  pm_field *fields);
  /* Checkpoints in pieces (may be NULL: the whole state, gathered): this
   * rank's share of checkpoint id written as piece pm_par_rank() into
   * the output folder dir (pm_ckpt_create_piece), and what the index
   * records of it: its count of points and checksum into *count and *sum,
   * PM_VIEW_CKPT_VALUES doubles of the backend's own into values. */
  pm_err (*ckpt_piece)(void *ctx, const char *dir, long id, long *count,
                       unsigned long long *sum, double *values);
  const pm_observer *obs; /* the run's, while it runs (rank 0 reports) */
  /* Across ranks with output.ranks: pieces and a results folder (rank 0's,
   * passed to every rank at the start): the folder and the last frame's
   * pieces. */
  bool in_pieces;
  bool ending; /* the run has ended: gather's last call, for the figures */
  char dir[PM_PATH_MAX + 1];
  pm_view_pieces pieces;
  /* Rank 0 while its observer reads the view in pieces: the other ranks
   * wait for a checkpoint's pieces (pm_view_checkpoint_pieces). */
  bool serving;
  /* The last checkpoint's pieces (on rank 0): per rank its count and
   * checksum (2 longs), and its PM_VIEW_CKPT_VALUES doubles. */
  long *ckpt_counts;
  double *ckpt_values;
} pm_view;

/* Doubles a checkpoint's piece records in its index (the backend's). */
#define PM_VIEW_CKPT_VALUES 128

/* Whether this rank holds the whole model and state through a run: across
 * ranks, rank 0 while frames, checkpoints and the end's figures are
 * gathered into its view.  Setup builds the whole model only where this is
 * true (and a share everywhere across ranks).  For a backend that writes
 * no frames in pieces (pm_backend.pieces NULL); otherwise
 * pm_view_keeps_whole_for. */
bool pm_view_keeps_whole(void);

/* Whether a run of scene s across ranks needs the whole model on rank 0:
 * unless its frames go in pieces (output.ranks: pieces, a backend that
 * writes them) and nothing else reads the whole run: checkpoints
 * (output.checkpoint) only where the backend writes them in pieces too
 * (pm_backend.ckpt_pieces), and a reference field only where the backend
 * sums its errors over the shares (pm_backend.errors).  Without it the
 * history rows and the end's figures come from reductions over the shares
 * (pm_view.gather then reduces), and checkpoints (a signal's too) are
 * written in pieces.  The same on every rank. */
bool pm_view_whole_needed(const pm_scene *s);

/* pm_view_keeps_whole for scene s: rank 0 across ranks where
 * pm_view_whole_needed(s). */
bool pm_view_keeps_whole_for(const pm_scene *s);

/* The run starts with observer obs (which may be NULL): across ranks, the
 * ranks other than 0 release their view. */
void pm_view_start(pm_view *v, const pm_observer *obs);

/* Then, for a backend that writes frames in pieces (v->piece): across
 * ranks with output.ranks: pieces in scene s, every rank learns rank 0's
 * results folder (from obs there) and the frames go in pieces
 * (collective).  Fails only for want of memory (agreed). */
pm_err pm_view_start_pieces(pm_view *v, const pm_scene *s);

/* Across ranks, the ranks other than 0 let their view go (a plan, or the
 * start of a run).  Nothing on one process or on rank 0. */
void pm_view_release(pm_view *v);

/* Report step r: on one process to the observer; across ranks rank 0
 * reports, with the shares gathered into its view where the observer asks
 * for them (pm_observer_share; collective).  The observer's failure. */
pm_err pm_view_step(pm_view *v, const pm_step_report *r, bool frame);

/* A signal stopped a load step inside its solve (e: PM_ERR_INTERRUPTED,
 * on every rank): the last converged step r, which the state still holds,
 * goes to the observer once more, which (seeing the signal) writes its
 * frame, dropped on resume, and its checkpoint, collectively, and ends the
 * run; the message then says where the solve was stopped.  Any other e
 * comes back as it is. */
pm_err pm_view_stopped_inside(pm_view *v, const pm_step_report *r, pm_err e);

/* The run ended with e: across ranks, the state it ended in (a failure's
 * too) gathered into rank 0's view for the figures (collective).  e, or the
 * gather's failure where e is PM_SUCCESS.  The observer is let go. */
pm_err pm_view_end(pm_view *v, pm_err e);

/* On rank 0, from the backend's checkpoint writer while its observer
 * writes a checkpoint in pieces (the ranks' frames in pieces, and
 * v->ckpt_piece): every rank writes its piece of checkpoint id into the
 * output folder (collective with the other ranks, which wait in
 * pm_view_step), then v->ckpt_counts and v->ckpt_values hold every
 * piece's record.  The failure of any rank, agreed; PM_ERR_ARG where the
 * run writes no checkpoint in pieces. */
pm_err pm_view_checkpoint_pieces(pm_view *v, long id);

/* The frame the ranks last wrote in pieces, or NULL where frames are
 * written whole (one process, output.ranks: gather, no results). */
const pm_view_pieces *pm_view_frame_pieces(const pm_view *v);

#endif
