/* mpm_view: rank 0's view of an MPM run across ranks: each rank's share
 * made from the whole model, the time loop of the shares, and the whole
 * run gathered into the view where the run writes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_backend_impl.h"
#include "mpm_par.h"
#include "pm_par.h"

/* Across ranks: this rank's share of the whole model and state, which
 * every rank holds (collective; every rank returns the same error), with
 * the energy accounts of a checkpoint of as many ranks, if given. */
pm_err mpm_view_share(mpm_sim *r, const double *accounts) {
  PM_CALL(pm_par_agree(mpm_par_create(r->scene, r->model, r->state, accounts,
                                      r->ckpt_cut, &r->local_model,
                                      &r->local_state)));
  return pm_par_agree(mpm_work_create(r->local_model, &r->local_work));
}

/* Across ranks, once the run starts: the whole model stays on rank 0 as
 * its view of the run; the other ranks let it go (pm_view.release, called
 * on them alone).  Until then every rank holds it, so that a checkpoint is
 * read into it. */
static void release(void *ctx) {
  mpm_sim *r = ctx;
  if (!r->model) return;
  mpm_state_destroy(r->state);
  mpm_model_destroy(r->model);
  r->state = NULL;
  r->model = NULL;
}

pm_err mpm_view_setup(mpm_sim *r) {
  PM_CALL(mpm_view_share(r, NULL));
  return pm_par_agree(pm_par_root() ? mpm_sim_figures_work(r->model, &r->work)
                                    : PM_SUCCESS);
}

/* Rank 0's view of the last step: the figures every rank shares (the
 * residual, the reactions, the smallest J) and its own timers. */
static void view_figures(mpm_sim *r) {
  const mpm_work *lw = r->local_work;
  mpm_work *w = r->work;
  w->residual = lw->residual;
  w->min_jacobian = lw->min_jacobian;
  w->iter_max = lw->iter_max;
  w->iter_capped = lw->iter_capped;
  const int n_bcs = r->local_model->n_bcs;
  if (n_bcs > 0) /* (a scene without conditions has no array) */
    memcpy(w->cond.reaction, lw->cond.reaction,
           3 * sizeof(double) * (size_t)n_bcs);
  w->timers = lw->timers;
  mpm_state *v = r->state; /* (without the whole model: the scalars) */
  const mpm_state *ls = r->local_state;
  v->t = ls->t;
  v->step = ls->step;
  v->dt = ls->dt;
  v->dt_stable = ls->dt_stable;
}

/* Every rank's particles into rank 0's view, or without the whole model
 * the sums over the shares, with the field figures at the end
 * (collective). */
static pm_err gather(void *ctx) {
  mpm_sim *r = ctx;
  if (!r->whole) {
    PM_CALL(mpm_view_sum(r, r->view.ending));
    if (r->state) view_figures(r);
    return PM_SUCCESS;
  }
  PM_CALL(pm_par_agree(
      mpm_par_gather(r->local_model, r->local_state, r->model, r->state)));
  if (r->model) view_figures(r);
  return PM_SUCCESS;
}

void mpm_view_init(mpm_sim *r, bool implicit) {
  pm_err (*whole)(void *) = implicit ? mpm_view_implicit_gather : gather;
  r->view = (pm_view){.ranks = r->local_model != NULL,
                      .ctx = r,
                      .gather = implicit && !r->whole ? mpm_view_implicit_sums
                                                      : whole,
                      .release = release,
                      .piece = mpm_sim_piece,
                      .ckpt_piece = r->whole || !mpm_sim_ckpt_pieces(r->scene)
                                        ? NULL
                                        : mpm_sim_ckpt_piece};
}

pm_err mpm_view_report(mpm_sim *r, bool frame, bool last) {
  pm_step_report rep = {0};
  if (r->state) { /* one process, or rank 0 */
    if (r->view.ranks) view_figures(r);
    rep = mpm_sim_step_report(r, last);
  }
  return pm_view_step(&r->view, &rep, frame);
}

void mpm_view_drop_share(mpm_sim *r) {
  mpm_work_destroy(r->local_work);
  mpm_state_destroy(r->local_state);
  mpm_model_destroy(r->local_model);
  r->local_work = NULL;
  r->local_state = NULL;
  r->local_model = NULL;
}

void mpm_view_drop_whole(mpm_sim *r) {
  if (!r->model) return;
  if (r->ckpt_scalars) mpm_state_copy_values(r->ckpt_scalars, r->state);
  mpm_state_destroy(r->state);
  mpm_model_destroy(r->model);
  r->state = r->ckpt_scalars;
  r->model = NULL;
  r->ckpt_scalars = NULL;
}

pm_err mpm_view_reshare(mpm_sim *r) {
  mpm_view_drop_share(r);
  return mpm_view_share(r, r->ckpt_ranks == pm_par_size() ? r->ckpt_accounts
                                                          : NULL);
}

pm_err mpm_view_counts(mpm_sim *r) {
  mpm_par_counts c;
  mpm_par_get_counts(r->local_model, &c);
  /* A rank's own work: its stages' time less the exchanges (in which it
   * waits for the others). */
  double own = -c.halo_seconds - c.migrate_seconds;
  const pm_timers *t = &r->local_work->timers;
  for (int k = 0; k < t->n; k++) own += t->stage[k].seconds;
  double sums[6] = {c.halo_bytes,
                    c.migrate_bytes,
                    (double)c.migrated,
                    (double)c.grown,
                    own,
                    c.ghost_bytes},
         most[4] = {c.halo_seconds, c.migrate_seconds, own, c.recut_seconds};
  pm_par_sum(sums, 6);
  pm_par_max(most, 4);
  memcpy(r->ranks_counts, sums, 4 * sizeof(double));
  memcpy(r->ranks_counts + 4, most, 2 * sizeof(double));
  r->ranks_counts[6] = most[2];                 /* the busiest rank's */
  r->ranks_counts[7] = sums[4] / pm_par_size(); /* the mean */
  r->ranks_counts[8] = sums[5];
  r->ranks_counts[9] = c.look_most; /* (every rank's alike) */
  r->ranks_counts[10] = c.look_mean;
  r->ranks_counts[11] = most[3];
  /* Where the particles went: each rank's at the end and its most, the
   * load balance the cut made at the start has kept or lost. */
  const int size = pm_par_size(), me = pm_par_rank();
  pm_err e = r->ranks_held ? PM_SUCCESS
                           : PM_ALLOC(r->ranks_held, 2 * size, "ranks' counts");
  PM_CALL(pm_par_agree(e));
  memset(r->ranks_held, 0, 2 * (size_t)size * sizeof(long));
  r->ranks_held[2 * me] = r->local_model->n;
  r->ranks_held[2 * me + 1] = c.most;
  pm_par_sum_long(r->ranks_held, 2 * size);
  return PM_SUCCESS;
}

/* Across ranks, what rank 0's observer reads of a converged load step:
 * every rank's particles and load stepping's states (collective). */
pm_err mpm_view_implicit_gather(void *ctx) {
  mpm_sim *r = ctx;
  PM_CALL(pm_par_agree(
      mpm_par_gather(r->local_model, r->local_state, r->model, r->state)));
  return mpm_implicit_gather(r->imp, r->model);
}

pm_err mpm_view_implicit_sums(void *ctx) {
  mpm_sim *r = ctx;
  /* (the figures every rank shares are every rank's: implicit_observe) */
  return mpm_view_sum(r, r->view.ending);
}
