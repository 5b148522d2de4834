/* mpm_backend: sets up an MPM simulation from a scene (explicit or
 * implicit), and method mpm as an entry of the backend table: its time loop
 * on one process, its status and checkpoint. */
#include "mpm_backend.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_backend_impl.h"
#include "mpm_estimate.h"
#include "mpm_par.h"
#include "pm_par.h"
#include "pm_view.h"

/* Doubles per particle of the output buffer: strain energy density, J,
 * density, pressure, internal energy, the stress's von Mises and mean, the
 * displacement (3) and the material; with membranes their normal (3),
 * damage and failed. */
long mpm_sim_scratch_per_particle(const mpm_model *m) {
  return 12 + (m->kinds & MPM_KIND_MEMBRANE ? 5 : 0);
}

/* The scene checks: the method's own, then what a run across ranks cannot
 * do yet (mpm_par_check), then for the implicit MPM its own. */
pm_err mpm_sim_check_scene(const pm_scene *s) {
  PM_CALL(mpm_check_scene(s));
  if (pm_par_active()) PM_CALL(mpm_par_check(s));
  return PM_SUCCESS;
}

/* A workspace that holds only the figures of a step (reactions, residual)
 * and the timers: the implicit solver's, and rank 0's view of a run
 * across ranks. */
pm_err mpm_sim_figures_work(const mpm_model *m, mpm_work **out) {
  PM_CALL(PM_ALLOC(*out, 1, "MPM workspace"));
  return PM_ALLOC((*out)->cond.reaction, 3 * m->n_bcs + 1, "reactions");
}

/* The simulation of s: explicit (its step's workspace) or implicit (its
 * solver; the workspace holds only the reactions and the timers).  A scene
 * graded for FPM (discretization.refine) runs on MPM's uniform grid: said
 * once, on the standard error of rank 0, not refused. */
pm_err mpm_sim_setup(const pm_scene *s, bool implicit, mpm_sim **out) {
  if (s->refine.near && s->refine.size_ratio != 1.0 && pm_par_root())
    fprintf(stderr,
            "pointmech: note: discretization.refine grades FPM's point "
            "cloud; MPM's grid stays uniform at mesh_size %g m\n",
            s->mesh_size);
  pm_err ret = PM_SUCCESS;
  mpm_sim *r = NULL;
  *out = NULL;
  PM_TRY(PM_ALLOC(r, 1, "MPM simulation"));
  r->scene = s;
  double t0 = pm_wtime();
  /* The whole model: on one process, and where a rank keeps the run's
   * view (pm_view_keeps_whole).  Across ranks each rank seeds its share
   * from the scene: the particles of its cells by their reference
   * positions, in one process's order. */
  const bool par = pm_par_active();
  r->whole = !par || pm_view_whole_needed(s);
  PM_TRY(pm_par_agree(!par || pm_view_keeps_whole_for(s)
                          ? mpm_model_create(s, &r->model, &r->state)
                          : PM_SUCCESS));
  if (par)
    PM_TRY(pm_par_agree(mpm_par_create_seeded(
        s, r->model != NULL, &r->local_model, &r->local_state)));
  if (implicit) { /* (across ranks the grid moves with the particles: none
                     migrates) */
    PM_TRY(mpm_sim_figures_work(par ? r->local_model : r->model, &r->work));
    PM_TRY(pm_par_agree(
        par ? mpm_implicit_create(s, r->local_model, r->local_state, &r->imp)
            : mpm_implicit_create(s, r->model, r->state, &r->imp)));
    r->run_min_jacobian = 1;
    if (!r->whole) PM_TRY(mpm_view_sums_setup(r));
  } else if (par) {
    PM_TRY(pm_par_agree(mpm_work_create(r->local_model, &r->local_work)));
    PM_TRY(pm_par_agree(r->model ? mpm_sim_figures_work(r->model, &r->work)
                                 : PM_SUCCESS));
    if (!r->whole) PM_TRY(mpm_view_sums_setup(r));
  } else {
    PM_TRY(mpm_work_create(r->model, &r->work));
  }
  mpm_view_init(r, implicit);
  r->setup_wall = pm_wtime() - t0;
  if (r->model && pm_par_root()) { /* the outputs' (rank 0's across ranks) */
    PM_TRY(PM_ALLOC(r->scratch,
                    mpm_sim_scratch_per_particle(r->model) * r->model->n,
                    "output buffer"));
    PM_TRY(mpm_sim_history_setup(r));
  } else if (r->state && pm_par_root()) { /* rank 0 without the model */
    PM_TRY(mpm_sim_history_setup(r));
  }
  *out = r;
  r = NULL;
done:
  mpm_sim_destroy(r);
  return ret;
}

pm_err mpm_sim_create(const pm_scene *s, mpm_sim **out) {
  return mpm_sim_setup(s, false, out);
}

void mpm_sim_destroy(mpm_sim *r) {
  if (!r) return;
  free(r->ckpt_accounts);
  free(r->ckpt_cut);
  free(r->ckpt_pieces.counts);
  free(r->ckpt_pieces.values);
  mpm_state_destroy(r->ckpt_scalars);
  free(r->imp_ranks);
  free(r->ranks_held);
  mpm_work_destroy(r->local_work);
  mpm_state_destroy(r->local_state);
  mpm_model_destroy(r->local_model);
  mpm_implicit_destroy(r->imp);
  mpm_work_destroy(r->work);
  mpm_state_destroy(r->state);
  mpm_model_destroy(r->model);
  for (int b = 0; r->surface && r->model && b < r->scene->n_bodies; b++)
    free(r->surface[b]);
  free(r->surface);
  free(r->scratch);
  free(r->share_scratch);
  free(r->mesh_x0);
  free(r->sums.buf);
  free(r->sums.body);
  free(r);
}

/* Everything the simulation holds: model, state, workspace and buffer
 * (across ranks, rank 0's: its share and the whole run's view). */
size_t mpm_sim_bytes(const mpm_sim *r) {
  size_t bytes = 0;
  if (r->model)
    bytes += mpm_model_bytes(r->model) + mpm_state_bytes(r->model, r->state) +
             mpm_work_bytes(r->model, r->work) +
             mpm_sim_scratch_per_particle(r->model) * sizeof(double) *
                 (size_t)r->model->n;
  if (r->local_model) /* (the implicit solver has no step workspace) */
    bytes +=
        mpm_model_bytes(r->local_model) +
        mpm_state_bytes(r->local_model, r->local_state) +
        (r->local_work ? mpm_work_bytes(r->local_model, r->local_work) : 0);
  return bytes;
}

/* ---- run ---------------------------------------------------------------- */

/* The report of the step the state is at (the initial state as step 0). */
pm_step_report mpm_sim_step_report(const mpm_sim *r, bool last) {
  const mpm_state *s = r->state;
  const mpm_model *m = r->model ? r->model : r->local_model;
  return (pm_step_report){.last = last,
                          .step = s->step,
                          .t = s->t,
                          .residual = r->work->residual,
                          .progress = s->t / m->opt.t_end};
}

/* Report a step to the run's observer (rank 0's alone, across ranks). */
pm_err mpm_sim_report(mpm_sim *r, bool frame, bool last) {
  pm_step_report rep = mpm_sim_step_report(r, last);
  const pm_observer *obs = r->view.obs;
  return obs ? obs->step(obs->ctx, &rep, frame) : PM_SUCCESS;
}

/* What the run keeps of a step's figures over all its steps. */
void mpm_sim_note_step(mpm_sim *r, const mpm_state *s, const mpm_work *w,
                       const mpm_step_info *info) {
  r->last = *info;
  if (w->min_jacobian < r->run_min_jacobian) {
    r->run_min_jacobian = w->min_jacobian;
    r->run_min_jacobian_step = s->step;
  }
  if (info->iter_max > r->iter_max_row) r->iter_max_row = info->iter_max;
}

static pm_err observe(void *ctx, const mpm_model *m, const mpm_state *s,
                      const mpm_work *w, const mpm_step_info *info,
                      bool frame) {
  (void)m;
  mpm_sim_note_step(ctx, s, w, info);
  return mpm_view_report(ctx, frame, info->last);
}

/* The run's status from the loop's error. */
static void conclude(mpm_sim *r, const mpm_model *m, pm_err e) {
  if (e == PM_ERR_UNSTABLE)
    r->status = PM_STATUS_UNSTABLE;
  else if (e != PM_SUCCESS)
    r->status = PM_STATUS_FAILED;
  else if (m->opt.qs == PM_QS_NONE)
    r->status = PM_STATUS_COMPLETED;
  else
    r->status =
        r->last.converged ? PM_STATUS_CONVERGED : PM_STATUS_NOT_CONVERGED;
}

/* The time loop: on one process the run's; across ranks every rank
 * steps its share and rank 0's view is gathered where the run writes, and
 * at the end (pm_view). */
static pm_err run(void *p, const pm_observer *obs) {
  mpm_sim *r = p;
  pm_err e = PM_SUCCESS;
  free(r->mesh_x0); /* (the results' mesh is written) */
  r->mesh_x0 = NULL;
  if (r->view.ranks && r->resumed) { /* the shares of the checkpoint's state */
    PM_CALL(r->ckpt_pieces.on ? mpm_view_reload(r) : mpm_view_reshare(r));
    if (!r->whole) mpm_view_drop_whole(r);
  }
  pm_view_start(&r->view, obs);
  e = pm_view_start_pieces(&r->view, r->scene); /* (agreed) */
  mpm_model *lm = r->view.ranks ? r->local_model : r->model;
  mpm_state *ls = r->view.ranks ? r->local_state : r->state;
  mpm_work *lw = r->view.ranks ? r->local_work : r->work;
  if (!r->resumed) { /* a resumed run has these from its checkpoint */
    r->run_min_jacobian = INFINITY;
    r->run_min_jacobian_step = 0;
    if (r->model) { /* the initial state: across ranks rank 0's view's */
      double kin, strain, internal;
      mpm_energies(r->model, r->state, &kin, &strain, &internal);
      r->energy0 = kin + strain + internal;
      for (long q = 0; q < r->model->n; q++)
        r->run_min_jacobian =
            fmin(r->run_min_jacobian, r->state->vol[q] / r->model->vol0[q]);
    } else if (!r->whole) { /* the same summed over the shares */
      if (!e) e = mpm_view_sum(r, false);
      r->energy0 = r->sums.kinetic + r->sums.strain + r->sums.internal;
      for (long q = 0; q < lm->n; q++)
        r->run_min_jacobian =
            fmin(r->run_min_jacobian, ls->vol[q] / lm->vol0[q]);
      pm_par_min(&r->run_min_jacobian, 1);
    }
    if (!e) e = mpm_view_report(r, true, false);
  }
  mpm_run_options opt = {.t_end = lm->opt.t_end,
                         .max_steps = lm->opt.max_steps,
                         .frame_every = r->scene->output.every};
  if (!e) e = mpm_solve(lm, ls, lw, &opt, observe, r, &r->last);
  e = pm_view_end(&r->view, e); /* the state it ended in, for the figures */
  if (r->view.ranks) {
    const pm_err c = mpm_view_counts(r);
    if (!e) e = c;
  }
  conclude(r, lm, e);
  return e;
}

/* ---- what the run driver reads ------------------------------------------ */

/* ---- plan --------------------------------------------------------------- */

static pm_err create(const pm_scene *s, void **out) {
  mpm_sim *r = NULL;
  PM_CALL(mpm_sim_create(s, &r));
  *out = r;
  return PM_SUCCESS;
}

void mpm_sim_destroy_any(void *p) { mpm_sim_destroy(p); }

pm_err mpm_sim_cut_items(mpm_sim *r, pm_ckpt *ck, long ranks) {
  const long n = mpm_decomp_items((int)ranks);
  if (pm_ckpt_reading(ck)) {
    free(r->ckpt_cut);
    r->ckpt_cut = NULL;
    if (!pm_ckpt_has(ck, "run.ranks.cut")) return PM_SUCCESS;
    PM_CALL(PM_ALLOC(r->ckpt_cut, n, "the cut of the boxes"));
    PM_CALL(pm_ckpt_longs(ck, "run.ranks.cut", n, r->ckpt_cut));
    if (ranks != pm_par_size()) { /* (another count cuts afresh) */
      free(r->ckpt_cut);
      r->ckpt_cut = NULL;
    }
    return PM_SUCCESS;
  }
  if (!r->local_model) return PM_SUCCESS;
  long *buf = NULL;
  PM_CALL(PM_ALLOC(buf, n, "the cut of the boxes"));
  mpm_decomp_pack(mpm_par_decomp(r->local_model), buf);
  const pm_err e = pm_ckpt_longs(ck, "run.ranks.cut", n, buf);
  free(buf);
  return e;
}

/* The ranks a run had and their energy accounts (one process: its own),
 * so that a run resumed on as many ranks goes on as it would have. */
static pm_err ranks_checkpoint(mpm_sim *r, pm_ckpt *ck) {
  const int n = MPM_PAR_ACCOUNTS;
  long ranks = pm_par_size();
  PM_CALL(pm_ckpt_long(ck, "run.ranks", &ranks));
  PM_CHECK(ranks >= 1 && ranks <= 1000000, PM_ERR_IO,
           "%s: run.ranks: expected a count of ranks, got %ld",
           pm_ckpt_path(ck), ranks);
  if (pm_ckpt_reading(ck)) {
    free(r->ckpt_accounts);
    r->ckpt_accounts = NULL;
    PM_CALL(PM_ALLOC(r->ckpt_accounts, n * ranks, "energy accounts"));
    r->ckpt_ranks = (int)ranks;
    PM_CALL(mpm_sim_cut_items(r, ck, ranks));
    return pm_ckpt_doubles(ck, "run.ranks.accounts", n * ranks,
                           r->ckpt_accounts);
  }
  PM_CALL(mpm_sim_cut_items(r, ck, ranks));
  double own[MPM_PAR_ACCOUNTS];
  const double *rows = own;
  if (r->local_model) {
    rows = mpm_par_accounts(r->local_model);
  } else {
    memcpy(own, r->state->energy, sizeof r->state->energy);
    own[n - 2] = r->state->external_work;
    own[n - 1] = r->state->dissipated;
  }
  return pm_ckpt_doubles(ck, "run.ranks.accounts", n * ranks, (double *)rows);
}

pm_err mpm_sim_run_items(mpm_sim *r, pm_ckpt *ck) {
  long iter_max_row = r->iter_max_row;
  PM_CALL(pm_ckpt_double(ck, "run.energy0", &r->energy0));
  PM_CALL(pm_ckpt_double(ck, "run.min_jacobian", &r->run_min_jacobian));
  PM_CALL(pm_ckpt_long(ck, "run.min_jacobian_step", &r->run_min_jacobian_step));
  PM_CALL(pm_ckpt_long(ck, "run.iter_max_row", &iter_max_row));
  r->iter_max_row = (int)iter_max_row;
  return pm_ckpt_long(ck, "run.iter_capped_prev", &r->iter_capped_prev);
}

/* The state, and what the run reports over all its steps: across ranks
 * without the whole model, in pieces (mpm_ckpt_pieces.c). */
static pm_err checkpoint(void *p, pm_ckpt *ck) {
  mpm_sim *r = p;
  if (pm_ckpt_reading(ck) ? mpm_sim_ckpt_is_pieces(ck) : !r->whole)
    return mpm_sim_ckpt_index(r, ck);
  /* A rank without the whole model reads a checkpoint of the whole run
   * into one, from which its share is cut anew (mpm_view_reshare). */
  if (pm_ckpt_reading(ck) && !r->model) {
    r->ckpt_scalars = r->state; /* (rank 0 without the whole model's) */
    r->state = NULL;
    PM_CALL(mpm_model_create(r->scene, &r->model, &r->state));
  }
  PM_CALL(mpm_state_checkpoint(r->model, r->state, ck));
  PM_CALL(mpm_sim_run_items(r, ck));
  PM_CALL(ranks_checkpoint(r, ck));
  if (pm_ckpt_reading(ck)) {
    r->resumed = true;
    r->last.step = r->state->step;
    r->last.t = r->state->t;
    r->last.dt = r->state->dt;
  }
  return PM_SUCCESS;
}

const pm_backend mpm_backend = {
    .method = "mpm",
    .description = "explicit Material Point Method",
    .section = &mpm_section,
    .dt_safety = 0.5,
    .ranks = true,
    .check = mpm_sim_check_scene,
    .create = create,
    .estimate_bytes = mpm_estimate_bytes,
    .ghost_layers = mpm_sim_ghost_layers,
    .setup_whole =
        false, /* each rank seeds its share (mpm_par_create_seeded) */
    .destroy = mpm_sim_destroy_any,
    .plan = mpm_sim_plan,
    .run = run,
    .points = mpm_sim_points,
    .fields = mpm_sim_fields,
    .displacement = mpm_sim_displacement,
    .figures = mpm_sim_figures,
    .history_names = mpm_sim_history_names,
    .history_values = mpm_sim_history_values,
    .summary = mpm_sim_summary,
    .timers = mpm_sim_timers,
    .checkpoint = checkpoint,
    .pieces = mpm_sim_pieces,
    .ckpt_pieces = mpm_sim_ckpt_pieces,
    .pieces_apply = mpm_sim_pieces_apply,
    .errors = mpm_sim_errors,
};

/* ---- method mpm-implicit ------------------------------------------------ */
