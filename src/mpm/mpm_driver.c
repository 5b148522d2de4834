/* mpm_driver: runs an MPM scene with output, history, summary and the
 * plan. */
#include "mpm_driver.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_files.h"
#include "pm_metrics.h"
#include "pm_omp.h"
#include "pm_output.h"
#include "pm_tensor.h"

#define MPM_HIST_MAX 128

const char *mpm_status_name(mpm_status s) {
  switch (s) {
  case MPM_STATUS_COMPLETED: return "completed";
  case MPM_STATUS_CONVERGED: return "converged";
  case MPM_STATUS_NOT_CONVERGED: return "not-converged";
  case MPM_STATUS_UNSTABLE: return "unstable";
  case MPM_STATUS_FAILED: return "failed";
  default: return "not-run";
  }
}

pm_err mpm_run_create(const pm_scene *s, mpm_run **out) {
  pm_err ret = PM_SUCCESS;
  mpm_run *r = NULL;
  *out = NULL;
  PM_TRY(PM_ALLOC(r, 1, "MPM run"));
  r->scene = s;
  double t0 = pm_wtime();
  PM_TRY(mpm_model_create(s, &r->sim));
  r->setup_wall = pm_wtime() - t0;
  for (int c = 0; c < 3; c++) r->nrmse[c] = NAN;
  r->nrmse_vector = NAN;
  *out = r;
  r = NULL;
done:
  mpm_run_destroy(r);
  return ret;
}

void mpm_run_destroy(mpm_run *r) {
  if (!r) return;
  mpm_model_destroy(r->sim);
  free(r);
}

void mpm_run_field_figures(const mpm_run *r, mpm_field_figures *ff) {
  const mpm_sim *sim = r->sim;
  double w = 0, v0 = 0;
  *ff = (mpm_field_figures){.max_von_mises = 0,
                            .max_von_mises_particle = -1,
                            .min_jacobian = INFINITY,
                            .min_jacobian_particle = -1};
  for (int gi = 0; gi < sim->n_groups; gi++) {
    const mpm_group *g = &sim->group[gi];
    for (long p = g->begin; p < g->end; p++) {
      double vm = pm_t_von_mises(sim->sigma + 9 * p);
      if (vm > ff->max_von_mises) {
        ff->max_von_mises = vm;
        ff->max_von_mises_particle = p;
      }
      double J = sim->vol[p] / sim->vol0[p];
      if (J < ff->min_jacobian) {
        ff->min_jacobian = J;
        ff->min_jacobian_particle = p;
      }
      if (!g->fluid) {
        w += sim->vol0[p] *
             pm_material_energy(&g->solid, g->F + 9 * (p - g->begin), NULL);
        v0 += sim->vol0[p];
      }
    }
  }
  ff->mean_strain_energy_density = v0 > 0 ? w / v0 : NAN;
}

void mpm_reaction(const mpm_run *r, int b, double R[3]) {
  for (int c = 0; c < 3; c++) R[c] = r->sim->bcs[b].reaction[c];
}

/* ---- history and frames ------------------------------------------------- */

typedef struct {
  mpm_run *run;
  pm_results *results;
  pm_history *history;
  int n_hist;
  const char *names[MPM_HIST_MAX];
  char names_buf[MPM_HIST_MAX][32];
  int reaction_bc[MPM_HIST_MAX];
  int reaction_comp[MPM_HIST_MAX];
  int col_internal, col_iter, col_nrmse;
  bool overflow;    /* more history columns than MPM_HIST_MAX */
  int iter_max_row; /* energy iterations since the last row */
  long iter_capped_prev;
  double *scratch; /* 9 n */
  double *ref;     /* 3 n or NULL */
  double t_start;
} run_ctx;

static void add_col(run_ctx *c, const char *name) {
  if (c->n_hist >= MPM_HIST_MAX) {
    c->overflow = true;
    return;
  }
  snprintf(c->names_buf[c->n_hist], sizeof c->names_buf[0], "%s", name);
  c->names[c->n_hist] = c->names_buf[c->n_hist];
  c->reaction_bc[c->n_hist] = -1;
  c->n_hist++;
}

static void setup_history(run_ctx *c) {
  const mpm_sim *sim = c->run->sim;
  const pm_scene *s = c->run->scene;
  static const char *const base[] = {"time", "step",           "wall_seconds",
                                     "dt",   "kinetic_energy", "strain_energy"};
  for (int k = 0; k < 6; k++) add_col(c, base[k]);
  c->col_internal = -1;
  if (sim->has_fluid) {
    c->col_internal = c->n_hist;
    add_col(c, "internal_energy");
  }
  add_col(c, "external_work");
  add_col(c, "dissipated");
  add_col(c, "energy_error");
  add_col(c, "residual");
  c->col_iter = -1;
  if (sim->has_fluid) {
    c->col_iter = c->n_hist;
    add_col(c, "energy_iterations");
    add_col(c, "energy_iterations_capped");
  }
  for (int b = 0; b < s->n_bcs; b++) {
    unsigned mask = s->bcs[b].disp_mask | s->bcs[b].velocity_mask;
    for (int k = 0; k < 3; k++) {
      if (!(mask >> k & 1u) || c->n_hist >= MPM_HIST_MAX) continue;
      char name[32];
      snprintf(name, sizeof name, "reaction_%s_%c",
               pm_face_name(s->bcs[b].face), "xyz"[k]);
      int col = c->n_hist;
      add_col(c, name);
      c->reaction_bc[col] = b;
      c->reaction_comp[col] = k;
    }
  }
  c->col_nrmse = -1;
  if (s->reference_mask) {
    c->col_nrmse = c->n_hist;
    add_col(c, "nrmse_displacement");
  }
}

static void fill_reference(run_ctx *c, double t) {
  const mpm_sim *sim = c->run->sim;
  const pm_scene *s = c->run->scene;
  /* Serial: an expression is not thread-safe. */
  for (long p = 0; p < sim->n; p++) {
    const double *X = sim->x0 + 3 * p;
    for (int k = 0; k < 3; k++)
      c->ref[3 * p + k] =
          s->reference[k] ? pm_expr_eval(s->reference[k], X[0], X[1], X[2], t)
                          : 0.0;
  }
}

static void displacement(const mpm_sim *sim, double *u) {
  PM_OMP(parallel for schedule(static))
  for (long i = 0; i < 3 * sim->n; i++) u[i] = sim->x[i] - sim->x0[i];
}

static void compute_errors(run_ctx *c, double t) {
  mpm_run *r = c->run;
  const pm_scene *s = r->scene;
  if (!c->ref) return;
  fill_reference(c, t);
  displacement(r->sim, c->scratch);
  for (int k = 0; k < 3; k++)
    if (s->reference_mask >> k & 1u)
      r->nrmse[k] = pm_nrmse(r->sim->n, 3, c->scratch + k, c->ref + k);
  r->nrmse_vector =
      pm_nrmse_vector(r->sim->n, s->reference_mask, c->scratch, c->ref);
}

static void update_energy(mpm_run *r) {
  const mpm_sim *sim = r->sim;
  mpm_energies(sim, &r->kinetic, &r->strain, &r->internal);
  double E = r->kinetic + r->strain + r->internal + sim->dissipated -
             sim->external_work;
  double scale = fmax(fabs(r->energy0), fabs(sim->external_work));
  r->energy_error = scale > 0 ? (E - r->energy0) / scale : 0.0;
}

static pm_err write_history_row(run_ctx *c) {
  mpm_run *r = c->run;
  const mpm_sim *sim = r->sim;
  double row[MPM_HIST_MAX];
  int k = 0;
  row[k++] = sim->t;
  row[k++] = (double)sim->step;
  row[k++] = pm_wtime() - c->t_start;
  row[k++] = sim->dt;
  row[k++] = r->kinetic;
  row[k++] = r->strain;
  if (c->col_internal >= 0) row[k++] = r->internal;
  row[k++] = sim->external_work;
  row[k++] = sim->dissipated;
  row[k++] = r->energy_error;
  row[k++] = sim->residual;
  if (c->col_iter >= 0) {
    /* Over the steps since the previous row. */
    row[k++] = c->iter_max_row;
    row[k++] = (double)(sim->iter_capped_total - c->iter_capped_prev);
    c->iter_capped_prev = sim->iter_capped_total;
    c->iter_max_row = 0;
  }
  for (; k < c->n_hist && c->reaction_bc[k] >= 0; k++)
    row[k] = sim->bcs[c->reaction_bc[k]].reaction[c->reaction_comp[k]];
  if (c->col_nrmse >= 0) {
    compute_errors(c, sim->t);
    row[k++] = r->nrmse_vector;
  }
  return pm_history_row(c->history, row);
}

static pm_err write_frame(run_ctx *c) {
  mpm_run *r = c->run;
  const mpm_sim *sim = r->sim;
  const pm_scene *s = r->scene;
  const long n = sim->n;
  double *buf = c->scratch;
  pm_field f[8];
  int nf = 0;
  unsigned fields = s->output.fields;
  /* Field data must stay valid for the call: give each its own slice. */
  double *u = buf, *scal = buf + 3 * n; /* scal: up to 6 scalars */
  if (fields & PM_FIELD_DISPLACEMENT) {
    displacement(sim, u);
    f[nf++] = (pm_field){"displacement", 3, u};
  }
  if (fields & PM_FIELD_VELOCITY) f[nf++] = (pm_field){"velocity", 3, sim->v};
  if (fields & PM_FIELD_STRESS) f[nf++] = (pm_field){"stress", 9, sim->sigma};
  double *sed = scal, *jac = scal + n, *rho = scal + 2 * n,
         *pres = scal + 3 * n, *ener = scal + 4 * n;
  for (int gi = 0; gi < sim->n_groups; gi++) {
    const mpm_group *g = &sim->group[gi];
    for (long p = g->begin; p < g->end; p++) {
      long k = p - g->begin;
      jac[p] = sim->vol[p] / sim->vol0[p];
      rho[p] = sim->mass[p] / sim->vol[p];
      const double *sg = sim->sigma + 9 * p;
      if (g->fluid) {
        sed[p] = 0;
        pres[p] = g->pressure[k];
        ener[p] = g->energy[k];
      } else {
        sed[p] = pm_material_energy(&g->solid, g->F + 9 * k, NULL);
        pres[p] = -(sg[0] + sg[4] + sg[8]) / 3.0;
        ener[p] = 0;
      }
    }
  }
  if (fields & PM_FIELD_STRAIN_ENERGY_DENSITY)
    f[nf++] = (pm_field){"strain_energy_density", 1, sed};
  if (fields & PM_FIELD_JACOBIAN) f[nf++] = (pm_field){"jacobian", 1, jac};
  if (sim->has_fluid) {
    f[nf++] = (pm_field){"density", 1, rho};
    f[nf++] = (pm_field){"pressure", 1, pres};
    f[nf++] = (pm_field){"internal_energy", 1, ener};
  }
  return pm_results_write_frame(c->results, sim->step, sim->t, nf, f);
}

/* ---- summary ------------------------------------------------------------ */

static pm_err write_summary(mpm_run *r, const char *out_dir) {
  pm_err ret = PM_SUCCESS;
  pm_json *j = NULL;
  char path[4096];
  const mpm_sim *sim = r->sim;
  const pm_scene *s = r->scene;
  PM_TRY(pm_path_join(path, sizeof path, out_dir, "summary.json"));
  PM_TRY(pm_json_open(path, &j));
  PM_TRY(pm_json_begin_object(j, NULL));
  PM_TRY(pm_json_run_header(j, s->path, s->name, "mpm", s->n_overrides,
                            s->overrides));
  PM_TRY(pm_json_string(j, "status", mpm_status_name(r->status)));
  if (r->message[0]) PM_TRY(pm_json_string(j, "message", r->message));
  PM_TRY(pm_json_integer(j, "dimension", sim->dim));
  PM_TRY(pm_json_integer(j, "points", sim->n));
  PM_TRY(pm_json_integer(j, "particles", sim->n));
  PM_TRY(pm_json_begin_object(j, "groups"));
  for (int gi = 0; gi < sim->n_groups; gi++) {
    const mpm_group *g = &sim->group[gi];
    PM_TRY(pm_json_begin_object(j, g->name));
    PM_TRY(pm_json_integer(j, "particles", g->end - g->begin));
    PM_TRY(pm_json_string(j, "kind", g->fluid ? "fluid" : "solid"));
    PM_TRY(pm_json_integer(j, "bytes_per_particle",
                           (long long)(mpm_particle_bytes_common() +
                                       mpm_group_bytes_per_particle(g))));
    PM_TRY(pm_json_end_object(j));
  }
  PM_TRY(pm_json_end_object(j));
  PM_TRY(pm_json_integer(j, "grid_nodes", sim->grid.n_nodes));
  PM_TRY(pm_json_number(j, "cell_size", sim->grid.h));
  PM_TRY(pm_json_number(j, "mesh_size", s->mesh_size));
  PM_TRY(pm_json_string(
      j, "shape", s->mpm.shape == PM_SHAPE_QUADRATIC ? "quadratic" : "linear"));
  PM_TRY(pm_json_string(j, "update",
                        s->mpm.update == PM_UPDATE_USF   ? "usf"
                        : s->mpm.update == PM_UPDATE_USL ? "usl"
                                                         : "musl"));
  PM_TRY(pm_json_number(j, "flip", s->mpm.flip));
  PM_TRY(pm_json_number(j, "dt", sim->dt));
  PM_TRY(pm_json_number(j, "dt_stable", sim->dt_stable));
  PM_TRY(pm_json_integer(j, "steps", sim->step));
  PM_TRY(pm_json_number(j, "time", sim->t));
  PM_TRY(pm_json_number(j, "residual", sim->residual));
  PM_TRY(pm_json_bool(j, "converged", r->status == MPM_STATUS_CONVERGED));
  PM_TRY(pm_json_number(j, "kinetic_energy", r->kinetic));
  PM_TRY(pm_json_number(j, "strain_energy", r->strain));
  if (sim->has_fluid) {
    PM_TRY(pm_json_number(j, "internal_energy", r->internal));
    PM_TRY(pm_json_integer(j, "energy_iterations_max", sim->iter_max_total));
    PM_TRY(
        pm_json_integer(j, "energy_iterations_capped", sim->iter_capped_total));
  }
  PM_TRY(pm_json_number(j, "initial_energy", r->energy0));
  PM_TRY(pm_json_number(j, "external_work", sim->external_work));
  PM_TRY(pm_json_number(j, "dissipated", sim->dissipated));
  PM_TRY(pm_json_number(j, "energy_balance_error", r->energy_error));
  mpm_field_figures ff;
  mpm_run_field_figures(r, &ff);
  PM_TRY(pm_json_number(j, "mean_strain_energy_density",
                        ff.mean_strain_energy_density));
  PM_TRY(pm_json_number(j, "max_von_mises", ff.max_von_mises));
  PM_TRY(
      pm_json_integer(j, "max_von_mises_particle", ff.max_von_mises_particle));
  PM_TRY(pm_json_number(j, "min_jacobian", ff.min_jacobian));
  PM_TRY(pm_json_integer(j, "min_jacobian_particle", ff.min_jacobian_particle));
  PM_TRY(pm_json_number(j, "wall_seconds", r->wall));
  PM_TRY(pm_json_number(j, "setup_seconds", r->setup_wall));
  int threads = pm_omp_threads();
  /* Particle-steps per second of the step alone (the stages), without
   * output. */
  double step_s = 0;
  for (int k = 0; k < sim->timers.n; k++)
    step_s += sim->timers.stage[k].seconds;
  double ps = step_s > 0 ? (double)sim->n * sim->step / step_s : 0;
  PM_TRY(pm_json_number(j, "step_seconds", step_s));
  PM_TRY(pm_json_integer(j, "threads", threads));
  PM_TRY(pm_json_number(j, "particle_steps_per_second", ps));
  PM_TRY(pm_json_number(j, "particle_steps_per_second_per_core", ps / threads));
  size_t bytes =
      mpm_grid_bytes(&sim->grid) + mpm_particle_bytes_common() * (size_t)sim->n;
  for (int gi = 0; gi < sim->n_groups; gi++)
    bytes += mpm_group_bytes_per_particle(&sim->group[gi]) *
             (size_t)(sim->group[gi].end - sim->group[gi].begin);
  PM_TRY(pm_json_integer(j, "memory_bytes", (long long)bytes));
  PM_TRY(pm_json_begin_object(j, "stage_seconds"));
  for (int k = 0; k < sim->timers.n; k++)
    PM_TRY(pm_json_number(j, sim->timers.stage[k].name,
                          sim->timers.stage[k].seconds));
  PM_TRY(pm_json_end_object(j));
  if (isfinite(r->nrmse_vector))
    PM_TRY(pm_json_number(j, "nrmse_displacement", r->nrmse_vector));
  PM_TRY(pm_json_begin_object(j, "nrmse"));
  for (int c = 0; c < 3; c++) {
    char key[8] = {'u', '_', "xyz"[c], 0};
    if (isfinite(r->nrmse[c])) PM_TRY(pm_json_number(j, key, r->nrmse[c]));
  }
  PM_TRY(pm_json_end_object(j));
  PM_TRY(pm_json_begin_object(j, "reactions"));
  for (int b = 0; b < s->n_bcs; b++) {
    if (!(s->bcs[b].disp_mask | s->bcs[b].velocity_mask)) continue;
    PM_TRY(pm_json_begin_array(j, pm_face_name(s->bcs[b].face)));
    for (int c = 0; c < 3; c++)
      PM_TRY(pm_json_number(j, NULL, sim->bcs[b].reaction[c]));
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

/* ---- run ---------------------------------------------------------------- */

static double load_end(const pm_scene *s) {
  double T = 0;
  for (int b = 0; b < s->n_bcs; b++)
    if ((s->bcs[b].disp_mask | s->bcs[b].velocity_mask) &&
        s->bcs[b].ramp != PM_RAMP_NONE)
      T = fmax(T, s->bcs[b].ramp_time);
  return T;
}

pm_err mpm_run_go(mpm_run *r, const char *out_dir, bool quiet) {
  pm_err ret = PM_SUCCESS, run_err = PM_SUCCESS;
  mpm_sim *sim = r->sim;
  const pm_scene *s = r->scene;
  run_ctx *c = NULL;
  pm_progress progress;
  PM_TRY(PM_ALLOC(c, 1, "run context"));
  c->run = r;
  PM_TRY(PM_ALLOC(c->scratch, 9 * sim->n, "output buffer"));
  if (s->reference_mask) PM_TRY(PM_ALLOC(c->ref, 3 * sim->n, "reference"));
  setup_history(c);
  PM_ENSURE(!c->overflow, PM_ERR_SCENE,
            "%s: boundary: expected at most %d history columns (reactions "
            "of every prescribed component), got more: merge boundary "
            "entries",
            s->path, MPM_HIST_MAX);
  if (out_dir) {
    PM_TRY(pm_mkdir_p(out_dir));
    PM_TRY(pm_results_create(out_dir, sim->dim, sim->n, sim->x0, 0, 1, NULL,
                             s->text, PM_VERSION, &c->results));
    PM_TRY(pm_history_open(out_dir, c->n_hist, c->names, &c->history));
  }
  pm_progress_init(&progress, stderr, s->name);
  mpm_energies(sim, &r->kinetic, &r->strain, &r->internal);
  r->energy0 = r->kinetic + r->strain + r->internal;
  r->energy_error = 0;
  const double t_load = load_end(s);
  const long every = s->output.every;
  double t0 = pm_wtime();
  c->t_start = t0;
  if (out_dir) {
    PM_TRY(write_frame(c));
    PM_TRY(write_history_row(c));
  }
  bool converged = false;
  for (;;) {
    if (sim->t >= s->time.end * (1 - 1e-12)) break;
    if (s->time.max_steps > 0 && sim->step >= s->time.max_steps) break;
    if (sim->dt_fixed > 0) {
      sim->dt = sim->dt_fixed;
      double left = s->time.end - sim->t;
      if (left < sim->dt && left > 1e-12 * sim->dt) sim->dt = left;
    }
    run_err = mpm_step(sim);
    if (run_err) break;
    if (sim->iter_max_step > c->iter_max_row)
      c->iter_max_row = sim->iter_max_step;
    if (s->time.qs != PM_QS_NONE && sim->t >= t_load && sim->step > 10 &&
        sim->residual < s->time.qs_tolerance) {
      converged = true;
    }
    bool frame = sim->step % every == 0 || converged;
    if (frame) {
      update_energy(r);
      if (out_dir) {
        PM_TRY(write_frame(c));
        PM_TRY(write_history_row(c));
      }
    }
    if (!quiet) {
      char status[96];
      snprintf(status, sizeof status, "step %ld t %.4g", sim->step, sim->t);
      pm_progress_update(&progress, sim->t / s->time.end, status);
    }
    if (converged) break;
  }
  r->wall = pm_wtime() - t0;
  if (!quiet) pm_progress_finish(&progress);
  update_energy(r);
  if (run_err == PM_ERR_UNSTABLE) {
    r->status = MPM_STATUS_UNSTABLE;
    snprintf(r->message, sizeof r->message,
             "%s; dt %.4g s (%s), stable estimate %.4g s", pm_error_message(),
             sim->dt, sim->dt_fixed > 0 ? "time.dt" : "dt_safety x stable",
             sim->dt_stable);
  } else if (run_err) {
    r->status = MPM_STATUS_FAILED;
    snprintf(r->message, sizeof r->message, "%s", pm_error_message());
  } else if (s->time.qs == PM_QS_NONE) {
    r->status = MPM_STATUS_COMPLETED;
  } else if (converged) {
    r->status = MPM_STATUS_CONVERGED;
  } else {
    r->status = MPM_STATUS_NOT_CONVERGED;
    snprintf(r->message, sizeof r->message,
             "quasi-static residual %.3g above tolerance %.3g at t = %.6g s "
             "after %ld steps (raise time.end or time.max_steps)",
             sim->residual, s->time.qs_tolerance, sim->t, sim->step);
  }
  if (r->status != MPM_STATUS_UNSTABLE && r->status != MPM_STATUS_FAILED) {
    compute_errors(c, sim->t);
    /* The last state as a frame, unless it was just written. */
    if (out_dir && sim->step % every != 0 && !converged) {
      PM_TRY(write_frame(c));
      PM_TRY(write_history_row(c));
    }
  }
  if (out_dir) {
    pm_results *res = c->results;
    c->results = NULL;
    PM_TRY(pm_results_close(res, true));
    pm_history *h = c->history;
    c->history = NULL;
    PM_TRY(pm_history_close(h, true));
    PM_TRY(write_summary(r, out_dir));
  }
  if (!quiet) {
    fprintf(stderr,
            "%s: %s after %ld steps, t = %.6g s (dt %.4g s), %ld particles, "
            "energy balance error %.3g\n",
            s->name, mpm_status_name(r->status), sim->step, sim->t, sim->dt,
            sim->n, r->energy_error);
    for (int k = 0; k < 3; k++)
      if (isfinite(r->nrmse[k]))
        fprintf(stderr, "  NRMSE u_%c = %.4e\n", "xyz"[k], r -> nrmse[k]);
    if (sim->iter_capped_total > 0)
      fprintf(stderr,
              "  energy iteration hit mpm.fluid.max_iterations = %d on %ld "
              "particle steps\n",
              s->mpm.max_iterations, sim->iter_capped_total);
    pm_timers_print(&sim->timers, stderr, r->setup_wall + r->wall);
  }
  if (run_err) {
    ret = PM_ERROR(run_err, "%s", r->message);
  } else if (r->status == MPM_STATUS_NOT_CONVERGED) {
    ret = PM_ERROR(PM_ERR_NOT_CONVERGED, "%s", r->message);
  }
done:
  if (c) {
    if (c->results) pm_results_close(c->results, false);
    if (c->history) pm_history_close(c->history, false);
    free(c->scratch);
    free(c->ref);
    free(c);
  }
  return ret;
}

/* ---- plan --------------------------------------------------------------- */

pm_err mpm_run_plan(mpm_run *r, FILE *out) {
  mpm_sim *sim = r->sim;
  const pm_scene *s = r->scene;
  const mpm_grid *g = &sim->grid;
  fprintf(out, "scene        %s (%s)\n", s->name, s->path);
  fprintf(out, "method       mpm, %dD%s, %s B-splines, %s, FLIP %g\n", sim->dim,
          sim->dim == 2 ? " plane strain" : "",
          s->mpm.shape == PM_SHAPE_QUADRATIC ? "quadratic" : "linear",
          s->mpm.update == PM_UPDATE_USF   ? "USF"
          : s->mpm.update == PM_UPDATE_USL ? "USL"
                                           : "MUSL",
          s->mpm.flip);
  fprintf(out, "grid         %ld x %ld x %ld nodes, cell %g m\n", g->nn[0],
          g->nn[1], g->nn[2], g->h);
  fprintf(out, "particles    %ld (%d x %d x %d per cell)\n", sim->n,
          s->mpm.ppc[0], s->mpm.ppc[1], sim->dim == 3 ? s->mpm.ppc[2] : 1);
  size_t common = mpm_particle_bytes_common();
  /* Particles, grid, and the run's output buffers (9 n, and 3 n for a
   * reference field). */
  size_t out_bytes =
      sizeof(double) * (size_t)sim->n * (s->reference_mask ? 12 : 9);
  size_t bytes = mpm_grid_bytes(g) + common * (size_t)sim->n + out_bytes;
  for (int gi = 0; gi < sim->n_groups; gi++) {
    const mpm_group *gr = &sim->group[gi];
    size_t own = mpm_group_bytes_per_particle(gr);
    long n = gr->end - gr->begin;
    bytes += own * (size_t)n;
    fprintf(out,
            "  group %-8s %ld particles, %s, %zu bytes per particle (%zu "
            "common + %zu:",
            gr->name, n, gr->fluid ? "fluid" : "solid", common + own, common,
            own);
    if (gr->F) fprintf(out, " F");
    if (gr->rho) fprintf(out, " density");
    if (gr->energy) fprintf(out, " energy");
    if (gr->pressure) fprintf(out, " pressure");
    if (gr->q) fprintf(out, " q");
    fprintf(out, "%s)\n", own ? "" : " none");
  }
  fprintf(out, "pipeline\n");
  for (int k = 0; k < sim->n_stages; k++)
    fprintf(out, "  %2d. %-20s %s\n", k + 1, sim->stage[k].name,
            sim->stage[k].detail);
  fprintf(out, "dt           %.4g s (%s); stable estimate %.4g s\n", sim->dt,
          sim->dt_fixed > 0 ? "time.dt" : "dt_safety x stable, each step",
          sim->dt_stable);
  if (sim->dt_fixed > sim->dt_stable)
    fprintf(out,
            "             warning: time.dt is %.2f x the stable estimate\n",
            sim->dt_fixed / sim->dt_stable);
  double steps = ceil(s->time.end / sim->dt);
  if (s->time.max_steps > 0 && steps > s->time.max_steps)
    steps = (double)s->time.max_steps;
  fprintf(out, "steps        %.0f to t = %g s%s%s\n", steps, s->time.end,
          s->time.qs != PM_QS_NONE ? " (at most: stops when converged)" : "",
          sim->dt_fixed > 0 ? ""
                            : " (at the first step's dt; the step adapts)");
  fprintf(out,
          "memory       %.1f MiB (grid %.1f MiB with %d thread "
          "accumulators, output buffers %.1f MiB)\n",
          bytes / 1048576.0, mpm_grid_bytes(g) / 1048576.0, g->threads,
          out_bytes / 1048576.0);
  /* Time a few steps (the state is advanced: a plan is not run after). */
  double t0 = pm_wtime();
  int reps = 0;
  while (pm_wtime() - t0 < 0.3 && reps < 200) {
    if (mpm_step(sim) != PM_SUCCESS) break;
    reps++;
  }
  if (reps > 0) {
    double per = (pm_wtime() - t0) / reps;
    fprintf(out,
            "estimate     %.3g s per step, %.3g s for %.0f steps on %d "
            "thread%s (%.3g particle-steps/s; setup took %.3g s)\n",
            per, per * steps, steps, pm_omp_threads(),
            pm_omp_threads() == 1 ? "" : "s", sim->n / per, r->setup_wall);
  }
  return PM_SUCCESS;
}
