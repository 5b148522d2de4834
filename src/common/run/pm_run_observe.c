/* pm_run_observe: what the driver does after each step of a backend's loop
 * (progress, frames, checkpoints) and how a run ends on SIGINT or SIGTERM. */
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "pm_par.h"
#include "pm_run_impl.h"

/* SIGINT or SIGTERM received during a run (0: none).  Sticky for the
 * process: once a run is interrupted, pm_run_scene starts no other (a
 * study's remaining levels are refused without being set up). */
static volatile sig_atomic_t interrupt_signal;

static void on_interrupt(int sig) { interrupt_signal = sig; }

static const char *signal_name(int sig) {
  return sig == SIGINT ? "SIGINT" : "SIGTERM";
}

/* Catch SIGINT and SIGTERM once each (a second one acts as usual, so a
 * run that does not reach the end of its step can still be stopped).
 * Across ranks every one is caught: mpirun forwards the signal it gets,
 * a batch system or timeout signals every process besides, so rank 0 may
 * get two at once; mpirun's SIGKILL, after odls_base_sigkill_timeout, is
 * the hard stop. */
void pm_run_catch_interrupts(struct sigaction old[2]) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = pm_par_active() ? 0 : SA_RESETHAND;
  sigaction(SIGINT, &sa, &old[0]);
  sigaction(SIGTERM, &sa, &old[1]);
}

void pm_run_release_interrupts(const struct sigaction old[2]) {
  sigaction(SIGINT, &old[0], NULL);
  sigaction(SIGTERM, &old[1], NULL);
}

/* After a signal, the state after this step becomes the last frame and a
 * checkpoint; on the run's last step the run simply ends.  Decided once
 * per step: by wants when the backend asks first, else by observe. */
static void decide(pm_run_ctx *c, const pm_step_report *r) {
  if (c->decided) return;
  c->decided = true;
  c->decided_sig = r->last ? 0 : interrupt_signal;
  c->decided_ckpt = c->results && (pm_run_checkpoint_due(c, r) ||
                                   (c->decided_sig && r->step > 0));
}

bool pm_run_wants(void *ctx, const pm_step_report *r, bool frame) {
  pm_run_ctx *c = ctx;
  decide(c, r);
  return frame || c->decided_sig || c->decided_ckpt;
}

pm_err pm_run_observe(void *ctx, const pm_step_report *r, bool frame) {
  pm_run_ctx *c = ctx;
  decide(c, r);
  c->decided = false;
  const int sig = c->decided_sig;
  if (c->show_progress) {
    char status[96];
    snprintf(status, sizeof status, "t=%.4g s  step %ld  residual %.2e", r->t,
             r->step, r->residual);
    pm_progress_update(&c->progress, r->progress, status);
  }
  if ((frame || sig) && c->results) {
    pm_timers_start(&c->out_timer, c->tm_output);
    pm_err e = pm_run_write_frame(c, r);
    pm_timers_stop(&c->out_timer, c->tm_output);
    PM_CALL(e);
    c->extra_frame = !frame;
  }
  if (c->decided_ckpt) {
    pm_err e = pm_run_write_checkpoint(c, r->step);
    if (e == PM_ERR_ARG && sig) /* the method cannot: say so, go on */
      snprintf(c->ckpt_note, sizeof c->ckpt_note, "no checkpoint: %s",
               pm_error_message());
    else
      PM_CALL(e);
  }
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

/* Refuse to start once a run of this process was interrupted. */
pm_err pm_run_check_not_interrupted(pm_outcome *o) {
  memset(o, 0, sizeof *o);
  o->fig.status = PM_STATUS_FAILED;
  const int sig = interrupt_signal;
  if (!sig) return PM_SUCCESS;
  o->fig.status = PM_STATUS_INTERRUPTED;
  return PM_ERROR(PM_ERR_INTERRUPTED,
                  "not started: an earlier run was interrupted by %s",
                  signal_name(sig));
}
