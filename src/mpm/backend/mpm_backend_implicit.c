/* mpm_backend_implicit: method mpm-implicit as an entry of the backend
 * table: the quasi-static solver (mpm_implicit.h) on MPM's model, with the
 * explicit backend's fields, figures and output. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_backend_impl.h"
#include "mpm_estimate.h"
#include "mpm_par.h"
#include "pm_par.h"

/* The scene check: explicit MPM's, what a run across ranks cannot do yet,
 * then the implicit MPM's own. */
static pm_err check_implicit(const pm_scene *s) {
  PM_CALL(mpm_sim_check_scene(s));
  if (pm_par_active()) PM_CALL(mpm_par_check_implicit(s));
  return mpm_implicit_check_scene(s);
}
static pm_err implicit_create(const pm_scene *s, void **out) {
  mpm_sim *r = NULL;
  PM_CALL(mpm_sim_setup(s, true, &r));
  *out = r;
  return PM_SUCCESS;
}

/* Each converged load step is a step of the run: t = lambda t_load. */
static pm_err implicit_observe(void *ctx, const mpm_implicit_step *step) {
  mpm_sim *r = ctx;
  const mpm_model *m = r->local_model ? r->local_model : r->model;
  mpm_state *st = r->local_model ? r->local_state : r->state;
  st->step = step->step;
  st->t = step->lambda * m->opt.t_load;
  r->imp_newton = step->newton;
  r->imp_linear = step->linear;
  memcpy(r->work->cond.reaction, mpm_implicit_reactions(r->imp),
         3 * sizeof(double) * (size_t)m->n_bcs);
  r->work->residual = step->residual;
  if (step->min_jacobian < r->run_min_jacobian) {
    r->run_min_jacobian = step->min_jacobian;
    r->run_min_jacobian_step = step->step;
  }
  const bool last = step->lambda >= 1;
  const long every = r->scene->output.every;
  pm_step_report rep = {.last = last,
                        .step = st->step,
                        .t = st->t,
                        .residual = step->residual,
                        .progress = step->lambda};
  const bool frame = last || (every > 0 && st->step % every == 0);
  return pm_view_step(&r->view, &rep, frame);
}

/* A signal stopped a load step inside its solve: the last converged step,
 * which the state still holds, to the observer once more
 * (pm_view_stopped_inside).  Nothing to resume before the first one. */
static pm_err stopped_inside(mpm_sim *r, pm_err e) {
  const mpm_model *m = r->local_model ? r->local_model : r->model;
  const mpm_state *st = r->local_model ? r->local_state : r->state;
  if (e != PM_ERR_INTERRUPTED || st->step <= 0) return e;
  pm_step_report rep = {.last = false,
                        .step = st->step,
                        .t = st->t,
                        .residual = r->work->residual,
                        .progress =
                            m->opt.t_load > 0 ? st->t / m->opt.t_load : 0};
  return pm_view_stopped_inside(&r->view, &rep, e);
}

/* The initial state to the observer: rank 0's view holds it where it
 * keeps the whole model; without it, every rank writes its piece of the
 * frame and rank 0 reports the sums (collective). */
static pm_err report_start(mpm_sim *r) {
  if (!r->whole) {
    const mpm_state *ls = r->local_state;
    pm_step_report rep = {.step = ls->step, .t = ls->t};
    return pm_view_step(&r->view, &rep, true);
  }
  pm_err e = pm_par_root() ? mpm_sim_report(r, true, false) : PM_SUCCESS;
  return r->local_model ? pm_par_agree(e) : e;
}

static pm_err implicit_run(void *p, const pm_observer *obs) {
  mpm_sim *r = p;
  pm_err e = PM_SUCCESS;
  free(r->mesh_x0); /* (the results' mesh is written) */
  r->mesh_x0 = NULL;
  /* a resumed run in pieces: each share's state and unknowns */
  if (r->view.ranks && r->resumed && r->ckpt_pieces.on)
    PM_CALL(mpm_view_implicit_reload(r));
  pm_view_start(&r->view, obs);
  e = pm_view_start_pieces(&r->view, r->scene); /* (agreed) */
  if (!r->resumed) {
    r->energy0 = 0;
    r->run_min_jacobian_step = 0;
    if (!e) e = report_start(r);
  }
  if (!e) e = stopped_inside(r, mpm_implicit_run(r->imp, implicit_observe, r));
  /* Across ranks, the state the run ended in, for the figures (a
   * failure's too), and each rank's share of the unknowns. */
  if (r->local_model) {
    const int size = pm_par_size(), me = pm_par_rank();
    pm_err a = PM_SUCCESS;
    if (!r->imp_ranks) a = PM_ALLOC(r->imp_ranks, 3 * size, "ranks' unknowns");
    if (!(a = pm_par_agree(a))) {
      memset(r->imp_ranks, 0, 3 * (size_t)size * sizeof(long));
      r->imp_ranks[3 * me] = r->local_model->n;
      mpm_implicit_held(r->imp, &r->imp_ranks[3 * me + 1],
                        &r->imp_ranks[3 * me + 2]);
      pm_par_sum_long(r->imp_ranks, 3 * size);
    }
    if (!e) e = a;
  }
  e = pm_view_end(&r->view, e);
  /* the solver's time, as stages */
  const pm_load_report *lr = mpm_implicit_report(r->imp);
  pm_timers *t = &r->work->timers;
  pm_timers_init(t);
  t->stage[pm_timers_add(t, "residual")].seconds = lr->time_residual;
  t->stage[pm_timers_add(t, "tangent")].seconds = lr->time_assembly;
  t->stage[pm_timers_add(t, "linear solve")].seconds = lr->time_linear;
  t->stage[pm_timers_add(t, "other (line search, vectors)")].seconds =
      fmax(0, lr->time_total - lr->time_residual - lr->time_assembly -
                  lr->time_linear);
  r->status = pm_static_status(e);
  return e;
}

/* The reactions the solver read from a checkpoint, for the figures. */
static void read_reactions(mpm_sim *r) {
  const mpm_model *m = r->local_model ? r->local_model : r->model;
  memcpy(r->work->cond.reaction, mpm_implicit_reactions(r->imp),
         3 * sizeof(double) * (size_t)m->n_bcs);
}

/* A checkpoint in pieces (mpm_ckpt_pieces.c): each rank's piece holds its
 * particles and its own unknowns of load stepping's states, the index the
 * run's values and the solver's scalars.  Read: on one process or where
 * the run keeps the whole model, every piece now (each rank's particles
 * then take their state); in pieces, each rank's at the run's start
 * (mpm_view_implicit_reload). */
static pm_err implicit_index(mpm_sim *r, pm_ckpt *ck) {
  PM_CALL(mpm_sim_ckpt_index(r, ck));
  PM_CALL(mpm_implicit_checkpoint_scalars(r->imp, ck));
  if (!pm_ckpt_reading(ck)) return PM_SUCCESS;
  read_reactions(r);
  if (r->local_model && !r->ckpt_pieces.on)
    mpm_par_take_state(r->model, r->state, r->local_model, r->local_state);
  return PM_SUCCESS;
}

static pm_err implicit_checkpoint(void *p, pm_ckpt *ck) {
  mpm_sim *r = p;
  if (pm_ckpt_reading(ck) ? mpm_sim_ckpt_is_pieces(ck) : !r->whole)
    return implicit_index(r, ck);
  /* A rank without the whole model reads a checkpoint of the whole run
   * into one, whose state its particles then take (and which a run in
   * pieces then lets go: mpm_view_drop_whole). */
  if (pm_ckpt_reading(ck) && !r->model) {
    r->ckpt_scalars = r->state; /* (rank 0 without the whole model's) */
    r->state = NULL;
    PM_CALL(mpm_model_create(r->scene, &r->model, &r->state));
  }
  PM_CALL(mpm_state_checkpoint(r->model, r->state, ck));
  /* A resumed run across ranks: each rank's particles take the state read
   * (they are those of its cells by their reference positions, as at the
   * start). */
  if (r->local_model && pm_ckpt_reading(ck))
    mpm_par_take_state(r->model, r->state, r->local_model, r->local_state);
  PM_CALL(mpm_implicit_checkpoint(r->imp, r->model, ck));
  PM_CALL(pm_ckpt_double(ck, "run.min_jacobian", &r->run_min_jacobian));
  PM_CALL(pm_ckpt_long(ck, "run.min_jacobian_step", &r->run_min_jacobian_step));
  if (pm_ckpt_reading(ck)) {
    r->resumed = true;
    read_reactions(r);
    if (!r->whole) mpm_view_drop_whole(r);
  }
  return PM_SUCCESS;
}

const pm_backend mpm_implicit_backend = {
    .method = "mpm-implicit",
    .description = "implicit quasi-static Material Point Method (Newton on "
                   "the grid, PETSc)",
    .section = NULL,
    .dt_safety = 0.5,
    .check = check_implicit,
    .ranks = true,
    .create = implicit_create,
    .estimate_bytes = mpm_implicit_estimate_bytes,
    .ghost_layers = mpm_sim_ghost_layers,
    .setup_whole =
        false, /* each rank seeds its share (mpm_par_create_seeded) */
    .destroy = mpm_sim_destroy_any,
    .plan = mpm_sim_implicit_plan,
    .run = implicit_run,
    .points = mpm_sim_points,
    .fields = mpm_sim_fields,
    .displacement = mpm_sim_displacement,
    .figures = mpm_sim_figures,
    .history_names = mpm_sim_history_names,
    .history_values = mpm_sim_history_values,
    .summary = mpm_sim_implicit_summary,
    .timers = mpm_sim_timers,
    .checkpoint = implicit_checkpoint,
    .pieces = mpm_sim_pieces,
    .ckpt_pieces = mpm_sim_ckpt_pieces,
    .pieces_apply = mpm_sim_pieces_apply,
    .errors = mpm_sim_errors,
};
