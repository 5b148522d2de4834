/* mpm_summary: summary.json of an MPM run, explicit and implicit: the
 * grid, groups, stages' energies, and across ranks what the exchanges
 * cost. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_backend_impl.h"
#include "mpm_par.h"
#include "pm_par.h"

const char *mpm_sim_basis_name(mpm_basis b) {
  return b == MPM_BASIS_QUADRATIC ? "quadratic" : "linear";
}

/* "usf", "usl", "musl"; upper case with upper. */
const char *mpm_sim_update_name(mpm_update u, bool upper) {
  static const char *const lower_names[] = {"usf", "usl", "musl"};
  static const char *const upper_names[] = {"USF", "USL", "MUSL"};
  return (upper ? upper_names : lower_names)[u];
}

/* m: the whole model, or a share with its whole run's ranges (whole). */
static pm_err summary_groups(pm_json *j, const mpm_model *m,
                             const mpm_par_ranges *whole) {
  PM_CALL(pm_json_begin_object(j, "groups"));
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    PM_CALL(pm_json_begin_object(j, g->name));
    PM_CALL(pm_json_integer(j, "particles",
                            whole ? whole->gend[gi] - whole->gbegin[gi]
                                  : g->end - g->begin));
    PM_CALL(pm_json_string(j, "kind", g->kind->name));
    PM_CALL(pm_json_integer(j, "bytes_per_particle",
                            (long long)(mpm_particle_bytes_common() +
                                        mpm_group_bytes_per_particle(g))));
    PM_CALL(pm_json_end_object(j));
  }
  return pm_json_end_object(j);
}

/* Each stage's energy accounts (those it keeps). */
static pm_err summary_stage_energy(pm_json *j, const mpm_model *m,
                                   const mpm_state *s) {
  PM_CALL(pm_json_begin_object(j, "energy_by_stage"));
  for (int k = 0; k < m->pipeline.n; k++) {
    const mpm_stage *st = &m->pipeline.stage[k];
    if (!st->books) continue;
    PM_CALL(pm_json_begin_object(j, st->name));
    if (st->books & MPM_BOOKS_WORK)
      PM_CALL(pm_json_number(j, "work", s->energy[k].work));
    if (st->books & MPM_BOOKS_DISSIPATED)
      PM_CALL(pm_json_number(j, "dissipated", s->energy[k].dissipated));
    PM_CALL(pm_json_end_object(j));
  }
  return pm_json_end_object(j);
}

/* The most particles a rank held (of counts[stride * k], rank k) over the
 * mean a rank holds (of the totals in `of`, alike). */
static double imbalance(const long *counts, const long *of, int size,
                        int stride) {
  long most = 0, sum = 0;
  for (int k = 0; k < size; k++) {
    const long c = counts[(size_t)stride * k];
    most = c > most ? c : most;
    sum += of[(size_t)stride * k];
  }
  return sum > 0 ? (double)most * size / (double)sum : 1;
}

/* Each rank's particles at the end and the most it held, and the
 * imbalance of the cut (the busiest rank over the mean) at the start, at
 * the end and at its worst: what a cut made once has lost as the
 * particles travelled. */
static pm_err summary_held(pm_json *j, const mpm_decomp *d, const long *held,
                           const double steps[2]) {
  const char *names[2] = {"particles_at_end", "particles_most"};
  for (int k = 0; k < 2; k++) {
    PM_CALL(pm_json_begin_array(j, names[k]));
    for (int q = 0; q < d->size; q++)
      PM_CALL(pm_json_integer(j, NULL, held[2 * q + k]));
    PM_CALL(pm_json_end_array(j));
  }
  PM_CALL(pm_json_begin_object(j, "imbalance"));
  /* the busiest rank's particles over the mean, every 20 steps, summed:
   * what the load costs a step's pace over the run (the efficiency the
   * ranks' counts allow is its inverse) */
  PM_CALL(
      pm_json_number(j, "over_run", steps[1] > 0 ? steps[0] / steps[1] : 1));
  const long *start0 = d->count0 ? d->count0 : d->count;
  PM_CALL(pm_json_number(j, "at_start", imbalance(start0, start0, d->size, 1)));
  PM_CALL(pm_json_number(j, "at_end", imbalance(held, held, d->size, 2)));
  /* (the most a rank held at any time, over the mean at the end) */
  PM_CALL(pm_json_number(j, "most", imbalance(held + 1, held, d->size, 2)));
  return pm_json_end_object(j);
}

/* The decomposition and what the exchanges cost (summed over the ranks;
 * seconds of the slowest rank). */
static pm_err summary_ranks(pm_json *j, const mpm_sim *r) {
  const mpm_decomp *d = mpm_par_decomp(r->local_model);
  const double *c = r->ranks_counts;
  const double steps = r->state->step > 0 ? (double)r->state->step : 1;
  PM_CALL(pm_json_begin_object(j, "ranks"));
  PM_CALL(pm_json_integer(j, "count", d->size));
  PM_CALL(pm_json_begin_array(j, "cuts"));
  for (int a = 0; a < 3; a++) PM_CALL(pm_json_integer(j, NULL, d->cuts[a]));
  PM_CALL(pm_json_end_array(j));
  PM_CALL(pm_json_begin_array(j, "particles_at_start"));
  const long *start = d->count0 ? d->count0 : d->count;
  for (int k = 0; k < d->size; k++) PM_CALL(pm_json_integer(j, NULL, start[k]));
  PM_CALL(pm_json_end_array(j));
  /* the boxes cut anew as the particles travelled (mpm.rebalance), and
   * the particles per rank of the last cut */
  PM_CALL(pm_json_integer(j, "recuts", d->recuts));
  PM_CALL(pm_json_number(j, "recut_seconds", c[11]));
  if (d->recuts > 0) {
    PM_CALL(pm_json_begin_array(j, "particles_at_last_cut"));
    for (int k = 0; k < d->size; k++)
      PM_CALL(pm_json_integer(j, NULL, d->count[k]));
    PM_CALL(pm_json_end_array(j));
  }
  if (r->ranks_held) PM_CALL(summary_held(j, d, r->ranks_held, c + 9));
  /* what a rank sent, on average */
  PM_CALL(pm_json_number(j, "node_bytes_per_step", c[0] / steps / d->size));
  PM_CALL(pm_json_number(j, "particle_bytes_per_step", c[1] / steps / d->size));
  /* the ghosts of linked points (membranes' neighbours) */
  PM_CALL(pm_json_number(j, "ghost_bytes_per_step", c[8] / steps / d->size));
  PM_CALL(pm_json_number(j, "particles_migrated", c[2]));
  PM_CALL(pm_json_number(j, "arrays_grown", c[3]));
  PM_CALL(pm_json_number(j, "node_exchange_seconds", c[4]));
  PM_CALL(pm_json_number(j, "migration_seconds", c[5]));
  PM_CALL(pm_json_number(j, "own_work_seconds_max", c[6]));
  PM_CALL(pm_json_number(j, "own_work_seconds_mean", c[7]));
  return pm_json_end_object(j);
}

/* The particles, groups, grid and shape of both methods' summaries: of
 * the whole model, or without it of the share with the whole run's
 * counts. */
static pm_err summary_head(pm_json *j, const mpm_sim *r) {
  const mpm_model *m = r->model ? r->model : r->local_model;
  mpm_par_ranges whole;
  if (!r->model) mpm_par_whole_ranges(m, &whole);
  PM_CALL(pm_json_integer(j, "particles", r->model ? m->n : whole.n));
  PM_CALL(summary_groups(j, m, r->model ? NULL : &whole));
  PM_CALL(pm_json_integer(j, "grid_nodes",
                          r->model ? m->grid.n_nodes : r->sums.grid_nodes));
  PM_CALL(pm_json_number(j, "cell_size", m->grid.h));
  return pm_json_string(j, "shape", mpm_sim_basis_name(m->opt.shape));
}

pm_err mpm_sim_summary(void *p, pm_json *j) {
  const mpm_sim *r = p;
  const mpm_model *m = r->model ? r->model : r->local_model;
  const mpm_state *s = r->state;
  PM_CALL(summary_head(j, r));
  PM_CALL(
      pm_json_string(j, "update", mpm_sim_update_name(m->opt.update, false)));
  PM_CALL(pm_json_number(j, "flip", m->opt.flip));
  if (m->kinds & MPM_KIND_ITERATES) {
    PM_CALL(pm_json_integer(j, "energy_iterations_max", s->iter_max_total));
    PM_CALL(
        pm_json_integer(j, "energy_iterations_capped", s->iter_capped_total));
  }
  if (r->local_model) PM_CALL(summary_ranks(j, r));
  return summary_stage_energy(j, m, s);
}

const pm_timers *mpm_sim_timers(void *p) {
  return &((const mpm_sim *)p)->work->timers;
}

/* The decomposition of an implicit run across ranks: per rank its
 * particles, own unknowns and ghost unknowns, and the bytes a rank
 * receives, on average, in a product with the tangent (its ghosts'
 * values; a residual's or the tangent's assembly sends as many back). */
static pm_err implicit_summary_ranks(pm_json *j, const mpm_sim *r) {
  const mpm_decomp *d = mpm_par_decomp(r->local_model);
  const int size = pm_par_size();
  static const char *const names[3] = {"particles", "unknowns",
                                       "ghost_unknowns"};
  double ghosts = 0;
  PM_CALL(pm_json_begin_object(j, "ranks"));
  PM_CALL(pm_json_integer(j, "count", size));
  PM_CALL(pm_json_begin_array(j, "cuts"));
  for (int a = 0; a < 3; a++) PM_CALL(pm_json_integer(j, NULL, d->cuts[a]));
  PM_CALL(pm_json_end_array(j));
  for (int k = 0; k < 3; k++) {
    PM_CALL(pm_json_begin_array(j, names[k]));
    for (int q = 0; q < size; q++)
      PM_CALL(pm_json_integer(j, NULL, r->imp_ranks[3 * q + k]));
    PM_CALL(pm_json_end_array(j));
  }
  for (int q = 0; q < size; q++) ghosts += (double)r->imp_ranks[3 * q + 2];
  PM_CALL(pm_json_number(j, "halo_bytes_per_product",
                         ghosts * sizeof(double) / size));
  return pm_json_end_object(j);
}

pm_err mpm_sim_implicit_summary(void *p, pm_json *j) {
  const mpm_sim *r = p;
  /* without the whole model: the share's, with the whole run's counts */
  const pm_load_report *lr = mpm_implicit_report(r->imp);
  const mpm_settings *ms = mpm_scene_settings(r->scene);
  long unknowns, entries;
  mpm_implicit_size(r->imp, &unknowns, &entries);
  PM_CALL(summary_head(j, r));
  PM_CALL(pm_json_string(
      j, "grid", ms->implicit.grid == MPM_GRID_KEPT ? "kept" : "reset"));
  PM_CALL(pm_json_string(j, "operator",
                         ms->implicit.op == MPM_OP_MATRIX_FREE ? "matrix-free"
                                                               : "assembled"));
  PM_CALL(pm_json_integer(j, "unknowns", unknowns));
  PM_CALL(pm_json_integer(j, "jacobian_entries", entries));
  PM_CALL(pm_json_number(j, "load_reached", mpm_implicit_lambda(r->imp)));
  PM_CALL(pm_json_integer(j, "load_steps", lr->steps));
  PM_CALL(pm_json_integer(j, "load_cuts", lr->cuts));
  PM_CALL(pm_json_integer(j, "newton_iterations", lr->newton_iterations));
  PM_CALL(pm_json_integer(j, "linear_iterations", lr->linear_iterations));
  PM_CALL(pm_json_number(j, "residual_seconds", lr->time_residual));
  PM_CALL(pm_json_number(j, "tangent_seconds", lr->time_assembly));
  PM_CALL(pm_json_number(j, "linear_seconds", lr->time_linear));
  if (r->imp_ranks) PM_CALL(implicit_summary_ranks(j, r));
  return PM_SUCCESS;
}
