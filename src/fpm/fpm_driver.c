/* fpm_driver: sets up an FPM simulation from a scene and runs it with
 * output, history, progress and a summary; also the run plan. */
#include "fpm_driver.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_files.h"
#include "pm_metrics.h"
#include "pm_omp.h"
#include "pm_output.h"
#include "fpm_gfd.h"
#include "pm_tensor.h"

#define FPM_HIST_MAX 64

const char *fpm_status_name(fpm_status s) {
  switch (s) {
  case FPM_STATUS_COMPLETED: return "completed";
  case FPM_STATUS_CONVERGED: return "converged";
  case FPM_STATUS_NOT_CONVERGED: return "not-converged";
  case FPM_STATUS_UNSTABLE: return "unstable";
  case FPM_STATUS_FAILED: return "failed";
  default: return "not-run";
  }
}

static void fill_reference(fpm_sim *sim, double t);

void fpm_sim_destroy(fpm_sim *sim) {
  if (!sim) return;
  fpm_state_destroy(sim->state);
  fpm_model_destroy(sim->model);
  gm_dual_destroy(sim->dual);
  gm_mesh_destroy(sim->mesh);
  free(sim->scratch);
  free(sim->ref);
  free(sim);
}

pm_err fpm_sim_create(const pm_scene *s, fpm_sim **out) {
  pm_err ret = PM_SUCCESS;
  fpm_sim *sim = NULL;
  *out = NULL;
  PM_ENSURE(s->method == PM_METHOD_FPM, PM_ERR_UNSUPPORTED,
            "%s: method %s is not the FPM backend", s->path,
            pm_method_name(s->method));
  PM_TRY(PM_ALLOC(sim, 1, "FPM simulation"));
  sim->scene = s;
  for (int c = 0; c < 3; c++) sim->nrmse[c] = NAN;
  sim->nrmse_vector = NAN;
  pm_timers_init(&sim->timers);
  sim->tm_mesh = pm_timers_add(&sim->timers, "mesh (gmsh)");
  sim->tm_dual = pm_timers_add(&sim->timers, "median-dual subdomains");
  sim->tm_operators = pm_timers_add(&sim->timers, "GFD operators and BCs");
  sim->tm_force = pm_timers_add(&sim->timers, "internal force");
  sim->tm_update = pm_timers_add(&sim->timers, "time integration");
  sim->tm_output = pm_timers_add(&sim->timers, "output");
  double t0 = pm_wtime();
  pm_timers_start(&sim->timers, sim->tm_mesh);
  PM_TRY(gm_mesh_box(s->dimension, s->box_min, s->box_max, s->mesh_size,
                     &sim->mesh));
  pm_timers_stop(&sim->timers, sim->tm_mesh);
  sim->mean_edge = gm_mesh_mean_edge(sim->mesh);
  pm_timers_start(&sim->timers, sim->tm_dual);
  PM_TRY(gm_dual_build(sim->mesh, &sim->dual));
  pm_timers_stop(&sim->timers, sim->tm_dual);
  pm_timers_start(&sim->timers, sim->tm_operators);
  PM_TRY(fpm_model_create(s, sim->dual, &sim->model));
  PM_TRY(fpm_state_create(sim->model, &sim->state));
  PM_TRY(PM_ALLOC(sim->scratch, 9 * sim->model->n, "output buffer"));
  if (s->reference_mask) {
    PM_TRY(PM_ALLOC(sim->ref, 3 * sim->model->n, "reference field"));
    for (int c = 0; c < 3; c++)
      if ((s->reference_mask & (1u << c)) && pm_expr_uses(s->reference[c], 't'))
        sim->ref_time_dependent = true;
    fill_reference(sim, 0);
  }
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

/* ---- run ---------------------------------------------------------------- */

/* Reference displacement at time t (serial: expressions are not
 * thread-safe). */
static void fill_reference(fpm_sim *sim, double t) {
  const pm_scene *s = sim->scene;
  const fpm_model *m = sim->model;
  for (int c = 0; c < 3; c++) {
    if (!(s->reference_mask & (1u << c))) continue;
    for (long i = 0; i < m->n; i++)
      sim->ref[3 * i + c] = pm_expr_eval(s->reference[c], m->x[3 * i],
                                         m->x[3 * i + 1], m->x[3 * i + 2], t);
  }
}

/* NRMSE (eq. 28) of each reference component at time t into sim->nrmse. */
static void compute_errors(fpm_sim *sim, double t) {
  const pm_scene *s = sim->scene;
  sim->n_ref = 0;
  sim->nrmse_vector = NAN;
  for (int c = 0; c < 3; c++) sim->nrmse[c] = NAN;
  if (!sim->ref) return;
  if (sim->ref_time_dependent) fill_reference(sim, t);
  for (int c = 0; c < 3; c++) {
    if (!(s->reference_mask & (1u << c))) continue;
    sim->nrmse[c] = pm_nrmse(sim->model->n, 3, sim->state->u + c, sim->ref + c);
    sim->nrmse_vector = sim->nrmse[c];
    sim->n_ref++;
  }
  if (sim->n_ref > 1)
    sim->nrmse_vector = pm_nrmse_vector(sim->model->n, s->reference_mask,
                                        sim->state->u, sim->ref);
}

typedef struct {
  fpm_sim *sim;
  pm_results *results;
  pm_history *history;
  pm_progress progress;
  bool show_progress;
  int n_hist;
  double row[FPM_HIST_MAX];
  int reaction_bc[FPM_HIST_MAX]; /* per history column: bc, or -1 */
  int first_error;               /* column of the first NRMSE, or -1 */
  double t_start;                /* wall clock at the start of the run */
  int reaction_comp[FPM_HIST_MAX];
  char names_buf[FPM_HIST_MAX][40];
  const char *names[FPM_HIST_MAX];
  double res0;
  double load_end;
} run_ctx;

static void setup_history_columns(run_ctx *c) {
  static const char *base[] = {
      "time",           "step",          "wall_seconds",   "kinetic_energy",
      "strain_energy",  "external_work", "penalty_energy", "dissipated",
      "residual",       "damping",       "energy_error",   "min_jacobian",
      "ill_conditioned"};
  const pm_scene *s = c->sim->scene;
  int n = 0;
  for (int k = 0; k < (int)(sizeof base / sizeof *base); k++) {
    snprintf(c->names_buf[n], sizeof c->names_buf[n], "%s", base[k]);
    c->reaction_bc[n] = -1;
    n++;
  }
  for (int b = 0; b < s->n_bcs && n + 3 <= FPM_HIST_MAX; b++)
    for (int comp = 0; comp < 3; comp++) {
      if (!(s->bcs[b].disp_mask & (1u << comp))) continue;
      snprintf(c->names_buf[n], sizeof c->names_buf[n], "reaction_%s_%c",
               pm_face_name(s->bcs[b].face), "xyz"[comp]);
      c->reaction_bc[n] = b;
      c->reaction_comp[n] = comp;
      n++;
    }
  /* Accuracy beside time: the error against the reference at each frame. */
  c->first_error = -1;
  for (int comp = 0; comp < 3 && n < FPM_HIST_MAX; comp++) {
    if (!(s->reference_mask & (1u << comp))) continue;
    if (c->first_error < 0) c->first_error = n;
    snprintf(c->names_buf[n], sizeof c->names_buf[n], "nrmse_u_%c",
             "xyz"[comp]);
    c->reaction_bc[n] = -1;
    n++;
  }
  for (int k = 0; k < n; k++) c->names[k] = c->names_buf[k];
  c->n_hist = n;
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

static pm_err write_frame(run_ctx *c, const fpm_state *st, long step,
                          double t) {
  const fpm_model *m = c->sim->model;
  unsigned want = c->sim->scene->output.fields;
  pm_field fields[6];
  int nf = 0;
  if (want & PM_FIELD_DISPLACEMENT)
    fields[nf++] = (pm_field){"displacement", 3, st->u};
  if (want & PM_FIELD_VELOCITY) fields[nf++] = (pm_field){"velocity", 3, st->v};
  if (want & PM_FIELD_STRESS) {
    cauchy_stress(m, st, c->sim->scratch);
    fields[nf++] = (pm_field){"stress", 9, c->sim->scratch};
  }
  if (want & PM_FIELD_STRAIN_ENERGY_DENSITY)
    fields[nf++] = (pm_field){"strain_energy_density", 1, st->W};
  if (want & PM_FIELD_JACOBIAN) fields[nf++] = (pm_field){"jacobian", 1, st->J};
  if (want & PM_FIELD_FORCE) fields[nf++] = (pm_field){"force", 3, st->f};
  return pm_results_write_frame(c->results, step, t, nf, fields);
}

static pm_err observe(void *ctx, const fpm_model *m, const fpm_state *st,
                      const fpm_step_info *info, bool frame) {
  run_ctx *c = ctx;
  fpm_sim *sim = c->sim;
  if (info->min_jacobian < sim->run_min_jacobian) {
    sim->run_min_jacobian = info->min_jacobian;
    sim->run_min_jacobian_step = info->step;
  }
  if (info->energy_checked &&
      fabs(info->energy_error) > sim->run_max_energy_error)
    sim->run_max_energy_error = fabs(info->energy_error);
  if (c->show_progress) {
    double frac = info->t / sim->scene->time.end;
    if (sim->scene->time.qs != PM_QS_NONE && info->t >= c->load_end &&
        c->res0 > 0 && info->residual > 0) {
      double tol = sim->scene->time.qs_tolerance;
      double q = log(c->res0 / info->residual) / log(c->res0 / tol);
      if (q > frac) frac = q;
    } else if (info->t >= c->load_end && c->res0 == 0) {
      c->res0 = info->residual;
    }
    char status[96];
    snprintf(status, sizeof status, "t=%.4g s  step %ld  residual %.2e",
             info->t, info->step, info->residual);
    pm_progress_update(&c->progress, frac, status);
  }
  if (!frame || !c->results) return PM_SUCCESS;
  pm_timers_start(&sim->timers, sim->tm_output);
  pm_err ret = write_frame(c, st, info->step, info->t);
  if (ret == PM_SUCCESS && c->history) {
    double *row = c->row;
    row[0] = info->t;
    row[1] = (double)info->step;
    row[2] = pm_wtime() - c->t_start;
    row[3] = info->kinetic;
    row[4] = info->strain;
    row[5] = info->external_work;
    row[6] = info->penalty;
    row[7] = info->dissipated;
    row[8] = info->residual;
    row[9] = info->damping;
    row[10] = info->energy_error;
    row[11] = info->min_jacobian;
    row[12] = (double)fpm_sim_conditioning(sim, NULL, NULL);
    int k = 13;
    for (; k < c->n_hist && c->reaction_bc[k] >= 0; k++) {
      double R[3];
      fpm_reaction(m, st, c->reaction_bc[k], R);
      row[k] = R[c->reaction_comp[k]];
    }
    if (c->first_error >= 0) {
      compute_errors(sim, info->t);
      for (int comp = 0; comp < 3; comp++)
        if (isfinite(sim->nrmse[comp])) row[k++] = sim->nrmse[comp];
    }
    ret = pm_history_row(c->history, row);
  }
  pm_timers_stop(&sim->timers, sim->tm_output);
  return ret;
}

long fpm_sim_conditioning(const fpm_sim *sim, double *worst,
                          long *worst_point) {
  const fpm_model *m = sim->model;
  return fpm_gfd_deformed_condition(m->dim, m->n, m->x, sim->state->u,
                                    m->nbr_ptr, sim->dual->nbr, FPM_COND_MAX,
                                    worst, worst_point);
}

void fpm_sim_field_figures(fpm_sim *sim, fpm_field_figures *ff) {
  const fpm_model *m = sim->model;
  const fpm_state *st = sim->state;
  const double *vol = sim->dual->volume;
  double *sig = sim->scratch;
  cauchy_stress(m, st, sig);
  double vsum = 0, wsum = 0;
  *ff = (fpm_field_figures){.min_jacobian = INFINITY, .max_von_mises = -1};
  for (long i = 0; i < m->n; i++) {
    vsum += vol[i];
    wsum += vol[i] * st->W[i];
    double vm = pm_t_von_mises(sig + 9 * i);
    if (vm > ff->max_von_mises) {
      ff->max_von_mises = vm;
      ff->max_von_mises_point = i;
    }
    if (st->J[i] < ff->min_jacobian) {
      ff->min_jacobian = st->J[i];
      ff->min_jacobian_point = i;
    }
  }
  ff->mean_strain_energy_density = vsum > 0 ? wsum / vsum : 0;
  ff->ill_conditioned =
      fpm_sim_conditioning(sim, &ff->max_condition, &ff->max_condition_point);
}

static pm_err json_point(pm_json *j, const char *key, const fpm_model *m,
                         long p) {
  PM_CALL(pm_json_begin_array(j, key));
  for (int a = 0; a < m->dim; a++)
    PM_CALL(pm_json_number(j, NULL, m->x[3 * p + a]));
  return pm_json_end_array(j);
}

/* Figures of the final fields: energy density, stress, J, conditioning. */
static pm_err write_field_figures(fpm_sim *sim, pm_json *j) {
  const fpm_model *m = sim->model;
  fpm_field_figures ff;
  fpm_sim_field_figures(sim, &ff);
  PM_CALL(pm_json_number(j, "mean_strain_energy_density",
                         ff.mean_strain_energy_density));
  PM_CALL(pm_json_number(j, "max_von_mises", ff.max_von_mises));
  PM_CALL(json_point(j, "max_von_mises_at", m, ff.max_von_mises_point));
  PM_CALL(pm_json_number(j, "min_jacobian", ff.min_jacobian));
  PM_CALL(json_point(j, "min_jacobian_at", m, ff.min_jacobian_point));
  PM_CALL(pm_json_number(j, "run_min_jacobian", sim->run_min_jacobian));
  PM_CALL(
      pm_json_integer(j, "run_min_jacobian_step", sim->run_min_jacobian_step));
  PM_CALL(pm_json_number(j, "run_max_energy_error", sim->run_max_energy_error));
  PM_CALL(pm_json_integer(j, "ill_conditioned_points", ff.ill_conditioned));
  PM_CALL(pm_json_number(j, "max_support_condition", ff.max_condition));
  return PM_SUCCESS;
}

static pm_err write_summary(fpm_sim *sim, const char *out_dir) {
  pm_err ret = PM_SUCCESS;
  pm_json *j = NULL;
  char path[4096];
  const fpm_model *m = sim->model;
  const pm_scene *s = sim->scene;
  PM_TRY(pm_path_join(path, sizeof path, out_dir, "summary.json"));
  PM_TRY(pm_json_open(path, &j));
  PM_TRY(pm_json_begin_object(j, NULL));
  PM_TRY(pm_json_run_header(j, s->path, s->name, "fpm", s->n_overrides,
                            s->overrides));
  PM_TRY(pm_json_string(j, "status", fpm_status_name(sim->status)));
  if (sim->message[0]) PM_TRY(pm_json_string(j, "message", sim->message));
  PM_TRY(pm_json_integer(j, "dimension", m->dim));
  PM_TRY(pm_json_integer(j, "points", m->n));
  PM_TRY(pm_json_integer(j, "cells", sim->mesh->n_cells));
  PM_TRY(pm_json_integer(j, "interfaces", sim->dual->n_ifaces));
  PM_TRY(pm_json_integer(j, "boundary_facets", sim->dual->n_facets));
  PM_TRY(pm_json_integer(j, "prescribed_dofs", m->n_cdofs));
  PM_TRY(pm_json_number(j, "mesh_size", s->mesh_size));
  PM_TRY(pm_json_number(j, "mean_edge_length", sim->mean_edge));
  PM_TRY(pm_json_number(j, "penalty", m->penalty));
  PM_TRY(pm_json_number(j, "dt", sim->dt));
  PM_TRY(pm_json_string(j, "dt_rule",
                        s->time.dt > 0                      ? "time.dt"
                        : s->time.dt_rule == PM_DT_SPECTRAL ? "spectral"
                                                            : "paper"));
  PM_TRY(pm_json_number(j, "dt_stable", sim->dt_stable));
  PM_TRY(pm_json_number(j, "dt_paper", sim->dt_paper));
  if (sim->dt_spectral > 0)
    PM_TRY(pm_json_number(j, "dt_spectral", sim->dt_spectral));
  PM_TRY(pm_json_integer(j, "dt_critical_point", sim->dt_point));
  PM_TRY(pm_json_integer(j, "steps", sim->last.step));
  PM_TRY(pm_json_number(j, "time", sim->last.t));
  PM_TRY(pm_json_number(j, "residual", sim->last.residual));
  PM_TRY(pm_json_bool(j, "converged", sim->status == FPM_STATUS_CONVERGED));
  PM_TRY(pm_json_number(j, "kinetic_energy", sim->last.kinetic));
  PM_TRY(pm_json_number(j, "strain_energy", sim->last.strain));
  PM_TRY(pm_json_number(j, "external_work", sim->last.external_work));
  PM_TRY(pm_json_number(j, "dissipated", sim->last.dissipated));
  PM_TRY(pm_json_number(j, "penalty_energy", sim->last.penalty));
  PM_TRY(
      pm_json_number(j, "energy_balance_error", fpm_energy_error(&sim->last)));
  PM_TRY(write_field_figures(sim, j));
  PM_TRY(pm_json_number(j, "wall_seconds", sim->wall));
  PM_TRY(pm_json_number(j, "setup_seconds", sim->setup_wall));
  int threads = pm_omp_threads();
  double force_s = pm_timers_seconds(&sim->timers, sim->tm_force) +
                   pm_timers_seconds(&sim->timers, sim->tm_update);
  double ps = force_s > 0 ? (double)m->n * sim->last.step / force_s : 0;
  PM_TRY(pm_json_integer(j, "threads", threads));
  PM_TRY(pm_json_number(j, "point_steps_per_second", ps));
  PM_TRY(pm_json_number(j, "point_steps_per_second_per_core", ps / threads));
  PM_TRY(pm_json_number(j, "seconds_per_point_step", ps > 0 ? 1.0 / ps : NAN));
  PM_TRY(pm_json_integer(j, "memory_bytes",
                         (long long)(fpm_model_bytes(m) + fpm_state_bytes(m))));
  PM_TRY(pm_json_begin_object(j, "stage_seconds"));
  for (int k = 0; k < sim->timers.n; k++)
    PM_TRY(pm_json_number(j, sim->timers.stage[k].name,
                          sim->timers.stage[k].seconds));
  PM_TRY(pm_json_end_object(j));
  if (isfinite(sim->nrmse_vector))
    PM_TRY(pm_json_number(j, "nrmse_displacement", sim->nrmse_vector));
  PM_TRY(pm_json_string(j, "flux", m->flux == PM_FLUX_SIPG ? "sipg" : "iipg"));
  PM_TRY(pm_json_begin_object(j, "nrmse"));
  for (int c = 0; c < 3; c++) {
    char key[8] = {'u', '_', "xyz"[c], 0};
    if (isfinite(sim->nrmse[c])) PM_TRY(pm_json_number(j, key, sim->nrmse[c]));
  }
  PM_TRY(pm_json_end_object(j));
  PM_TRY(pm_json_begin_object(j, "reactions"));
  for (int b = 0; b < s->n_bcs; b++) {
    if (!s->bcs[b].disp_mask) continue;
    double R[3];
    fpm_reaction(m, sim->state, b, R);
    PM_TRY(pm_json_begin_array(j, pm_face_name(s->bcs[b].face)));
    for (int c = 0; c < 3; c++) PM_TRY(pm_json_number(j, NULL, R[c]));
    PM_TRY(pm_json_end_array(j));
  }
  PM_TRY(pm_json_end_object(j));
  PM_TRY(pm_json_end_object(j));
  ret = pm_json_close(j, true);
  j = NULL;
done:
  if (j) pm_json_close(j, false);
  return ret;
}

pm_err fpm_sim_run(fpm_sim *sim, const char *out_dir, bool quiet) {
  pm_err ret = PM_SUCCESS, run_err = PM_SUCCESS;
  const pm_scene *s = sim->scene;
  fpm_model *m = sim->model;
  run_ctx *c = NULL;
  PM_TRY(PM_ALLOC(c, 1, "run context"));
  c->sim = sim;
  c->load_end = fpm_load_end(m);
  c->show_progress = !quiet;
  pm_progress_init(&c->progress, stderr, s->name ? s->name : "fpm");
  setup_history_columns(c);
  if (out_dir) {
    PM_TRY(pm_mkdir_p(out_dir));
    PM_TRY(pm_results_create(out_dir, m->dim, m->n, m->x, sim->mesh->n_cells,
                             sim->mesh->nodes_per_cell, sim->mesh->cells,
                             s->text, PM_VERSION, &c->results));
    PM_TRY(pm_history_open(out_dir, c->n_hist, c->names, &c->history));
  }
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
  memset(sim->state->u, 0, 3 * m->n * sizeof(double));
  memset(sim->state->v, 0, 3 * m->n * sizeof(double));
  sim->run_min_jacobian = INFINITY;
  sim->run_min_jacobian_step = 0;
  sim->run_max_energy_error = 0;
  double t0 = pm_wtime(), stage[2] = {0, 0};
  c->t_start = t0;
  run_err = fpm_run(m, sim->state, &opt, observe, c, &sim->last, stage);
  sim->wall = pm_wtime() - t0;
  if (!quiet) pm_progress_finish(&c->progress);
  sim->timers.stage[sim->tm_force].seconds += stage[0];
  sim->timers.stage[sim->tm_force].calls += sim->last.step + 1;
  sim->timers.stage[sim->tm_update].seconds += stage[1];
  sim->timers.stage[sim->tm_update].calls += sim->last.step;
  if (run_err == PM_ERR_UNSTABLE) {
    sim->status = FPM_STATUS_UNSTABLE;
    snprintf(sim->message, sizeof sim->message,
             "%s%s; stable step %.4g s by the %s rule: reduce "
             "time.dt_safety or time.dt",
             pm_error_message(), s->time.dt > 0 ? " set by time.dt" : "",
             sim->dt_stable,
             s->time.dt_rule == PM_DT_SPECTRAL ? "spectral" : "paper");
  } else if (run_err != PM_SUCCESS) {
    sim->status = FPM_STATUS_FAILED;
    snprintf(sim->message, sizeof sim->message, "%s", pm_error_message());
  } else if (s->time.qs == PM_QS_NONE) {
    sim->status = FPM_STATUS_COMPLETED;
  } else if (sim->last.converged) {
    sim->status = FPM_STATUS_CONVERGED;
  } else {
    sim->status = FPM_STATUS_NOT_CONVERGED;
    snprintf(sim->message, sizeof sim->message,
             "quasi-static residual %.3g above tolerance %.3g at t = %.6g s "
             "after %ld steps (raise time.end or time.max_steps)",
             sim->last.residual, s->time.qs_tolerance, sim->last.t,
             sim->last.step);
  }
  if (sim->status != FPM_STATUS_UNSTABLE && sim->status != FPM_STATUS_FAILED)
    compute_errors(sim, sim->last.t);
  if (out_dir) {
    /* Frames written before a failure are good: keep them. */
    pm_results *r = c->results;
    c->results = NULL;
    PM_TRY(pm_results_close(r, true));
    pm_history *h = c->history;
    c->history = NULL;
    PM_TRY(pm_history_close(h, true));
    PM_TRY(write_summary(sim, out_dir));
  }
  if (!quiet) {
    fprintf(stderr,
            "%s: %s after %ld steps, t = %.6g s (dt %.4g s), residual %.3g\n",
            s->name, fpm_status_name(sim->status), sim->last.step, sim->last.t,
            sim->dt, sim->last.residual);
    for (int k = 0; k < 3; k++)
      if (isfinite(sim->nrmse[k]))
        fprintf(stderr, "  NRMSE u_%c = %.4e\n", "xyz"[k], sim -> nrmse[k]);
    pm_timers_print(&sim->timers, stderr, sim->setup_wall + sim->wall);
  }
  if (run_err != PM_SUCCESS) {
    ret = PM_ERROR(run_err, "%s", sim->message);
  } else if (sim->status == FPM_STATUS_NOT_CONVERGED) {
    ret = PM_ERROR(PM_ERR_NOT_CONVERGED, "%s", sim->message);
  }
done:
  if (c) {
    if (c->results) pm_results_close(c->results, false);
    if (c->history) pm_history_close(c->history, false);
    free(c);
  }
  return ret;
}

/* ---- plan --------------------------------------------------------------- */

pm_err fpm_sim_plan(fpm_sim *sim, FILE *out) {
  const pm_scene *s = sim->scene;
  fpm_model *m = sim->model;
  fpm_state *st = sim->state;
  /* Time a few force evaluations at a small deformation. */
  for (long i = 0; i < 3 * m->n; i++) st->u[i] = 1e-9 * m->x[i];
  double t0 = pm_wtime();
  int reps = 0;
  do {
    fpm_force(m, st);
    reps++;
  } while (pm_wtime() - t0 < 0.2 && reps < 1000);
  double per_step = 1.1 * (pm_wtime() - t0) / reps;
  memset(st->u, 0, 3 * m->n * sizeof(double));
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
  fprintf(out,
          "cells        %ld simplices, %ld interfaces, %ld boundary facets\n",
          sim->mesh->n_cells, sim->dual->n_ifaces, sim->dual->n_facets);
  fprintf(out, "pipeline     1. stress per point (");
  for (int k = 0; k < m->n_mats; k++)
    fprintf(out, "%s%s", k ? ", " : "", m->mats[k].model->name);
  fprintf(out,
          ")\n             2. interface flux (%s, penalty %g), %ld "
          "support entries\n",
          m->flux == PM_FLUX_SIPG ? "SIPG: with the adjoint term, tangent "
                                    "per point"
                                  : "IIPG",
          m->penalty, m->nnz);
  int stage = 3;
  if (m->n_dpts > 0)
    fprintf(out,
            "             %d. consistency flux on prescribed faces, %ld "
            "points\n",
            stage++, m->n_dpts);
  if (m->n_tfacets > 0)
    fprintf(out, "             %d. tractions, %ld facets%s\n", stage++,
            m->n_tfacets, m->tf_time_dependent ? " (time-dependent)" : "");
  fprintf(out, "             %d. gather forces\n", stage++);
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
  fprintf(out,
          "estimate     %.3g s per step, %.3g s for %.0f steps on %d "
          "threads (setup took %.3g s)\n",
          per_step, per_step * steps, steps, pm_omp_threads(), sim->setup_wall);
  return PM_SUCCESS;
}
