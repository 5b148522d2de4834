/* fpm_backend: sets up an FPM simulation from a scene and runs it for the
 * run driver (pm_run): observer, fields, figures, history, summary and the
 * plan. */
#include "fpm_backend.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_estimate.h"
#include "fpm_gfd.h"
#include "fpm_par.h"
#include "fpm_scene.h"
#include "gm_cells.h"
#include "pm_files.h"
#include "pm_metrics.h"
#include "pm_omp.h"
#include "pm_par.h"
#include "pm_tensor.h"

void fpm_sim_destroy(fpm_sim *sim) {
  if (!sim) return;
  fpm_state_destroy(sim->local_state);
  fpm_model_destroy(sim->local_model);
  fpm_static_state_free(&sim->static_state);
  fpm_static_state_free(&sim->local_static);
  free(sim->static_local);
  free(sim->static_whole);
  fpm_state_destroy(sim->state);
  fpm_model_destroy(sim->model);
  gm_dual_destroy(sim->dual);
  gm_mesh_destroy(sim->mesh);
  free(sim->scratch);
  free(sim);
}

pm_err fpm_sim_create(const pm_scene *s, fpm_sim **out) {
  pm_err ret = PM_SUCCESS;
  fpm_sim *sim = NULL;
  *out = NULL;
  PM_ENSURE(s->method && strcmp(s->method, "fpm") == 0, PM_ERR_ARG,
            "fpm_sim_create: scene %s has method %s", s->path,
            s->method ? s->method : "(none)");
  PM_TRY(PM_ALLOC(sim, 1, "FPM simulation"));
  sim->scene = s;
  pm_timers_init(&sim->timers);
  sim->tm_mesh = pm_timers_add(&sim->timers, "mesh (gmsh)");
  sim->tm_dual = pm_timers_add(&sim->timers, "subdomains");
  sim->tm_operators = pm_timers_add(&sim->timers, "GFD operators and BCs");
  sim->tm_force = pm_timers_add(&sim->timers, "internal force");
  sim->tm_assembly = sim->tm_linear = -1;
  if (s->time.qs == PM_QS_STATIC) {
    sim->tm_update = pm_timers_add(&sim->timers, "load steps and output");
    sim->tm_assembly = pm_timers_add(&sim->timers, "tangent (colouring)");
    sim->tm_linear = pm_timers_add(&sim->timers, "linear solves");
  } else {
    sim->tm_update = pm_timers_add(&sim->timers, "time integration");
  }
  double t0 = pm_wtime();
  pm_timers_start(&sim->timers, sim->tm_mesh);
  /* The domain: the box, or the scene's one gmsh volume. */
  int domain = fpm_domain_body(s);
  if (domain >= 0)
    PM_TRY(gm_mesh_file(s->bodies[domain].mesh, s->dimension, s->mesh_size,
                        &sim->mesh));
  else
    PM_TRY(gm_mesh_box(s->dimension, s->box_min, s->box_max, s->mesh_size,
                       &sim->mesh));
  pm_timers_stop(&sim->timers, sim->tm_mesh);
  sim->mean_edge = gm_mesh_mean_edge(sim->mesh);
  pm_timers_start(&sim->timers, sim->tm_dual);
  const fpm_options *o = fpm_scene_options(s);
  sim->cells = gm_cells_find(o->cells);
  PM_TRY(sim->cells->build(sim->mesh, &sim->dual));
  pm_timers_stop(&sim->timers, sim->tm_dual);
  pm_timers_start(&sim->timers, sim->tm_operators);
  PM_TRY(fpm_model_create(s, o, sim->mesh, sim->dual, &sim->model));
  PM_TRY(fpm_state_create(sim->model, &sim->state));
  if (s->time.qs == PM_QS_STATIC)
    PM_TRY(fpm_static_state_init(&sim->static_state, sim->model));
  PM_TRY(PM_ALLOC(sim->scratch, 11 * sim->model->n, "output buffer"));
  sim->dt_paper = fpm_stable_dt(sim->model, &sim->dt_point);
  sim->dt_stable = sim->dt_paper;
  if (s->time.dt_rule == PM_DT_SPECTRAL) {
    fpm_sim_measure_spectrum(sim);
    sim->dt_stable = sim->dt_spectral;
  }
  sim->dt = s->time.dt > 0 ? s->time.dt : s->time.dt_safety * sim->dt_stable;
  pm_timers_stop(&sim->timers, sim->tm_operators);
  sim->setup_wall = pm_wtime() - t0;
  *out = sim;
  sim = NULL;
done:
  fpm_sim_destroy(sim);
  return ret;
}

/* Power iterations for the spectral radius: the Rayleigh quotient
 * approaches it from below, to within a percent on the meshes tried. */
#define FPM_SPECTRAL_ITERATIONS 100

void fpm_sim_measure_spectrum(fpm_sim *sim) {
  if (sim->dt_spectral > 0) return;
  double lambda;
  sim->dt_spectral = fpm_spectral_dt(
      sim->model, sim->state, FPM_SPECTRAL_ITERATIONS, sim->scratch, &lambda);
}

/* Cauchy stress sigma = P F^T / J per point into scratch. */
static void cauchy_stress(const fpm_model *m, const fpm_state *st,
                          double *sig) {
  const long n = m->n;
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

long fpm_sim_conditioning(const fpm_sim *sim, double *worst,
                          long *worst_point) {
  const fpm_model *m = sim->model;
  return fpm_gfd_deformed_condition(m->dim, m->n, m->x, sim->state->u,
                                    m->nbr_ptr, sim->dual->nbr, FPM_COND_MAX,
                                    worst, worst_point);
}

/* ---- run ---------------------------------------------------------------- */

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
  to->external_work = from->external_work;
}

/* A static solve across ranks: the shares' load stepping into rank 0's
 * whole one, in one process's order (its two states through the points'
 * displacements), for a checkpoint (collective). */
static pm_err gather_static(fpm_sim *sim) {
  const fpm_model *lm = sim->local_model, *m = sim->model;
  const fpm_static_state *ls = &sim->local_static;
  fpm_static_state *ws = &sim->static_state;
  for (int k = 0; k < 2; k++) {
    fpm_static_nodal(lm, k ? ls->load.xprev : ls->load.xc, sim->static_local);
    PM_CALL(fpm_par_gather_points(lm, sim->static_local,
                                  pm_par_root() ? sim->static_whole : NULL));
    if (pm_par_root())
      fpm_static_unknowns(m, sim->static_whole,
                          k ? ws->load.xprev : ws->load.xc);
  }
  if (!pm_par_root()) return PM_SUCCESS;
  load_scalars(ws, ls);
  return PM_SUCCESS;
}

/* A static solve resumed across ranks: the share's load stepping and
 * displacements (of every point it holds) from the whole run's, which
 * every rank read from the checkpoint. */
static void scatter_static(fpm_sim *sim) {
  const fpm_model *lm = sim->local_model, *m = sim->model;
  const fpm_static_state *ws = &sim->static_state;
  fpm_static_state *ls = &sim->local_static;
  double *held = sim->local_state->u; /* 3 per point held */
  for (int k = 1; k >= 0; k--) {      /* xc last: its displacements stay */
    fpm_static_nodal(m, k ? ws->load.xprev : ws->load.xc, sim->static_whole);
    for (long i = 0; i < lm->n; i++)
      memcpy(held + 3 * i, sim->static_whole + 3 * lm->gid[i],
             3 * sizeof(double));
    fpm_static_unknowns(lm, held, k ? ls->load.xprev : ls->load.xc);
  }
  load_scalars(ls, ws);
}

/* Every rank's share of the state into rank 0's view (collective). */
static pm_err gather(void *ctx) {
  fpm_sim *sim = ctx;
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
  if (sim->local_model)
    return pm_observer_share(sim->obs, &r, frame, gather, sim);
  return sim->obs ? sim->obs->step(sim->obs->ctx, &r, frame) : PM_SUCCESS;
}

/* ---- across ranks ---- */

/* Across ranks, once the run starts: the whole model stays on rank 0 as
 * its view of the run; the other ranks let it go. */
static void release_view(fpm_sim *sim) {
  if (pm_par_root()) return;
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

static pm_err run(void *p, const pm_observer *obs) {
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
  if (sim->local_model) {
    if (sim->resumed && is_static)
      scatter_static(sim);
    else if (sim->resumed)
      fpm_par_scatter(lm, sim->state, st);
    release_view(sim);
  }
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
  sim->obs = obs;
  double stage[2] = {0, 0};
  pm_err e;
  if (is_static) {
    fpm_static_report *r = &sim->static_report;
    double w0 = pm_wtime();
    e = fpm_static_run_from(
        lm, st, sim->local_model ? &sim->local_static : &sim->static_state,
        observe, sim, &sim->last, r);
    double wall = pm_wtime() - w0;
    if (sim->local_model) { /* the state the run ended in, for the figures */
      pm_err g = gather(sim);
      if (!e) e = g;
      ranks_costs(sim);
    }
    sim->obs = NULL;
    pm_stage *tm = sim->timers.stage;
    tm[sim->tm_force].seconds += r->load.time_residual;
    tm[sim->tm_force].calls += r->load.newton_iterations;
    tm[sim->tm_assembly].seconds += r->load.time_assembly;
    tm[sim->tm_assembly].calls += r->load.newton_iterations;
    tm[sim->tm_linear].seconds += r->load.time_linear;
    tm[sim->tm_linear].calls += r->load.newton_iterations;
    tm[sim->tm_update].seconds += wall - r->load.time_residual -
                                  r->load.time_assembly - r->load.time_linear;
    tm[sim->tm_update].calls += r->load.steps;
    sim->status = pm_static_status(e);
    return e;
  }
  sim->first_step = st->step;
  e = fpm_run(lm, st, &opt, observe, sim, &sim->last, stage);
  if (sim->local_model) { /* the state the run ended in, for the figures */
    pm_err g = gather(sim);
    if (!e) e = g;
    ranks_costs(sim);
  }
  sim->obs = NULL;
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

/* ---- what the run driver reads ------------------------------------------ */

static void points(void *p, pm_points *pts) {
  const fpm_sim *sim = p;
  *pts = (pm_points){.n = sim->model->n,
                     .x = sim->model->x,
                     .n_cells = sim->mesh->n_cells,
                     .nodes_per_cell = sim->mesh->nodes_per_cell,
                     .cells = sim->mesh->cells};
}

static const double *displacement(void *p) { return ((fpm_sim *)p)->state->u; }

static int fields(void *p, unsigned want, pm_field *out, int max) {
  fpm_sim *sim = p;
  const fpm_state *st = sim->state;
  int nf = 0;
  if (max < 8) return 0;
  if (want & PM_FIELD_DISPLACEMENT)
    out[nf++] = (pm_field){"displacement", 3, st->u};
  if (want & PM_FIELD_VELOCITY) out[nf++] = (pm_field){"velocity", 3, st->v};
  if (want & PM_FIELD_STRESS) {
    const long n = sim->model->n;
    double *vm = sim->scratch + 9 * n, *p_mean = vm + n;
    cauchy_stress(sim->model, st, sim->scratch);
    pm_stress_invariants(n, sim->scratch, vm, p_mean);
    out[nf++] = (pm_field){"stress", 9, sim->scratch};
    out[nf++] = (pm_field){"von_mises", 1, vm};
    out[nf++] = (pm_field){"pressure", 1, p_mean};
  }
  if (want & PM_FIELD_STRAIN_ENERGY_DENSITY)
    out[nf++] = (pm_field){"strain_energy_density", 1, st->W};
  if (want & PM_FIELD_JACOBIAN) out[nf++] = (pm_field){"jacobian", 1, st->J};
  if (want & PM_FIELD_FORCE) out[nf++] = (pm_field){"force", 3, st->f};
  return nf;
}

/* Mean strain energy density, largest von Mises stress and smallest J of
 * the current fields, with their points. */
static void field_figures(fpm_sim *sim, pm_figures *f) {
  const fpm_model *m = sim->model;
  const fpm_state *st = sim->state;
  const double *vol = sim->dual->volume, *sig = sim->scratch;
  cauchy_stress(m, st, sim->scratch);
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
  for (int a = 0; a < 3; a++) {
    f->max_von_mises_at[a] = m->x[3 * vm_at + a];
    f->end_min_jacobian_at[a] = m->x[3 * j_at + a];
  }
}

static void figures(void *p, pm_figures *f, bool with_fields) {
  fpm_sim *sim = p;
  const fpm_model *m = sim->model;
  const pm_scene *s = sim->scene;
  const fpm_step_info *l = &sim->last;
  f->status = sim->status;
  f->dim = m->dim;
  f->points = m->n;
  f->steps = l->step;
  f->time = l->t;
  f->h = sim->mean_edge;
  f->dt = sim->dt;
  f->dt_stable = sim->dt_stable;
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
    fpm_reaction(m, sim->state, b, f->reaction[b]);
  f->setup_seconds = sim->setup_wall;
  f->step_seconds = pm_timers_seconds(&sim->timers, sim->tm_force) +
                    pm_timers_seconds(&sim->timers, sim->tm_update);
  f->memory_bytes = fpm_model_bytes(m) + fpm_state_bytes(m);
  if (sim->local_model)
    f->memory_bytes +=
        fpm_model_bytes(sim->local_model) + fpm_state_bytes(sim->local_model);
  if (with_fields) field_figures(sim, f);
}

static const char *const own_cols[] = {"damping", "ill_conditioned"};

static int history_names(void *p, const char **names, int max) {
  (void)p;
  int n = 0;
  for (; n < 2 && n < max; n++) names[n] = own_cols[n];
  return n;
}

static void history_values(void *p, double *v) {
  fpm_sim *sim = p;
  v[0] = sim->last.damping;
  v[1] = (double)fpm_sim_conditioning(sim, NULL, NULL);
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
      j, "edge_cut", fpm_partition_edge_cut(sim->model, fpm_par_owner(lm))));
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

static pm_err summary(void *p, pm_json *j) {
  fpm_sim *sim = p;
  const fpm_model *m = sim->model;
  const pm_scene *s = sim->scene;
  double worst;
  long worst_point;
  long ill = fpm_sim_conditioning(sim, &worst, &worst_point);
  PM_CALL(pm_json_integer(j, "cells", sim->mesh->n_cells));
  PM_CALL(pm_json_integer(j, "interfaces", sim->dual->n_ifaces));
  PM_CALL(pm_json_integer(j, "boundary_facets", sim->dual->n_facets));
  PM_CALL(pm_json_integer(j, "prescribed_dofs", m->n_cdofs));
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
  PM_CALL(pm_json_integer(j, "ill_conditioned_points", ill));
  PM_CALL(pm_json_string(j, "jump", m->q ? "quadratic" : "linear"));
  if (sim->local_model) PM_CALL(summary_ranks(j, sim));
  if (m->q) {
    PM_CALL(pm_json_integer(j, "fit_points_two_rings", m->n_qwide));
    PM_CALL(pm_json_integer(j, "fit_points_linear", m->n_qlinear));
  }
  if (s->time.qs == PM_QS_STATIC) {
    const fpm_static_report *r = &sim->static_report;
    PM_CALL(pm_json_integer(j, "static_unknowns", r->unknowns));
    PM_CALL(pm_json_integer(j, "static_jacobian_entries", r->pattern_entries));
    PM_CALL(pm_json_integer(j, "static_load_steps", r->load.steps));
    PM_CALL(pm_json_integer(j, "static_cuts", r->load.cuts));
    PM_CALL(pm_json_integer(j, "static_newton_iterations",
                            r->load.newton_iterations));
    PM_CALL(pm_json_integer(j, "static_linear_iterations",
                            r->load.linear_iterations));
    PM_CALL(pm_json_number(j, "static_setup_seconds", r->setup_seconds));
  }
  return pm_json_number(j, "max_support_condition", worst);
}

static const pm_timers *timers(void *p) { return &((fpm_sim *)p)->timers; }

/* The time loop's state (fpm_state: u, v and what the loop carries) and
 * what the run reports over all its steps. */
/* A static solve's load stepping: where it is, its last two converged
 * states over the free dofs, and its counters. */
static pm_err checkpoint_static(fpm_sim *sim, pm_ckpt *ck) {
  fpm_static_state *ss = &sim->static_state;
  PM_CALL(pm_load_checkpoint(ck, "static", ss->free_dofs, &ss->load,
                             &sim->static_report.load));
  return pm_ckpt_double(ck, "static.external_work", &ss->external_work);
}

/* The time loop's state (fpm_state: u, v and what the loop carries; or a
 * static solve's load stepping) and what the run reports over all its
 * steps. */
static pm_err checkpoint(void *p, pm_ckpt *ck) {
  fpm_sim *sim = p;
  fpm_state *st = sim->state;
  const long n3 = 3 * sim->model->n;
  const bool is_static = sim->scene->time.qs == PM_QS_STATIC;
  if (is_static) {
    PM_CALL(checkpoint_static(sim, ck));
  } else {
    PM_CALL(pm_ckpt_doubles(ck, "fpm.u", n3, st->u));
    PM_CALL(pm_ckpt_doubles(ck, "fpm.v", n3, st->v));
    PM_CALL(pm_ckpt_long(ck, "fpm.step", &st->step));
    PM_CALL(pm_ckpt_double(ck, "fpm.t", &st->t));
    PM_CALL(pm_ckpt_double(ck, "fpm.damping", &st->damping));
    PM_CALL(pm_ckpt_double(ck, "fpm.external_work", &st->external_work));
    PM_CALL(pm_ckpt_double(ck, "fpm.dissipated", &st->dissipated));
  }
  PM_CALL(pm_ckpt_double(ck, "run.min_jacobian", &sim->run_min_jacobian));
  PM_CALL(
      pm_ckpt_long(ck, "run.min_jacobian_step", &sim->run_min_jacobian_step));
  PM_CALL(
      pm_ckpt_double(ck, "run.max_energy_error", &sim->run_max_energy_error));
  PM_CALL(pm_ckpt_double(ck, "run.residual0", &sim->res0));
  if (pm_ckpt_reading(ck)) {
    sim->resumed = true;
    if (is_static) {
      sim->last.step = sim->static_report.load.steps;
      sim->last.t =
          sim->static_state.load.lambda * pm_scene_load_end(sim->scene);
      sim->last.external_work = sim->static_state.external_work;
    } else {
      sim->last.step = st->step;
      sim->last.t = st->t;
      sim->last.damping = st->damping;
      sim->last.external_work = st->external_work;
      sim->last.dissipated = st->dissipated;
    }
  }
  return PM_SUCCESS;
}

/* Across ranks every rank sets up the whole model (the same on every
 * rank), then takes its share (collective). */
static pm_err create(const pm_scene *s, void **out) {
  fpm_sim *sim = NULL;
  pm_err e = pm_par_agree(fpm_sim_create(s, &sim));
  if (!e && pm_par_active()) {
    const double t0 = pm_wtime();
    e = fpm_par_create(sim->model, &sim->local_model);
    if (!e)
      e = pm_par_agree(fpm_state_create(sim->local_model, &sim->local_state));
    if (!e && s->time.qs == PM_QS_STATIC) { /* its load stepping's share */
      const fpm_model *lm = sim->local_model;
      e = fpm_static_state_init(&sim->local_static, lm);
      if (!e) e = PM_ALLOC(sim->static_local, 3 * lm->n + 1, "nodal gather");
      if (!e)
        e = PM_ALLOC(sim->static_whole, 3 * sim->model->n, "nodal gather");
      e = pm_par_agree(e);
    }
    sim->setup_wall += pm_wtime() - t0;
  }
  if (e) {
    fpm_sim_destroy(sim);
    return e;
  }
  *out = sim;
  return PM_SUCCESS;
}

static void destroy(void *sim) { fpm_sim_destroy(sim); }

static pm_err plan(void *sim, FILE *out);

const pm_backend fpm_backend = {
    .method = "fpm",
    .description = "explicit total-Lagrangian Fragile Points Method",
    .section = &fpm_section,
    .dt_safety = 0.9,
    .ranks = true,
    .check = fpm_check_scene,
    .create = create,
    .estimate_bytes = fpm_estimate_bytes,
    .destroy = destroy,
    .plan = plan,
    .run = run,
    .points = points,
    .fields = fields,
    .displacement = displacement,
    .figures = figures,
    .history_names = history_names,
    .history_values = history_values,
    .summary = summary,
    .timers = timers,
    .checkpoint = checkpoint,
};

/* ---- plan --------------------------------------------------------------- */

/* Seconds of one force evaluation at a small deformation of model m (u:
 * its state's; across ranks every rank times its share together,
 * collective). */
static double time_force(const fpm_model *m, fpm_state *st) {
  for (long i = 0; i < 3 * m->n; i++) st->u[i] = 1e-9 * m->x[i];
  double t0 = pm_wtime();
  int reps = 0, more = 1;
  for (;;) {
    more = pm_wtime() - t0 < 0.2 && reps < 1000;
    if (m->par) pm_par_bcast(&more, sizeof more);
    if (!more) break;
    fpm_par_exchange(m, st->u);
    fpm_force(m, st);
    reps++;
  }
  memset(st->u, 0, 3 * m->n * sizeof(double));
  return 1.1 * (pm_wtime() - t0) / (reps > 0 ? reps : 1);
}

static void plan_estimate(const fpm_sim *sim, double per_step, double steps,
                          FILE *out) {
  fprintf(out,
          "estimate     %.3g s per step, %.3g s for %.0f steps on %d "
          "threads%s (setup took %.3g s)\n",
          per_step, per_step * steps, steps, pm_omp_threads(),
          pm_par_active() ? " per rank" : "", sim->setup_wall);
}

/* The plan's lines from the scene to the memory; the steps (0 for a static
 * solve, whose lines end there). */
static double plan_head(fpm_sim *sim, FILE *out) {
  const pm_scene *s = sim->scene;
  fpm_model *m = sim->model;
  double steps = ceil(s->time.end / sim->dt);
  if (s->time.max_steps > 0 && steps > s->time.max_steps)
    steps = (double)s->time.max_steps;
  size_t bytes = fpm_model_bytes(m) + fpm_state_bytes(m);
  const double *xc = m->x + 3 * sim->dt_point;
  fprintf(out, "scene        %s (%s)\n", s->name, s->path);
  fprintf(out, "method       fpm, %dD, %s\n", m->dim,
          m->dim == 2 ? "plane strain" : "solid");
  fprintf(out, "points       %ld (mesh size %g m, mean edge %.4g m)\n", m->n,
          s->mesh_size, sim->mean_edge);
  const gm_dual *d = sim->dual;
  fprintf(out,
          "cells        %s, one per node of %ld simplices: %ld interfaces, %ld "
          "facets\n",
          sim->cells->name, sim->mesh->n_cells, d->n_ifaces, d->n_facets);
  if (d->min_quality_point >= 0)
    fprintf(out,
            "             %ld faces of round-off size dropped, %ld slivers; "
            "lowest quality %.3g (1 for a cube) at point %ld\n",
            d->n_dropped_faces, d->n_slivers, d->min_quality,
            d->min_quality_point);
  fprintf(out, "pipeline     1. stress per point (");
  for (int k = 0; k < m->n_mats; k++)
    fprintf(out, "%s%s", k ? ", " : "", m->mats[k].model->name);
  fprintf(out, ")\n");
  if (m->q)
    fprintf(out,
            "             2. quadratic fit per point, %ld entries (%ld "
            "points over two rings, %ld linear)\n",
            m->qs_ptr[m->n], m->n_qwide, m->n_qlinear);
  fprintf(out,
          "             %d. interface flux (%s, penalty %g on the %s "
          "jump), %ld support entries\n",
          m->q ? 3 : 2,
          m->flux == FPM_FLUX_SIPG ? "SIPG: with the adjoint term, tangent "
                                     "per point"
                                   : "IIPG",
          m->penalty, m->q ? "quadratic" : "linear", m->nnz);
  int stage = m->q ? 4 : 3;
  if (m->n_dpts > 0)
    fprintf(out,
            "             %d. consistency flux on prescribed faces, %ld "
            "points\n",
            stage++, m->n_dpts);
  if (m->n_tfacets > 0)
    fprintf(out, "             %d. tractions, %ld facets%s\n", stage++,
            m->n_tfacets, m->tf_time_dependent ? " (time-dependent)" : "");
  fprintf(out, "             %d. gather forces\n", stage++);
  if (s->time.qs == PM_QS_STATIC) {
    static const char *const linear[] = {"direct (LU)", "GMRES + GAMG",
                                         "CG + Jacobi", "GMRES + ILU(0)"};
    fprintf(out,
            "             %d. Newton's method in %ld proportional load steps "
            "(at most %ld iterations each), %ld prescribed dofs\n"
            "             tangent assembled directly (%s), linear solver "
            "%s\n",
            stage++, s->time.qs_load_steps, s->time.qs_max_iterations,
            m->n_cdofs,
            m->flux == FPM_FLUX_SIPG
                ? "preconditioning the exact tangent applied matrix-free"
                : "exact",
            linear[s->time.qs_linear]);
    fprintf(out,
            "memory       %.1f MiB (operators and state; the tangent "
            "and its factors come on top)\n",
            (bytes + fpm_linear_bytes(m)) / 1048576.0);
    return 0;
  }
  fprintf(out, "             %d. central difference%s, %ld prescribed dofs\n",
          stage++,
          s->time.qs == PM_QS_DYNAMIC_RELAXATION ? " with dynamic relaxation"
          : s->time.qs == PM_QS_DAMPING          ? " with damping"
                                                 : "",
          m->n_cdofs);
  fpm_sim_measure_spectrum(sim);
  fprintf(out, "dt           %.4g s (%s)\n", sim->dt,
          s->time.dt > 0                      ? "time.dt"
          : s->time.dt_rule == PM_DT_SPECTRAL ? "dt_safety x spectral"
                                              : "dt_safety x paper bound");
  fprintf(out,
          "             bound of eqs. 24-26: %.4g s, set by point %ld at "
          "(%g, %g, %g)\n",
          sim->dt_paper, sim->dt_point, xc[0], xc[1], xc[2]);
  fprintf(out,
          "             spectral (power iteration): %.4g s = %.2f x the "
          "bound\n",
          sim->dt_spectral, sim->dt_spectral / sim->dt_paper);
  fprintf(out, "steps        %.0f to t = %g s%s\n", steps, s->time.end,
          s->time.qs != PM_QS_NONE ? " (at most: stops when converged)" : "");
  fprintf(out, "memory       %.1f MiB (operators and state)\n",
          bytes / 1048576.0);
  return steps;
}

/* The plan across ranks (collective): rank 0's view prints the scene's
 * lines and every rank's share, and the shares' forces are timed. */
static pm_err plan_ranks(fpm_sim *sim, FILE *out) {
  const fpm_model *lm = sim->local_model;
  double steps = 0;
  if (pm_par_root()) {
    steps = plan_head(sim, out);
    fpm_share_print(sim->model, fpm_par_owner(lm), pm_par_size(),
                    fpm_par_counts(lm), out);
  }
  double per_step = time_force(lm, sim->local_state);
  if (pm_par_root()) plan_estimate(sim, per_step, steps, out);
  return PM_SUCCESS;
}

static pm_err plan(void *p, FILE *out) {
  fpm_sim *sim = p;
  if (sim->local_model) return plan_ranks(sim, out);
  const int ranks = pm_par_plan_ranks();
  double per_step = time_force(sim->model, sim->state);
  double steps = plan_head(sim, out);
  if (ranks > 1) PM_CALL(fpm_share_predict(sim->model, ranks, out));
  if (sim->scene->time.qs == PM_QS_STATIC) return PM_SUCCESS;
  plan_estimate(sim, per_step, steps, out);
  return PM_SUCCESS;
}
