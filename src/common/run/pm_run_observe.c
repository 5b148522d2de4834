/* pm_run_observe: what the driver does after each step of a backend's loop
 * (progress, frames, checkpoints) and how a run ends on SIGINT or SIGTERM. */
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "pm_interrupt.h"
#include "pm_par.h"
#include "pm_run_impl.h"

/* The signal flag is the process's (pm_interrupt): sticky, so that once
 * a run is interrupted, pm_run_scene starts no other (a study's remaining
 * levels are refused without being set up). */
static const char *signal_name(int sig) { return pm_interrupt_name(sig); }

/* Catch SIGINT and SIGTERM once each (a second one acts as usual, so a
 * run that does not reach the end of its step can still be stopped).
 * Across ranks every one is caught: mpirun forwards the signal it gets,
 * a batch system or timeout signals every process besides, so rank 0 may
 * get two at once; mpirun's SIGKILL, after odls_base_sigkill_timeout, is
 * the hard stop. */
void pm_run_catch_interrupts(struct sigaction old[2]) {
  pm_interrupt_catch(old, !pm_par_active());
}

void pm_run_release_interrupts(const struct sigaction old[2]) {
  pm_interrupt_release(old);
}

/* After a signal, the state after this step becomes the last frame and a
 * checkpoint; on the run's last step the run simply ends.  Decided once
 * per step: by wants when the backend asks first, else by observe. */
static void decide(pm_run_ctx *c, const pm_step_report *r) {
  if (c->decided) return;
  c->decided = true;
  c->decided_sig = r->last ? 0 : pm_interrupt_signal();
  c->decided_ckpt = c->results && (pm_run_checkpoint_due(c, r) ||
                                   (c->decided_sig && r->step > 0));
}

bool pm_run_wants(void *ctx, const pm_step_report *r, bool frame) {
  pm_run_ctx *c = ctx;
  decide(c, r);
  const bool also =
      c->also && c->also->wants && c->also->wants(c->also->ctx, r, frame);
  return frame || c->decided_sig || c->decided_ckpt || also;
}

long pm_run_frame_index(void *ctx, const pm_step_report *r, bool frame) {
  pm_run_ctx *c = ctx;
  decide(c, r);
  return c->results && (frame || c->decided_sig) ? pm_results_frames(c->results)
                                                 : -1;
}

/* The checkpoint of step; after a signal sig, a method that cannot write
 * one is noted and the run stops all the same. */
static pm_err checkpoint(pm_run_ctx *c, long step, int sig) {
  pm_err e = pm_run_write_checkpoint(c, step);
  if (e != PM_ERR_ARG || !sig) return e;
  snprintf(c->ckpt_note, sizeof c->ckpt_note, "no checkpoint: %s",
           pm_error_message());
  pm_error_clear();
  return PM_SUCCESS;
}

pm_err pm_run_observe(void *ctx, const pm_step_report *r, bool frame) {
  pm_run_ctx *c = ctx;
  decide(c, r);
  c->decided = false;
  c->last_step = r->step;
  const int sig = c->decided_sig;
  if (c->show_progress) {
    char status[96];
    snprintf(status, sizeof status, "t=%.4g s  step %ld  residual %.2e", r->t,
             r->step, r->residual);
    pm_progress_update(&c->progress, r->progress, status);
  }
  /* A signal's frame off the schedule comes after the checkpoint: its
   * history row would restart the figures a row gathers over its steps
   * (the most iterations since the last row), which the checkpoint must
   * hold as they were for the resumed run's next row. */
  const bool extra = sig && !frame && c->results;
  if (c->decided_ckpt && extra) PM_CALL(checkpoint(c, r->step, sig));
  if ((frame || sig) && c->results) {
    pm_timers_start(&c->out_timer, c->tm_output);
    pm_err e = pm_run_write_frame(c, r);
    pm_timers_stop(&c->out_timer, c->tm_output);
    PM_CALL(e);
    c->extra_frame = !frame;
  }
  if (c->decided_ckpt && !extra) PM_CALL(checkpoint(c, r->step, sig));
  if (c->also) PM_CALL(c->also->step(c->also->ctx, r, frame));
  if (!sig) return PM_SUCCESS;
  if (c->ckpt_step == r->step)
    return PM_ERROR(PM_ERR_INTERRUPTED,
                    "interrupted by %s after step %ld, t = %.6g s (results up "
                    "to this step kept; `pointmech resume %s` continues from "
                    "its checkpoint)",
                    signal_name(sig), r->step, r->t, c->out_dir);
  return PM_ERROR(PM_ERR_INTERRUPTED,
                  "interrupted by %s after step %ld, t = %.6g s (results up "
                  "to this step kept%s%s)",
                  signal_name(sig), r->step, r->t, c->ckpt_note[0] ? "; " : "",
                  c->ckpt_note);
}

pm_err pm_run_interrupted_inside(pm_run_ctx *c, pm_err run_err) {
  if (run_err != PM_ERR_INTERRUPTED) return run_err;
  if (c->decided_sig) return run_err; /* the observer's own, after a step */
  char why[1024], note[600] = "";
  snprintf(why, sizeof why, "%s", pm_error_message());
  const long step = c->last_step;
  if (c->ckpt_step == step && step > 0) {
    snprintf(note, sizeof note,
             "; `pointmech resume %s` continues from its "
             "checkpoint of step %ld",
             c->out_dir, step);
  } else if (!c->results || step <= 0) {
    snprintf(note, sizeof note, "; no checkpoint: %s",
             step <= 0 ? "no step had converged" : "no output folder");
  } else if (pm_par_active()) {
    snprintf(note, sizeof note,
             "; no checkpoint: a signal inside a solve "
             "across ranks leaves the last one written");
  } else {
    pm_err e = pm_run_write_checkpoint(c, step);
    if (e == PM_SUCCESS)
      snprintf(note, sizeof note,
               "; `pointmech resume %s` continues from "
               "its checkpoint of step %ld, the last converged",
               c->out_dir, step);
    else
      snprintf(note, sizeof note, "; no checkpoint: %s", pm_error_message());
  }
  return PM_ERROR(PM_ERR_INTERRUPTED, "%s (results up to step %ld kept%s)", why,
                  step > 0 ? step : 0, note);
}

/* Refuse to start once a run of this process was interrupted. */
pm_err pm_run_check_not_interrupted(pm_outcome *o) {
  memset(o, 0, sizeof *o);
  o->fig.status = PM_STATUS_FAILED;
  const int sig = pm_interrupt_signal();
  if (!sig) return PM_SUCCESS;
  o->fig.status = PM_STATUS_INTERRUPTED;
  return PM_ERROR(PM_ERR_INTERRUPTED,
                  "not started: an earlier run was interrupted by %s",
                  signal_name(sig));
}
