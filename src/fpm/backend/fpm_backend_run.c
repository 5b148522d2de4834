/* fpm_backend_run: the run of an FPM simulation for the run driver: the
 * time loop or the static solve, on one process or on this rank's share
 * with rank 0's view of the whole run gathered where the run writes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_backend_impl.h"
#include "fpm_par.h"
#include "pm_par.h"

/* Each step of fpm_run: the run's figures, and the report to the run's
 * observer with a progress fraction (time, or the residual's way to its
 * tolerance once the loads are on). */
static pm_step_report note_step(fpm_sim *sim, const fpm_step_info *info) {
  const pm_scene *s = sim->scene;
  sim->last = *info;
  if (info->min_jacobian < sim->run_min_jacobian) {
    sim->run_min_jacobian = info->min_jacobian;
    sim->run_min_jacobian_step = info->step;
  }
  if (info->energy_checked &&
      fabs(info->energy_error) > sim->run_max_energy_error)
    sim->run_max_energy_error = fabs(info->energy_error);
  double frac = info->t / s->time.end, load_end = sim->load_end;
  if (s->time.qs == PM_QS_STATIC) {
    frac = load_end > 0 ? info->t / load_end : 1;
  } else if (s->time.qs != PM_QS_NONE && info->t >= load_end && sim->res0 > 0 &&
             info->residual > 0) {
    double q =
        log(sim->res0 / info->residual) / log(sim->res0 / s->time.qs_tolerance);
    if (q > frac) frac = q;
  } else if (info->step > 0 && info->t >= load_end && sim->res0 == 0) {
    sim->res0 = info->residual;
  }
  return (pm_step_report){.last = info->last,
                          .step = info->step,
                          .t = info->t,
                          .residual = info->residual,
                          .progress = frac};
}

/* Load stepping's scalars (where it stands, its last step, the work
 * done) from one static state to another; the displacements apart. */
static void load_scalars(fpm_static_state *to, const fpm_static_state *from) {
  to->load.lambda = from->load.lambda;
  to->load.lambda_prev = from->load.lambda_prev;
  to->load.dl = from->load.dl;
  to->load.good = from->load.good;
  to->load.have_prev = from->load.have_prev;
  to->load.pc_built = from->load.pc_built;
  to->load.pc_its = from->load.pc_its;
  to->load.pc_failed = from->load.pc_failed;
  to->load.pc_lambda = from->load.pc_lambda;
  to->load.pc_first_its = from->load.pc_first_its;
  to->load.fallback_kept = from->load.fallback_kept;
  to->load.relax_first = from->load.relax_first;
  to->load.relax_carried = from->load.relax_carried;
  to->load.done = from->load.done;
  to->external_work = from->external_work;
}

/* A load state's k-th state over the free dofs: the last converged, the
 * one before, the kept factorisation's. */
static double *load_state_x(const fpm_static_state *s, int k) {
  return k == 0 ? s->load.xc : k == 1 ? s->load.xprev : s->load.pc_x;
}

/* A static solve across ranks: the shares' load stepping into rank 0's
 * whole one, in one process's order (its three states through the points'
 * displacements), for a checkpoint (collective). */
static pm_err gather_static(fpm_sim *sim) {
  const fpm_model *lm = sim->local_model, *m = sim->model;
  const fpm_static_state *ls = &sim->local_static;
  fpm_static_state *ws = &sim->static_state;
  for (int k = 0; k < 3; k++) {
    fpm_static_nodal(lm, load_state_x(ls, k), sim->static_local);
    PM_CALL(fpm_par_gather_points(lm, sim->static_local,
                                  pm_par_root() ? sim->static_whole : NULL));
    if (pm_par_root())
      fpm_static_unknowns(m, sim->static_whole, load_state_x(ws, k));
  }
  if (!pm_par_root()) return PM_SUCCESS;
  load_scalars(ws, ls);
  return PM_SUCCESS;
}

void fpm_backend_scatter_static(fpm_sim *sim, const unsigned char *fixed,
                                long n, const fpm_static_state *ws,
                                double *nodal) {
  const fpm_model *lm = sim->local_model;
  fpm_static_state *ls = &sim->local_static;
  double *held = sim->local_state->u; /* 3 per point held */
  for (int k = 2; k >= 0; k--) {      /* xc last: its displacements stay */
    fpm_static_nodal_fixed(n, fixed, load_state_x(ws, k), nodal);
    for (long i = 0; i < lm->n; i++)
      memcpy(held + 3 * i, nodal + 3 * lm->gid[i], 3 * sizeof(double));
    fpm_static_unknowns(lm, held, load_state_x(ls, k));
  }
  load_scalars(ls, ws);
}

/* Every rank's share of the state into rank 0's view, or without the
 * whole model the figures summed over the shares, with the field figures
 * at the end (collective). */
static pm_err gather(void *ctx) {
  fpm_sim *sim = ctx;
  if (!sim->whole) return fpm_view_sum(sim, sim->view.ending);
  PM_CALL(pm_par_agree(fpm_par_gather(sim->local_model, sim->local_state,
                                      pm_par_root() ? sim->state : NULL)));
  if (sim->scene->time.qs == PM_QS_STATIC)
    PM_CALL(pm_par_agree(gather_static(sim)));
  return PM_SUCCESS;
}

/* Across ranks rank 0 reports, with the state gathered where its observer
 * reads it (collective). */
static pm_err observe(void *ctx, const fpm_model *m, const fpm_state *st,
                      const fpm_step_info *info, bool frame) {
  fpm_sim *sim = ctx;
  (void)m;
  (void)st;
  pm_step_report r = note_step(sim, info);
  return pm_view_step(&sim->view, &r, frame);
}

/* A signal stopped a load step inside its solve across ranks: the last
 * converged step to the observer once more (pm_view_stopped_inside).  On
 * one process the run driver writes that checkpoint itself. */
static pm_err stopped_inside(fpm_sim *sim, pm_err e) {
  if (e != PM_ERR_INTERRUPTED || !sim->local_model || sim->last.step <= 0)
    return e;
  fpm_step_info last = sim->last;
  last.last = false;
  pm_step_report rep = note_step(sim, &last);
  return pm_view_stopped_inside(&sim->view, &rep, e);
}

/* ---- across ranks ---- */

/* Across ranks, once the run starts: the whole model stays on rank 0 as
 * its view of the run; the other ranks let it go (pm_view.release). */
static void release_view(void *ctx) {
  fpm_sim *sim = ctx;
  fpm_state_destroy(sim->state);
  fpm_model_destroy(sim->model);
  gm_dual_destroy(sim->dual);
  gm_mesh_destroy(sim->mesh);
  free(sim->scratch);
  sim->state = NULL;
  sim->model = NULL;
  sim->dual = NULL;
  sim->mesh = NULL;
  sim->scratch = NULL;
}

/* What the exchanges cost over the run, summed over the ranks (the
 * seconds of the slowest rank), for the summary. */
static void ranks_costs(fpm_sim *sim) {
  fpm_par_costs c;
  fpm_par_get_costs(sim->local_model, &c);
  double sums[2] = {c.ghost_bytes, (double)c.exchanges},
         most[2] = {c.exchange_seconds, c.gather_seconds};
  pm_par_sum(sums, 2);
  pm_par_max(most, 2);
  memcpy(sim->ranks_costs, sums, sizeof sums);
  memcpy(sim->ranks_costs + 2, most, sizeof most);
}

void fpm_backend_view_init(fpm_sim *sim) {
  sim->view = (pm_view){.ranks = sim->local_model != NULL,
                        .ctx = sim,
                        .gather = gather,
                        .release = release_view,
                        .piece = sim->pieces ? fpm_backend_piece : NULL};
}

pm_err fpm_backend_run(void *p, const pm_observer *obs) {
  fpm_sim *sim = p;
  const pm_scene *s = sim->scene;
  fpm_model *m = sim->model;
  fpm_run_options opt = {
      .dt = sim->dt,
      .t_end = s->time.end,
      .max_steps = s->time.max_steps,
      .qs = s->time.qs,
      .qs_tolerance = s->time.qs_tolerance,
      .damping = s->time.qs_damping,
      .frame_every = s->output.every,
      .min_jacobian = s->stability.min_jacobian,
      .max_energy_error = s->stability.max_energy_error,
  };
  /* Across ranks, this rank's share: from the checkpoint every rank read
   * into the whole state, when resumed. */
  fpm_model *lm = sim->local_model ? sim->local_model : m;
  fpm_state *st = sim->local_model ? sim->local_state : sim->state;
  const bool is_static = s->time.qs == PM_QS_STATIC;
  if (sim->local_model && sim->resumed && !sim->scattered) {
    if (is_static)
      fpm_backend_scatter_static(sim, m->fixed, m->n, &sim->static_state,
                                 sim->static_whole);
    else
      fpm_par_scatter(lm, sim->state, st);
  }
  free(sim->mesh_x); /* (the results' mesh is written) */
  sim->mesh_x = NULL;
  pm_view_start(&sim->view, obs);
  pm_err e = pm_view_start_pieces(&sim->view, s); /* (agreed) */
  if (!sim->resumed) { /* a resumed run has these from its checkpoint */
    if (!is_static || !sim->local_model)
      memset(st->u, 0, 3 * lm->n * sizeof(double));
    memset(st->v, 0, 3 * lm->n * sizeof(double));
    st->step = 0;
    sim->run_min_jacobian = INFINITY;
    sim->run_min_jacobian_step = 0;
    sim->run_max_energy_error = 0;
    sim->res0 = 0;
  }
  sim->load_end = pm_scene_load_end(s);
  double stage[2] = {0, 0};
  if (is_static) {
    fpm_static_report *r = &sim->static_report;
    double w0 = pm_wtime();
    if (!e)
      e = fpm_static_run_from(
          lm, st, sim->local_model ? &sim->local_static : &sim->static_state,
          observe, sim, &sim->last, r);
    e = stopped_inside(sim, e);
    double wall = pm_wtime() - w0;
    e = pm_view_end(&sim->view, e); /* the state it ended in, for figures */
    if (sim->local_model) ranks_costs(sim);
    pm_stage *tm = sim->timers.stage;
    tm[sim->tm_force].seconds += r->load.time_residual;
    tm[sim->tm_force].calls += r->load.newton_iterations;
    tm[sim->tm_assembly].seconds += r->load.time_assembly;
    tm[sim->tm_assembly].calls += r->load.newton_iterations;
    tm[sim->tm_pcsetup].seconds += r->load.time_setup;
    tm[sim->tm_pcsetup].calls += r->load.newton_iterations;
    tm[sim->tm_linear].seconds += r->load.time_linear - r->load.time_setup;
    tm[sim->tm_linear].calls += r->load.newton_iterations;
    tm[sim->tm_update].seconds += wall - r->load.time_residual -
                                  r->load.time_assembly - r->load.time_linear;
    tm[sim->tm_update].calls += r->load.steps;
    sim->status = pm_static_status(e);
    return e;
  }
  sim->first_step = st->step;
  /* The explicit loop of the plain formulation reads its support entries
   * from the stream alone (a plan, made from the same model, still builds
   * shares from the records). */
  if (sim->model) fpm_model_drop_static(sim->model); /* (a view released) */
  if (sim->local_model) fpm_model_drop_static(sim->local_model);
  if (!e) e = fpm_run(lm, st, &opt, observe, sim, &sim->last, stage);
  e = pm_view_end(&sim->view, e); /* the state it ended in, for figures */
  if (sim->local_model) ranks_costs(sim);
  sim->timers.stage[sim->tm_force].seconds += stage[0];
  sim->timers.stage[sim->tm_force].calls += sim->last.step + 1;
  sim->timers.stage[sim->tm_update].seconds += stage[1];
  sim->timers.stage[sim->tm_update].calls += sim->last.step;
  if (e == PM_ERR_UNSTABLE)
    sim->status = PM_STATUS_UNSTABLE;
  else if (e != PM_SUCCESS)
    sim->status = PM_STATUS_FAILED;
  else if (s->time.qs == PM_QS_NONE)
    sim->status = PM_STATUS_COMPLETED;
  else
    sim->status =
        sim->last.converged ? PM_STATUS_CONVERGED : PM_STATUS_NOT_CONVERGED;
  return e;
}
