/* pm_run: the one driver of every method: outputs, history, summary,
 * progress and timings around a backend's time loop (rank 0), the other
 * ranks' part in it, and a plan without a run. */
#include "pm_run.h"

#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>

#include "pm_interrupt.h"
#include "pm_memory.h"
#include "pm_omp.h"
#include "pm_output.h"
#include "pm_par.h"
#include "pm_petsc.h"
#include "pm_run_impl.h"

static pm_outdir_mode outdir_mode(unsigned flags) {
  return flags & PM_RUN_OVERWRITE ? PM_OUTDIR_OVERWRITE : PM_OUTDIR_NEW;
}

/* outdir: the folder, claimed by the caller (taken over), or NULL. */
static pm_err open_outputs(pm_run_ctx *c, const char *out_dir, unsigned flags,
                           pm_outdir **outdir, pm_run_resume_info *rs) {
  /* PETSc starts MPI, which may start a helper process; it must not
   * inherit the run's open files (results.h5's lock would outlive the
   * run), so a scene solved by Newton's method starts PETSc first. */
  if (c->s->time.qs == PM_QS_STATIC) PM_CALL(pm_petsc_init());
  c->out_dir = out_dir;
  if (outdir && *outdir) {
    c->outdir = *outdir;
    *outdir = NULL;
  } else {
    PM_CALL(pm_outdir_claim(out_dir, outdir_mode(flags), &c->outdir));
  }
  if (rs) {
    PM_CALL(pm_results_reopen(out_dir, c->pts.n, rs->h.frames, &c->results));
    c->history_rows = rs->h.history_rows;
    PM_CALL(pm_history_open(out_dir, c->n_cols, c->names, c->history_rows,
                            &c->history));
  } else {
    PM_CALL(pm_results_create_ex(out_dir, c->s->dimension, &c->pts, c->s->text,
                                 PM_VERSION, &c->results));
    PM_CALL(pm_history_open(out_dir, c->n_cols, c->names, -1, &c->history));
  }
  return pm_run_write_summary(c, true);
}

/* Every rank's peak memory onto rank 0 for the summary, once the run has
 * ended (collective); without room for a double per rank the summary goes
 * without (the run's own outcome stands). */
static void gather_peaks(void) { (void)pm_memory_gather_peaks(); }

/* PETSc's start is collective, and across ranks nothing before the run
 * starts it (the exchanges are MPI alone): every rank of a scene solved
 * by Newton's method starts it as its run begins, rank 0 before it opens
 * its outputs. */
static pm_err start_petsc(const pm_scene *s) {
  if (!pm_par_active() || s->time.qs != PM_QS_STATIC) return PM_SUCCESS;
  return pm_petsc_init();
}

pm_err pm_run_root(const pm_scene *s, void *sim, const char *out_dir,
                   unsigned flags, pm_outcome *o, pm_outdir **outdir,
                   pm_run_resume_info *rs, const pm_observer *also) {
  pm_err ret = PM_SUCCESS, run_err = PM_SUCCESS;
  pm_run_ctx *c = NULL;
  const bool quiet = flags & PM_RUN_QUIET;
  bool agreed = false; /* across ranks: the others heard how setup went */
  void (*old_xfsz)(int) = SIG_ERR;
  memset(o, 0, sizeof *o);
  PM_TRY(start_petsc(s));
  for (int k = 0; k < 3; k++) o->nrmse[k] = NAN;
  o->nrmse_vector = o->loaded_reaction = NAN;
  o->loaded_axis = -1;
  PM_TRY(PM_ALLOC(c, 1, "run context"));
  c->s = s;
  c->be = s->backend;
  c->sim = sim;
  c->o = o;
  c->also = also;
  c->show_progress = !quiet;
  c->tm_output = pm_timers_add(&c->out_timer, "output");
  c->tm_checkpoint = pm_timers_add(&c->out_timer, "checkpoint");
  c->ckpt_step = -1;
  c->last_step = -1;
  c->ckpt_every = s->output.checkpoint.every;
  c->ckpt_seconds = 60 * s->output.checkpoint.minutes;
  c->be->points(sim, &c->pts);
  PM_TRY(pm_run_setup_columns(c));
  /* A backend that sums the errors over the ranks' shares (no rank holds
   * the whole displacement) needs no reference field here. */
  double skip[3], skip_vector;
  const bool summed = c->be->errors && c->be->errors(sim, skip, &skip_vector);
  if (s->reference_mask && !summed) {
    PM_TRY(PM_ALLOC(c->ref, 3 * c->pts.n, "reference field"));
    for (int k = 0; k < 3; k++)
      if ((s->reference_mask >> k & 1u) && pm_expr_uses(s->reference[k], 't'))
        c->ref_time = true;
    pm_run_fill_reference(c, 0);
  }
  if (rs) PM_TRY(pm_run_restore(c, rs));
  pm_progress_init(&c->progress, stderr, s->name);
  /* A full disk or the file size limit fails a write (EFBIG) instead of
   * killing the process, so that the run can say what happened. */
  old_xfsz = signal(SIGXFSZ, SIG_IGN);
  if (out_dir) PM_TRY(open_outputs(c, out_dir, flags, outdir, rs));
  pm_observer obs = {.ctx = c,
                     .step = pm_run_observe,
                     .wants = pm_run_wants,
                     .dir = c->results ? out_dir : NULL,
                     .frame_index = pm_run_frame_index};
  c->t_start = pm_wtime() - (rs ? rs->h.wall_seconds : 0);
  c->ckpt_last_wall = pm_wtime();
  struct sigaction old_handlers[2];
  pm_run_catch_interrupts(old_handlers);
  /* Across ranks, the others wait here for this rank's outputs. */
  agreed = true;
  PM_TRY(pm_par_agree(PM_SUCCESS));
  run_err = pm_run_interrupted_inside(c, c->be->run(sim, &obs));
  gather_peaks();
  pm_run_release_interrupts(old_handlers);
  if (!quiet) pm_progress_finish(&c->progress);
  c->be->figures(sim, &o->fig, true);
  o->fig.wall_seconds = pm_wtime() - c->t_start;
  pm_run_conclude(c, run_err);
  if (o->fig.status != PM_STATUS_UNSTABLE && o->fig.status != PM_STATUS_FAILED)
    pm_run_compute_errors(c, o->fig.time);
  if (out_dir) {
    /* Frames written before a failure are good: keep them. */
    pm_history *h = c->history;
    c->history = NULL;
    PM_TRY(pm_history_close(h));
    PM_TRY(pm_run_write_summary(c, false));
  }
  if (!quiet) pm_run_report(c);
  if (run_err != PM_SUCCESS)
    ret = PM_ERROR(run_err, "%s", o->message);
  else if (o->fig.status == PM_STATUS_NOT_CONVERGED)
    ret = PM_ERROR(PM_ERR_NOT_CONVERGED, "%s", o->message);
done:
  if (!agreed) pm_par_agree(ret ? ret : PM_ERR_INTERNAL);
  if (old_xfsz != SIG_ERR) signal(SIGXFSZ, old_xfsz);
  if (c) {
    pm_results_close(c->results, o->fig.status != PM_STATUS_NOT_RUN);
    if (c->history) pm_history_close(c->history);
    pm_outdir_release(c->outdir);
    free(c->ref);
    free(c);
  }
  return ret;
}

pm_err pm_run_sim(const pm_scene *s, void *sim, const char *out_dir,
                  unsigned flags, pm_outcome *o) {
  return pm_run_root(s, sim, out_dir, flags, o, NULL, NULL, NULL);
}

/* A rank other than 0 of a run across ranks: it steps its share and joins
 * the collectives of rank 0's observer, which writes everything; a signal
 * is rank 0's to act on. */
pm_err pm_run_worker(const pm_scene *s, void *sim, pm_outcome *o) {
  struct sigaction ignore, old[2];
  memset(&ignore, 0, sizeof ignore);
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGINT, &ignore, &old[0]);
  sigaction(SIGTERM, &ignore, &old[1]);
  pm_err e = start_petsc(s);
  if (!e) e = pm_par_agree(PM_SUCCESS); /* rank 0's outputs are open */
  if (!e) {
    e = s->backend->run(sim, NULL);
    gather_peaks();
  }
  pm_run_release_interrupts(old);
  if (e) snprintf(o->message, sizeof o->message, "%s", pm_error_message());
  return e;
}

pm_err pm_run_scene_observed(const pm_scene *s, const char *out_dir,
                             unsigned flags, const pm_observer *also,
                             void **simp, pm_outcome *o) {
  pm_err ret = PM_SUCCESS;
  void *sim = NULL;
  *simp = NULL;
  pm_outdir *outdir = NULL;
  const bool ranks = pm_par_active(), root = pm_par_root();
  PM_CALL(pm_run_check_not_interrupted(o));
  PM_CALL(pm_par_agree(pm_memory_check(s)));
  /* The folder first: a busy or taken one is refused before the setup
   * (across ranks, rank 0 writes everything). */
  if (out_dir && root)
    ret = pm_outdir_claim(out_dir, outdir_mode(flags), &outdir);
  if (ranks) ret = pm_par_agree(ret);
  if (ret) goto done;
  /* A signal during the setup (one process): the setup's polls stop it
   * (pm_interrupt_check), else it stops once the setup is done. */
  if (!ranks) {
    struct sigaction old[2];
    pm_interrupt_catch(old, 0);
    ret = s->backend->create(s, &sim);
    pm_interrupt_release(old);
    if (!ret) ret = pm_interrupt_check("during the setup (nothing written)");
    if (ret == PM_ERR_INTERRUPTED) o->fig.status = PM_STATUS_INTERRUPTED;
    if (ret) goto done;
  } else {
    PM_TRY(s->backend->create(s, &sim));
  }
  *simp = sim; /* the caller's observer reads it during the run */
  if (root)
    ret = pm_run_root(s, sim, out_dir, flags, o, &outdir, NULL, also);
  else
    ret = pm_run_worker(s, sim, o);
  /* Rank 0 concludes the run (not converged, interrupted): every rank
   * leaves with its outcome, and so with its exit status. */
  ret = pm_par_agree(ret);
done:
  *simp = sim;
  pm_outdir_release(outdir);
  return ret;
}

pm_err pm_run_scene(const pm_scene *s, const char *out_dir, unsigned flags,
                    pm_outcome *o) {
  void *sim = NULL;
  pm_err e = pm_run_scene_observed(s, out_dir, flags, NULL, &sim, o);
  if (sim) s->backend->destroy(sim);
  return e;
}

pm_err pm_plan_scene(const pm_scene *s, FILE *out) {
  void *sim = NULL;
  PM_CALL(pm_par_agree(pm_memory_check(s)));
  PM_CALL(s->backend->create(s, &sim));
  pm_err e = s->backend->plan(sim, out);
  if (e == PM_SUCCESS) pm_memory_plan(s, out);
  s->backend->destroy(sim);
  return e;
}
