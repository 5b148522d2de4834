/* pm_run_checkpoint: the driver's part of a checkpoint: when one is due,
 * its items (what the run is and how far its outputs go) written before
 * the backend's, and read back when a run resumes. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_omp.h"
#include "pm_output.h"
#include "pm_run_impl.h"

void pm_run_header_free(pm_run_header *h) {
  free(h->version);
  free(h->method);
  free(h->scene_path);
  free(h->scene_text);
  free(h->overrides);
  memset(h, 0, sizeof *h);
}

pm_err pm_run_header_items(pm_ckpt *ck, pm_run_header *h) {
  PM_CALL(pm_ckpt_string(ck, "run.version", &h->version));
  PM_CALL(pm_ckpt_string(ck, "run.method", &h->method));
  PM_CALL(pm_ckpt_string(ck, "run.scene_path", &h->scene_path));
  PM_CALL(pm_ckpt_string(ck, "run.scene_text", &h->scene_text));
  PM_CALL(pm_ckpt_string(ck, "run.overrides", &h->overrides));
  PM_CALL(pm_ckpt_long(ck, "run.step", &h->step));
  PM_CALL(pm_ckpt_long(ck, "run.frames", &h->frames));
  PM_CALL(pm_ckpt_long(ck, "run.history_rows", &h->history_rows));
  PM_CALL(pm_ckpt_long(ck, "run.threads", &h->threads));
  PM_CALL(pm_ckpt_long(ck, "run.resumes", &h->resumes));
  PM_CALL(pm_ckpt_double(ck, "run.wall_seconds", &h->wall_seconds));
  PM_CALL(pm_ckpt_double(ck, "run.output_seconds", &h->output_seconds));
  return pm_ckpt_double(ck, "run.checkpoint_seconds", &h->checkpoint_seconds);
}

/* The --set overrides as one string, one per line. */
static char *join_overrides(const pm_scene *s) {
  size_t len = 1;
  for (int k = 0; k < s->n_overrides; k++) len += strlen(s->overrides[k]) + 1;
  char *buf = malloc(len), *p = buf;
  if (!buf) return NULL;
  for (int k = 0; k < s->n_overrides; k++)
    p += sprintf(p, "%s\n", s->overrides[k]);
  *p = '\0';
  return buf;
}

/* Write OUT/checkpoint.h5 of the state after step (replacing the older
 * one).  PM_ERR_ARG when the method cannot checkpoint this scene. */
pm_err pm_run_write_checkpoint(pm_run_ctx *c, long step) {
  pm_err ret = PM_SUCCESS;
  pm_ckpt *ck = NULL;
  const pm_scene *s = c->s;
  pm_run_header h = {
      .version = (char *)PM_VERSION,
      .method = s->method,
      .scene_path = s->path,
      .scene_text = s->text,
      .overrides = join_overrides(s),
      .step = step,
      /* A signal's frame is not one of the run's: a resumed run drops
       * it, so that its results are those of an uninterrupted run. */
      .frames = pm_results_frames(c->results) - c->extra_frame,
      .history_rows = c->history_rows - c->extra_frame,
      .threads = pm_omp_threads(),
      .resumes = c->resumes,
      .wall_seconds = pm_wtime() - c->t_start,
      .output_seconds = pm_timers_seconds(&c->out_timer, c->tm_output),
      .checkpoint_seconds = pm_timers_seconds(&c->out_timer, c->tm_checkpoint),
  };
  char *overrides = h.overrides;
  PM_ENSURE(c->be->checkpoint, PM_ERR_ARG, "method %s cannot write checkpoints",
            s->method);
  PM_ENSURE(overrides, PM_ERR_MEMORY, "cannot join the scene's overrides");
  pm_timers_start(&c->out_timer, c->tm_checkpoint);
  PM_TRY(pm_ckpt_create(c->out_dir, &ck));
  PM_TRY(pm_run_header_items(ck, &h));
  PM_TRY(c->be->checkpoint(c->sim, ck));
  pm_ckpt *done_ck = ck;
  ck = NULL;
  PM_TRY(pm_ckpt_finish(done_ck));
  c->ckpt_step = step;
  c->ckpt_count++;
  c->ckpt_last_wall = pm_wtime();
done:
  pm_timers_stop(&c->out_timer, c->tm_checkpoint);
  pm_ckpt_abort(ck);
  free(overrides);
  return ret;
}

/* A checkpoint is due after step (not the initial state). */
bool pm_run_checkpoint_due(const pm_run_ctx *c, const pm_step_report *r) {
  const long step = r->step;
  /* None after the last step: there is nothing to resume. */
  if (step <= 0 || step == c->ckpt_step || r->last) return false;
  if (c->ckpt_every > 0 && step % c->ckpt_every == 0) return true;
  return c->ckpt_seconds > 0 &&
         pm_wtime() - c->ckpt_last_wall >= c->ckpt_seconds;
}

/* Read the backend's items of a checkpoint and check it whole. */
pm_err pm_run_restore(pm_run_ctx *c, pm_run_resume_info *rs) {
  PM_CHECK(c->be->checkpoint, PM_ERR_ARG, "method %s cannot resume",
           c->s->method);
  PM_CALL(c->be->checkpoint(c->sim, rs->ck));
  pm_ckpt *ck = rs->ck;
  rs->ck = NULL;
  PM_CALL(pm_ckpt_finish(ck));
  c->resumes = rs->h.resumes + 1;
  c->resumed_from = rs->h.step;
  c->ckpt_step = rs->h.step;
  c->last_step = rs->h.step; /* a signal before the next step names it */
  c->out_timer.stage[c->tm_output].seconds = rs->h.output_seconds;
  c->out_timer.stage[c->tm_checkpoint].seconds = rs->h.checkpoint_seconds;
  if (rs->h.threads != pm_omp_threads())
    fprintf(stderr,
            "pointmech: warning: the checkpoint was written on %ld threads, "
            "this run has %d: results differ from an uninterrupted run at "
            "round-off (set OMP_NUM_THREADS=%ld to repeat it bit for bit)\n",
            rs->h.threads, pm_omp_threads(), rs->h.threads);
  return PM_SUCCESS;
}
