/* pm_view: rank 0's view of a run across ranks (pm_view.h). */
#include "pm_view.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_checkpoint.h"
#include "pm_par.h"

bool pm_view_keeps_whole(void) { return pm_par_active() && pm_par_root(); }

bool pm_view_whole_needed(const pm_scene *s) {
  const bool pieces =
      s->output.ranks == PM_OUTPUT_PIECES && s->backend && s->backend->pieces;
  const bool ckpt =
      s->output.checkpoint.every > 0 || s->output.checkpoint.minutes > 0;
  const bool ckpt_pieces =
      pieces && s->backend->ckpt_pieces && s->backend->ckpt_pieces(s);
  return !pieces || (ckpt && !ckpt_pieces) ||
         (s->reference_mask && !s->backend->errors);
}

bool pm_view_keeps_whole_for(const pm_scene *s) {
  return pm_view_keeps_whole() && pm_view_whole_needed(s);
}

void pm_view_release(pm_view *v) {
  if (v->ranks && !pm_par_root() && v->release) v->release(v->ctx);
}

void pm_view_start(pm_view *v, const pm_observer *obs) {
  pm_view_release(v);
  v->obs = obs;
}

pm_err pm_view_start_pieces(pm_view *v, const pm_scene *s) {
  if (!v->ranks || !v->piece || s->output.ranks != PM_OUTPUT_PIECES)
    return PM_SUCCESS;
  const pm_observer *obs = pm_par_root() ? v->obs : NULL;
  int on = obs && obs->dir && obs->frame_index;
  if (on) snprintf(v->dir, sizeof v->dir, "%s", obs->dir);
  pm_par_bcast(&on, sizeof on);
  if (!on) return PM_SUCCESS; /* no results folder: no frames */
  pm_par_bcast(v->dir, sizeof v->dir);
  v->pieces.n = pm_par_size();
  pm_err e = PM_ALLOC(v->pieces.counts, v->pieces.n, "pieces");
  if (!e && v->ckpt_piece)
    e = PM_ALLOC(v->ckpt_counts, 2 * v->pieces.n, "checkpoint pieces");
  if (!e && v->ckpt_piece)
    e = PM_ALLOC(v->ckpt_values, PM_VIEW_CKPT_VALUES * v->pieces.n,
                 "checkpoint pieces");
  PM_CALL(pm_par_agree(e));
  v->in_pieces = true;
  return PM_SUCCESS;
}

/* Every rank's piece of checkpoint id, and their records on rank 0
 * (collective). */
static pm_err checkpoint_round(pm_view *v, long id) {
  const int n = pm_par_size(), me = pm_par_rank();
  long *counts = v->ckpt_counts;
  double *values = v->ckpt_values;
  memset(counts, 0, 2 * sizeof *counts * (size_t)n);
  memset(values, 0, PM_VIEW_CKPT_VALUES * sizeof *values * (size_t)n);
  unsigned long long sum = 0;
  PM_CALL(pm_par_agree(v->ckpt_piece(v->ctx, v->dir, id, &counts[2 * me], &sum,
                                     values + PM_VIEW_CKPT_VALUES * me)));
  /* (a rank's row is its own: the sums add zeros to it) */
  counts[2 * me + 1] = (long)sum;
  pm_par_sum_long(counts, 2 * n);
  pm_par_sum(values, PM_VIEW_CKPT_VALUES * n);
  return PM_SUCCESS;
}

/* A rank other than 0 while rank 0's observer reads the view: each
 * checkpoint it writes in pieces, until it says it is done. */
static void serve(pm_view *v) {
  for (;;) {
    long cmd[2] = {0, 0}; /* done (0) or a checkpoint (1), its id */
    pm_par_bcast(cmd, sizeof cmd);
    if (!cmd[0]) return;
    pm_error_clear();
    if (cmd[0] == 1)                     /* (2: rank 0 could not start it) */
      (void)checkpoint_round(v, cmd[1]); /* (rank 0 reports a failure) */
  }
}

pm_err pm_view_checkpoint_pieces(pm_view *v, long id) {
  PM_CHECK(v->serving && v->ckpt_piece && v->ckpt_counts, PM_ERR_ARG,
           "a run across ranks writes its checkpoint in pieces only where "
           "its frames go in pieces");
  pm_err e = pm_ckpt_pieces_folder(v->dir);
  long cmd[2] = {e ? 2 : 1, id};
  pm_par_bcast(cmd, sizeof cmd);
  PM_CALL(e);
  return checkpoint_round(v, id);
}

/* A step with frames in pieces: rank 0's observer says whether it reads
 * the view (a history row, a checkpoint) and which frame it writes; every
 * rank writes its piece of that frame, rank 0 learns their counts, and
 * then reports (collective). */
static pm_err step_pieces(pm_view *v, const pm_step_report *r, bool frame) {
  const pm_observer *obs = pm_par_root() ? v->obs : NULL;
  long at[2] = {frame, -1}; /* wants the view, the frame's index */
  if (obs) {
    at[0] = frame || (obs->wants && obs->wants(obs->ctx, r, frame));
    at[1] = obs->frame_index(obs->ctx, r, frame);
  }
  pm_par_bcast(at, sizeof at);
  if (at[0]) PM_CALL(v->gather(v->ctx));
  if (at[1] >= 0) {
    pm_view_pieces *pc = &v->pieces;
    long n = 0;
    PM_CALL(pm_par_agree(
        v->piece(v->ctx, v->dir, at[1], r, &n, &pc->n_fields, pc->fields)));
    memset(pc->counts, 0, sizeof *pc->counts * (size_t)pc->n);
    pc->counts[pm_par_rank()] = n;
    pm_par_sum_long(pc->counts, pc->n);
  }
  /* While rank 0's observer reads the view, the others wait for the
   * checkpoints it writes in pieces. */
  const bool serve_ckpt = at[0] && v->ckpt_counts;
  pm_err e = PM_SUCCESS;
  if (obs) {
    v->serving = serve_ckpt;
    e = obs->step(obs->ctx, r, frame);
    v->serving = false;
    if (serve_ckpt) {
      long done[2] = {0, 0};
      pm_par_bcast(done, sizeof done);
    }
  } else if (serve_ckpt) {
    serve(v);
  }
  return pm_par_agree(e);
}

pm_err pm_view_step(pm_view *v, const pm_step_report *r, bool frame) {
  if (v->in_pieces) return step_pieces(v, r, frame);
  if (v->ranks)
    return pm_observer_share(pm_par_root() ? v->obs : NULL, r, frame, v->gather,
                             v->ctx);
  return v->obs ? v->obs->step(v->obs->ctx, r, frame) : PM_SUCCESS;
}

const pm_view_pieces *pm_view_frame_pieces(const pm_view *v) {
  return v->in_pieces ? &v->pieces : NULL;
}

pm_err pm_view_stopped_inside(pm_view *v, const pm_step_report *r, pm_err e) {
  if (e != PM_ERR_INTERRUPTED) return e;
  char where[512];
  snprintf(where, sizeof where, "%s", pm_error_message());
  pm_err o = pm_view_step(v, r, false);
  if (o != PM_ERR_INTERRUPTED) return o ? o : e;
  char after[1024];
  snprintf(after, sizeof after, "%s", pm_error_message());
  return PM_ERROR(PM_ERR_INTERRUPTED, "%s; %s", where, after);
}

pm_err pm_view_end(pm_view *v, pm_err e) {
  if (v->ranks) {
    v->ending = true;
    pm_err g = v->gather(v->ctx);
    v->ending = false;
    if (!e) e = g;
  }
  v->obs = NULL;
  free(v->pieces.counts);
  v->pieces.counts = NULL;
  free(v->ckpt_counts);
  free(v->ckpt_values);
  v->ckpt_counts = NULL;
  v->ckpt_values = NULL;
  v->in_pieces = false;
  return e;
}
