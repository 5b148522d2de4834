/* fpm_backend_figures: what the run driver reads of an FPM simulation:
 * its points and fields, the figures, the history's columns and the
 * summary. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_backend_impl.h"
#include "fpm_gfd.h"
#include "fpm_par.h"
#include "pm_cavitation.h"
#include "pm_metrics.h"
#include "pm_omp.h"
#include "pm_par.h"
#include "pm_tensor.h"

void fpm_backend_cauchy_stress(long n, const fpm_state *st, double *sig) {
  PM_OMP(parallel for schedule(static) default(none) shared(n, st, sig))
  for (long i = 0; i < n; i++) {
    double F[9], FT[9];
    for (int a = 0; a < 9; a++) F[a] = st->H[9 * i + a];
    F[0] += 1;
    F[4] += 1;
    F[8] += 1;
    pm_t_transpose(F, FT);
    pm_t_mul(st->P + 9 * i, FT, sig + 9 * i);
    for (int a = 0; a < 9; a++) sig[9 * i + a] /= st->J[i];
  }
}

/* Whether point i is inside the body: its interfaces' area vectors close
 * (a point on the boundary has facets, which close them). */
static bool inside(const fpm_model *m, long i) {
  const double *a = m->p_area + 3 * i;
  return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) <=
         1e-8 * pow(m->dual->volume[i], (m->dim - 1.0) / m->dim);
}

void fpm_backend_tension(const fpm_model *m, long n, const double *sig,
                         bool spherical, fpm_tension *t) {
  /* A material's load is computed only where a point inside holds it in
   * tension (about 20 ms a material). */
  double load[FPM_MAX_MATERIALS] = {0};
  bool pulled[FPM_MAX_MATERIALS] = {false};
  for (long i = 0; i < n && spherical; i++) {
    const double *s = sig + 9 * i;
    if (s[0] + s[4] + s[8] > 0 && inside(m, i)) pulled[m->mat[i]] = true;
  }
  for (int k = 0; k < m->n_mats; k++) {
    load[k] = pulled[k] ? pm_cavitation_load(&m->mats[k]) : 0;
    if (!(isfinite(load[k]) && load[k] > 0)) load[k] = 0;
  }
  *t = (fpm_tension){.tension = -INFINITY, .tension_at = -1, .ratio_at = -1};
  for (long i = 0; i < n; i++) {
    const double *s = sig + 9 * i, p = (s[0] + s[4] + s[8]) / 3;
    /* (a void does not open on the body's boundary) */
    const double l = load[m->mat[i]] > 0 && inside(m, i) ? load[m->mat[i]] : 0;
    if (p > t->tension) {
      t->tension = p;
      t->tension_at = i;
    }
    if (l > 0 && (t->ratio_at < 0 || p / l > t->ratio)) {
      t->ratio = p / l;
      t->ratio_at = i;
      t->load = l;
    }
  }
}

void fpm_backend_points(void *p, pm_points *pts) {
  const fpm_sim *sim = p;
  /* Frames in pieces hold points in piece order, over which one process's
   * cells cannot be drawn: the points alone (each frame's geometry its
   * field "position"), from the whole model or, without it, the positions
   * gathered for the purpose. */
  if (sim->pieces) {
    *pts = (pm_points){.n = sim->n_whole,
                       .x = sim->model ? sim->model->x : sim->mesh_x,
                       .nodes_per_cell = 1};
    return;
  }
  *pts = (pm_points){.n = sim->model->n,
                     .x = sim->model->x,
                     .n_cells = sim->mesh->n_cells,
                     .nodes_per_cell = sim->mesh->nodes_per_cell,
                     .cells = sim->mesh->cells};
}

const double *fpm_backend_displacement(void *p) {
  return ((fpm_sim *)p)->state->u;
}

/* The fields wanted of the first n points of state st into out[0..max)
 * (at least 8), the stress and its invariants made in scratch (11 n);
 * how many. */
static int state_fields(long n, const fpm_state *st, double *scratch,
                        unsigned want, pm_field *out, int max) {
  int nf = 0;
  if (max < 8) return 0;
  if (want & PM_FIELD_DISPLACEMENT)
    out[nf++] = (pm_field){"displacement", 3, st->u};
  if (want & PM_FIELD_VELOCITY) out[nf++] = (pm_field){"velocity", 3, st->v};
  if (want & PM_FIELD_STRESS) {
    double *vm = scratch + 9 * n, *p_mean = vm + n;
    fpm_backend_cauchy_stress(n, st, scratch);
    pm_stress_invariants(n, scratch, vm, p_mean);
    out[nf++] = (pm_field){"stress", 9, scratch};
    out[nf++] = (pm_field){"von_mises", 1, vm};
    out[nf++] = (pm_field){"pressure", 1, p_mean};
  }
  if (want & PM_FIELD_STRAIN_ENERGY_DENSITY)
    out[nf++] = (pm_field){"strain_energy_density", 1, st->W};
  if (want & PM_FIELD_JACOBIAN) out[nf++] = (pm_field){"jacobian", 1, st->J};
  if (want & PM_FIELD_FORCE) out[nf++] = (pm_field){"force", 3, st->f};
  return nf;
}

int fpm_backend_fields(void *p, unsigned want, pm_field *out, int max) {
  fpm_sim *sim = p;
  return state_fields(sim->model->n, sim->state, sim->scratch, want, out, max);
}

/* This rank's own points' fields of a frame in pieces into fields: their
 * current positions (the frame's geometry), then the scene's; how many. */
static int piece_fields(fpm_sim *sim, pm_field *fields) {
  const fpm_model *m = sim->local_model;
  const fpm_state *st = sim->local_state;
  const long own = m->n_own;
  double *position = sim->share_scratch + 11 * own;
  for (long k = 0; k < 3 * own; k++) position[k] = m->x[k] + st->u[k];
  fields[0] = (pm_field){"position", 3, position};
  return 1 + state_fields(own, st, sim->share_scratch,
                          sim->scene->output.fields, fields + 1,
                          PM_VIEW_FIELDS - 1);
}

pm_err fpm_backend_piece(void *p, const char *dir, long frame,
                         const pm_step_report *r, long *n, int *n_fields,
                         pm_field *fields) {
  fpm_sim *sim = p;
  /* (r is rank 0's alone: the share's state has the step and time) */
  const fpm_state *st = sim->local_state;
  *n_fields = piece_fields(sim, fields);
  *n = sim->local_model->n_own;
  (void)r;
  return pm_results_write_piece(dir, frame, pm_par_rank(), *n,
                                sim->local_model->gid, st->step, st->t,
                                *n_fields, fields);
}

const pm_view_pieces *fpm_backend_pieces(void *p) {
  return pm_view_frame_pieces(&((const fpm_sim *)p)->view);
}

/* Mean strain energy density, largest von Mises stress and smallest J of
 * the current fields, with their points. */
static void field_figures(fpm_sim *sim, pm_figures *f) {
  const fpm_model *m = sim->model;
  const fpm_state *st = sim->state;
  const double *vol = sim->dual->volume, *sig = sim->scratch;
  fpm_backend_cauchy_stress(m->n, st, sim->scratch);
  double vsum = 0, wsum = 0;
  long vm_at = 0, j_at = 0;
  f->max_von_mises = -1;
  f->end_min_jacobian = INFINITY;
  for (long i = 0; i < m->n; i++) {
    vsum += vol[i];
    wsum += vol[i] * st->W[i];
    double vm = pm_t_von_mises(sig + 9 * i);
    if (vm > f->max_von_mises) {
      f->max_von_mises = vm;
      vm_at = i;
    }
    if (st->J[i] < f->end_min_jacobian) {
      f->end_min_jacobian = st->J[i];
      j_at = i;
    }
  }
  f->mean_sed = vsum > 0 ? wsum / vsum : 0;
  fpm_tension tn;
  fpm_backend_tension(m, m->n, sig, sim->scene->dimension == 3, &tn);
  f->tension = m->n > 0;
  f->max_tension = tn.tension;
  f->cavitation_ratio = tn.ratio;
  f->cavitation_load = tn.load;
  for (int a = 0; a < 3; a++) {
    f->max_von_mises_at[a] = m->x[3 * vm_at + a];
    f->end_min_jacobian_at[a] = m->x[3 * j_at + a];
    f->max_tension_at[a] = tn.tension_at < 0 ? 0 : m->x[3 * tn.tension_at + a];
    f->cavitation_ratio_at[a] = tn.ratio_at < 0 ? 0 : m->x[3 * tn.ratio_at + a];
  }
}

/* The end's field figures summed over the shares (fpm_view_sums.c). */
static void summed_figures(const fpm_sums *u, pm_figures *f) {
  f->mean_sed = u->mean_sed;
  f->max_von_mises = u->max_von_mises;
  f->end_min_jacobian = u->end_min_jacobian;
  memcpy(f->max_von_mises_at, u->max_von_mises_at, sizeof f->max_von_mises_at);
  memcpy(f->end_min_jacobian_at, u->end_min_jacobian_at,
         sizeof f->end_min_jacobian_at);
  f->tension = true;
  f->max_tension = u->max_tension;
  f->cavitation_ratio = u->cavitation_ratio;
  f->cavitation_load = u->cavitation_load;
  memcpy(f->max_tension_at, u->max_tension_at, sizeof f->max_tension_at);
  memcpy(f->cavitation_ratio_at, u->cavitation_ratio_at,
         sizeof f->cavitation_ratio_at);
}

void fpm_backend_figures(void *p, pm_figures *f, bool with_fields) {
  fpm_sim *sim = p;
  const fpm_model *m = sim->model;
  const pm_scene *s = sim->scene;
  const fpm_step_info *l = &sim->last;
  f->status = sim->status;
  f->dim = sim->scene->dimension;
  f->points = sim->n_whole;
  f->steps = l->step;
  f->time = l->t;
  f->h = sim->mean_edge;
  f->dt = sim->dt;
  f->dt_stable = sim->dt_stable;
  f->support_speed = sim->support_speed;
  f->residual = l->residual;
  f->kinetic = l->kinetic;
  f->strain = l->strain;
  f->internal = 0;
  f->interface = l->penalty;
  f->external_work = l->external_work;
  f->dissipated = l->dissipated;
  f->energy0 = 0;
  f->energy_error = fpm_energy_error(l);
  f->max_energy_error = sim->run_max_energy_error;
  f->min_jacobian = sim->run_min_jacobian;
  f->min_jacobian_step = sim->run_min_jacobian_step;
  for (int b = 0; b < s->n_bcs && b < PM_FIGURES_MAX_BCS; b++)
    if (m)
      fpm_reaction(m, sim->state, b, f->reaction[b]);
    else
      memcpy(f->reaction[b], sim->sums.reaction[b], sizeof f->reaction[b]);
  f->setup_seconds = sim->setup_wall;
  f->step_seconds = pm_timers_seconds(&sim->timers, sim->tm_force) +
                    pm_timers_seconds(&sim->timers, sim->tm_update);
  f->memory_bytes = m ? fpm_model_bytes(m) + fpm_state_bytes(m) : 0;
  if (sim->local_model)
    f->memory_bytes +=
        fpm_model_bytes(sim->local_model) + fpm_state_bytes(sim->local_model);
  if (with_fields && m)
    field_figures(sim, f);
  else if (with_fields)
    summed_figures(&sim->sums, f);
}

static const char *const own_cols[] = {"damping", "ill_conditioned"};

int fpm_backend_history_names(void *p, const char **names, int max) {
  (void)p;
  int n = 0;
  for (; n < 2 && n < max; n++) names[n] = own_cols[n];
  return n;
}

void fpm_backend_history_values(void *p, double *v) {
  fpm_sim *sim = p;
  v[0] = sim->last.damping;
  v[1] = sim->model ? (double)fpm_sim_conditioning(sim, NULL, NULL)
                    : (double)sim->sums.ill_conditioned;
}

/* The partition and what the exchanges cost (bytes a rank received per
 * step on average; seconds of the slowest rank). */
static pm_err summary_ranks(pm_json *j, const fpm_sim *sim) {
  const fpm_model *lm = sim->local_model;
  const fpm_share_counts *c = fpm_par_counts(lm);
  const double *k = sim->ranks_costs;
  const int size = pm_par_size();
  PM_CALL(pm_json_begin_object(j, "ranks"));
  PM_CALL(pm_json_integer(j, "count", size));
  PM_CALL(pm_json_integer(
      j, "edge_cut",
      sim->model ? fpm_partition_edge_cut(sim->model, fpm_par_owner(lm))
                 : sim->sums.edge_cut));
  PM_CALL(pm_json_begin_array(j, "points"));
  for (int r = 0; r < size; r++) PM_CALL(pm_json_integer(j, NULL, c[r].own));
  PM_CALL(pm_json_end_array(j));
  PM_CALL(pm_json_begin_array(j, "ghost_points"));
  for (int r = 0; r < size; r++)
    PM_CALL(pm_json_integer(
        j, NULL, c[r].flux_ghosts + c[r].stress_ghosts + c[r].u_ghosts));
  PM_CALL(pm_json_end_array(j));
  PM_CALL(
      pm_json_number(j, "ghost_bytes_per_step", k[1] > 0 ? k[0] / k[1] : 0));
  PM_CALL(pm_json_number(j, "exchange_seconds", k[2]));
  PM_CALL(pm_json_number(j, "gather_seconds", k[3]));
  return pm_json_end_object(j);
}

/* The whole model's counts, of the model or summed over the shares. */
static void whole_counts(const fpm_sim *sim, fpm_sums *c) {
  const fpm_model *m = sim->model;
  if (!m) {
    *c = sim->sums;
    return;
  }
  c->cells = sim->mesh->n_cells;
  c->interfaces = sim->dual->n_ifaces;
  c->facets = sim->dual->n_facets;
  c->cdofs = m->n_cdofs;
  c->qwide = m->n_qwide;
  c->qlinear = m->n_qlinear;
  c->ill_conditioned = fpm_sim_conditioning(sim, &c->worst_condition, NULL);
}

pm_err fpm_backend_summary(void *p, pm_json *j) {
  fpm_sim *sim = p;
  /* (the scalars of the whole model are its shares' too) */
  const fpm_model *m = sim->model ? sim->model : sim->local_model;
  const pm_scene *s = sim->scene;
  fpm_sums c;
  whole_counts(sim, &c);
  PM_CALL(pm_json_integer(j, "cells", c.cells));
  PM_CALL(pm_json_integer(j, "interfaces", c.interfaces));
  PM_CALL(pm_json_integer(j, "boundary_facets", c.facets));
  PM_CALL(pm_json_integer(j, "prescribed_dofs", c.cdofs));
  PM_CALL(pm_json_number(j, "mesh_size", s->mesh_size));
  PM_CALL(pm_json_number(j, "mean_edge_length", sim->mean_edge));
  PM_CALL(pm_json_number(j, "penalty", m->penalty));
  PM_CALL(
      pm_json_string(j, "flux", m->flux == FPM_FLUX_SIPG ? "sipg" : "iipg"));
  PM_CALL(pm_json_string(j, "dt_rule",
                         s->time.dt > 0                      ? "time.dt"
                         : s->time.dt_rule == PM_DT_SPECTRAL ? "spectral"
                                                             : "paper"));
  PM_CALL(pm_json_number(j, "dt_paper", sim->dt_paper));
  if (sim->dt_spectral > 0)
    PM_CALL(pm_json_number(j, "dt_spectral", sim->dt_spectral));
  PM_CALL(pm_json_integer(j, "dt_critical_point", sim->dt_point));
  PM_CALL(pm_json_integer(j, "ill_conditioned_points", c.ill_conditioned));
  PM_CALL(pm_json_string(j, "jump", m->q ? "quadratic" : "linear"));
  if (m->boundary_penalty > 0)
    PM_CALL(pm_json_number(j, "boundary_penalty", m->boundary_penalty));
  if (m->stiffening > 0) {
    PM_CALL(pm_json_number(j, "stiffening", m->stiffening));
    PM_CALL(pm_json_string(j, "stiffening_jump",
                           m->stiffen_quadratic ? "quadratic" : "linear"));
    PM_CALL(pm_json_number(j, "stiffening_onset", m->stiffening_onset));
    PM_CALL(pm_json_string(j, "stiffening_spacing",
                           m->stiffen_current ? "current" : "reference"));
  }
  if (m->volume_penalty > 0)
    PM_CALL(pm_json_number(j, "volume_penalty", m->volume_penalty));
  if (sim->local_model) PM_CALL(summary_ranks(j, sim));
  if (m->q) {
    PM_CALL(pm_json_integer(j, "fit_points_two_rings", c.qwide));
    PM_CALL(pm_json_integer(j, "fit_points_linear", c.qlinear));
  }
  if (s->time.qs == PM_QS_STATIC) {
    const fpm_static_report *r = &sim->static_report;
    PM_CALL(pm_json_integer(j, "static_unknowns", r->unknowns));
    PM_CALL(pm_json_integer(j, "static_jacobian_entries", r->pattern_entries));
    PM_CALL(pm_json_integer(j, "static_coupled_entries", r->coupled_entries));
    PM_CALL(pm_json_integer(j, "static_load_steps", r->load.steps));
    PM_CALL(pm_json_integer(j, "static_cuts", r->load.cuts));
    PM_CALL(pm_json_integer(j, "static_newton_iterations",
                            r->load.newton_iterations));
    PM_CALL(pm_json_integer(j, "static_linear_iterations",
                            r->load.linear_iterations));
    PM_CALL(pm_json_number(j, "static_seconds", r->seconds));
    PM_CALL(pm_json_number(j, "static_cpu_seconds", r->cpu_seconds));
    PM_CALL(pm_json_number(j, "static_setup_seconds", r->setup_seconds));
    PM_CALL(
        pm_json_number(j, "static_residual_seconds", r->load.time_residual));
    PM_CALL(pm_json_number(j, "static_tangent_seconds", r->load.time_assembly));
    PM_CALL(pm_json_number(j, "static_pc_setup_seconds", r->load.time_setup));
    PM_CALL(pm_json_integer(j, "static_pc_setups", r->load.pc_setups));
    PM_CALL(pm_json_number(j, "static_linear_seconds", r->load.time_linear));
    PM_CALL(pm_json_number(j, "static_apply_seconds", r->load.time_apply));
    PM_CALL(
        pm_json_number(j, "static_residual_cpu_seconds", r->load.cpu_residual));
    PM_CALL(
        pm_json_number(j, "static_tangent_cpu_seconds", r->load.cpu_assembly));
    PM_CALL(
        pm_json_number(j, "static_pc_setup_cpu_seconds", r->load.cpu_setup));
    PM_CALL(pm_json_number(j, "static_linear_cpu_seconds", r->load.cpu_linear));
    PM_CALL(pm_json_number(j, "static_apply_cpu_seconds", r->load.cpu_apply));
    PM_CALL(
        pm_json_integer(j, "static_residuals", r->load.residual_evaluations));
    PM_CALL(pm_json_integer(j, "static_tangents", r->load.jacobians));
    PM_CALL(
        pm_json_integer(j, "static_products", r->load.jacobian_applications));
    PM_CALL(pm_json_integer(j, "static_relaxations", r->load.relaxations));
    PM_CALL(pm_json_integer(j, "static_relaxed_steps", r->load.relaxed_steps));
    PM_CALL(pm_json_integer(j, "static_relax_iterations",
                            r->load.relax_iterations));
    PM_CALL(pm_json_number(j, "static_relax_seconds", r->load.time_relax));
    PM_CALL(pm_json_integer(j, "static_continuations", r->load.ptc_runs));
    PM_CALL(pm_json_integer(j, "static_continued_steps", r->load.ptc_steps));
    PM_CALL(pm_json_integer(j, "static_continuation_iterations",
                            r->load.ptc_iterations));
    PM_CALL(pm_json_number(j, "static_continuation_seconds", r->load.time_ptc));
    PM_CALL(pm_json_number(j, "static_continuation_curvature",
                           r->load.ptc_curvature));
    PM_CALL(pm_json_integer(j, "static_lowest_modes", r->load.mode_runs));
    PM_CALL(
        pm_json_number(j, "static_lowest_eigenvalue", r->load.mode_eigenvalue));
    PM_CALL(
        pm_json_integer(j, "static_branch_switches", r->load.branch_switches));
    PM_CALL(pm_json_integer(j, "static_arc_lengths", r->load.arc_runs));
    PM_CALL(pm_json_integer(j, "static_arc_passes", r->load.arc_passes));
    PM_CALL(pm_json_integer(j, "static_arcs", r->load.arc_steps));
    PM_CALL(
        pm_json_integer(j, "static_arc_iterations", r->load.arc_iterations));
    PM_CALL(pm_json_number(j, "static_arc_seconds", r->load.time_arc));
    PM_CALL(pm_json_integer(j, "static_snaps", r->load.snap_steps));
    PM_CALL(pm_json_number(j, "static_snap_lambda", r->load.snap_lambda));
    PM_CALL(pm_json_string(j, "static_snap", r->load.snap_note));
    PM_CALL(pm_json_integer(j, "static_fallbacks_timed_out",
                            r->load.fallbacks_timed_out));
    PM_CALL(pm_json_integer(j, "static_resolves", r->load.resolves));
    PM_CALL(pm_json_integer(j, "static_unsettled", r->load.unsettled));
    PM_CALL(pm_json_integer(j, "static_contact_frozen", r->contact_frozen));
    PM_CALL(
        pm_json_number(j, "static_contact_frozen_gap", r->contact_frozen_gap));
  }
  return pm_json_number(j, "max_support_condition", c.worst_condition);
}
