/* mpm_driver: runs an MPM scene with output, history and progress through
 * the solver's observer. */
#include "mpm_driver.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_report.h"
#include "mpm_solver.h"
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
  PM_TRY(mpm_model_create(s, &r->model, &r->state));
  PM_TRY(mpm_work_create(r->model, &r->work));
  r->setup_wall = pm_wtime() - t0;
  PM_TRY(PM_ALLOC(r->scratch, 9 * r->model->n, "output buffer"));
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
  mpm_work_destroy(r->work);
  mpm_state_destroy(r->state);
  mpm_model_destroy(r->model);
  free(r->scratch);
  free(r);
}

/* Per particle into r->scratch: strain energy density, J, density,
 * pressure, internal energy (n each, in that order). */
static void particle_fields(const mpm_run *r) {
  const mpm_model *m = r->model;
  const mpm_state *s = r->state;
  const long n = m->n;
  double *sed = r->scratch, *jac = sed + n, *rho = sed + 2 * n,
         *pres = sed + 3 * n, *ener = sed + 4 * n;
  for (long p = 0; p < n; p++) {
    jac[p] = s->vol[p] / m->vol0[p];
    rho[p] = m->mass[p] / s->vol[p];
  }
  for (int gi = 0; gi < m->n_groups; gi++)
    m->group[gi].kind->fields(m, s, &m->group[gi], sed, pres, ener);
}

void mpm_run_field_figures(const mpm_run *r, mpm_field_figures *ff) {
  const mpm_model *m = r->model;
  const mpm_state *s = r->state;
  const double *sed = r->scratch;
  double w = 0, v0 = 0;
  *ff = (mpm_field_figures){.max_von_mises = 0,
                            .max_von_mises_particle = -1,
                            .min_jacobian = INFINITY,
                            .min_jacobian_particle = -1};
  particle_fields(r);
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    const bool elastic = g->kind->flags & MPM_KIND_STRAIN_ENERGY;
    for (long p = g->begin; p < g->end; p++) {
      double vm = pm_t_von_mises(s->sigma + 9 * p);
      if (vm > ff->max_von_mises) {
        ff->max_von_mises = vm;
        ff->max_von_mises_particle = p;
      }
      double J = s->vol[p] / m->vol0[p];
      if (J < ff->min_jacobian) {
        ff->min_jacobian = J;
        ff->min_jacobian_particle = p;
      }
      if (elastic) {
        w += m->vol0[p] * sed[p];
        v0 += m->vol0[p];
      }
    }
  }
  ff->mean_strain_energy_density = v0 > 0 ? w / v0 : NAN;
}

void mpm_reaction(const mpm_run *r, int b, double R[3]) {
  for (int c = 0; c < 3; c++) R[c] = r->work->cond.reaction[3 * b + c];
}

/* ---- history and frames ------------------------------------------------- */

typedef struct {
  mpm_run *run;
  pm_results *results;
  pm_history *history;
  pm_progress progress;
  bool quiet;
  int n_hist;
  const char *names[MPM_HIST_MAX];
  char names_buf[MPM_HIST_MAX][32];
  int reaction_bc[MPM_HIST_MAX];
  int reaction_comp[MPM_HIST_MAX];
  int col_internal, col_iter, col_nrmse;
  bool overflow;    /* more history columns than MPM_HIST_MAX */
  int iter_max_row; /* iterations since the last row */
  long iter_capped_prev;
  double *ref; /* 3 n or NULL */
  double t_start;
  pm_err output_err; /* the observer's failure */
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
  const mpm_model *m = c->run->model;
  const pm_scene *s = c->run->scene;
  static const char *const base[] = {"time", "step",           "wall_seconds",
                                     "dt",   "kinetic_energy", "strain_energy"};
  for (int k = 0; k < 6; k++) add_col(c, base[k]);
  c->col_internal = -1;
  if (m->kinds & MPM_KIND_INTERNAL_ENERGY) {
    c->col_internal = c->n_hist;
    add_col(c, "internal_energy");
  }
  add_col(c, "external_work");
  add_col(c, "dissipated");
  add_col(c, "energy_error");
  add_col(c, "residual");
  c->col_iter = -1;
  if (m->kinds & MPM_KIND_ITERATES) {
    c->col_iter = c->n_hist;
    add_col(c, "energy_iterations");
    add_col(c, "energy_iterations_capped");
  }
  for (int b = 0; b < m->n_bcs; b++) {
    unsigned mask = m->bcs[b].disp_mask | m->bcs[b].vel_mask;
    for (int k = 0; k < 3; k++) {
      if (!(mask >> k & 1u) || c->n_hist >= MPM_HIST_MAX) continue;
      char name[32];
      snprintf(name, sizeof name, "reaction_%s_%c",
               pm_face_name(m->bcs[b].face), "xyz"[k]);
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
  const mpm_model *m = c->run->model;
  const pm_scene *s = c->run->scene;
  /* Serial: an expression is not thread-safe. */
  for (long p = 0; p < m->n; p++) {
    const double *X = m->x0 + 3 * p;
    for (int k = 0; k < 3; k++)
      c->ref[3 * p + k] =
          s->reference[k] ? pm_expr_eval(s->reference[k], X[0], X[1], X[2], t)
                          : 0.0;
  }
}

static void displacement(const mpm_run *r, double *u) {
  const long n3 = 3 * r->model->n;
  const double *x = r->state->x, *x0 = r->model->x0;
  PM_OMP(parallel for schedule(static) default(none) shared(n3, x, x0, u))
  for (long i = 0; i < n3; i++) u[i] = x[i] - x0[i];
}

static void compute_errors(run_ctx *c, double t) {
  mpm_run *r = c->run;
  const pm_scene *s = r->scene;
  const long n = r->model->n;
  if (!c->ref) return;
  fill_reference(c, t);
  displacement(r, r->scratch);
  for (int k = 0; k < 3; k++)
    if (s->reference_mask >> k & 1u)
      r->nrmse[k] = pm_nrmse(n, 3, r->scratch + k, c->ref + k);
  r->nrmse_vector = pm_nrmse_vector(n, s->reference_mask, r->scratch, c->ref);
}

static void update_energy(mpm_run *r) {
  const mpm_state *s = r->state;
  mpm_energies(r->model, s, &r->kinetic, &r->strain, &r->internal);
  double E =
      r->kinetic + r->strain + r->internal + s->dissipated - s->external_work;
  double scale = fmax(fabs(r->energy0), fabs(s->external_work));
  r->energy_error = scale > 0 ? (E - r->energy0) / scale : 0.0;
}

static pm_err write_history_row(run_ctx *c) {
  mpm_run *r = c->run;
  const mpm_state *s = r->state;
  double row[MPM_HIST_MAX];
  int k = 0;
  row[k++] = s->t;
  row[k++] = (double)s->step;
  row[k++] = pm_wtime() - c->t_start;
  row[k++] = s->dt;
  row[k++] = r->kinetic;
  row[k++] = r->strain;
  if (c->col_internal >= 0) row[k++] = r->internal;
  row[k++] = s->external_work;
  row[k++] = s->dissipated;
  row[k++] = r->energy_error;
  row[k++] = r->work->residual;
  if (c->col_iter >= 0) {
    /* Over the steps since the previous row. */
    row[k++] = c->iter_max_row;
    row[k++] = (double)(s->iter_capped_total - c->iter_capped_prev);
    c->iter_capped_prev = s->iter_capped_total;
    c->iter_max_row = 0;
  }
  for (; k < c->n_hist && c->reaction_bc[k] >= 0; k++)
    row[k] =
        r->work->cond.reaction[3 * c->reaction_bc[k] + c->reaction_comp[k]];
  if (c->col_nrmse >= 0) {
    compute_errors(c, s->t);
    row[k++] = r->nrmse_vector;
  }
  return pm_history_row(c->history, row);
}

static pm_err write_frame(run_ctx *c) {
  mpm_run *r = c->run;
  const mpm_state *s = r->state;
  const long n = r->model->n;
  pm_field f[8];
  int nf = 0;
  unsigned fields = r->scene->output.fields;
  /* Field data must stay valid for the call: give each its own slice. */
  double *u = r->scratch + 6 * n, *sed = r->scratch, *jac = sed + n,
         *rho = sed + 2 * n, *pres = sed + 3 * n, *ener = sed + 4 * n;
  particle_fields(r);
  if (fields & PM_FIELD_DISPLACEMENT) {
    displacement(r, u);
    f[nf++] = (pm_field){"displacement", 3, u};
  }
  if (fields & PM_FIELD_VELOCITY) f[nf++] = (pm_field){"velocity", 3, s->v};
  if (fields & PM_FIELD_STRESS) f[nf++] = (pm_field){"stress", 9, s->sigma};
  if (fields & PM_FIELD_STRAIN_ENERGY_DENSITY)
    f[nf++] = (pm_field){"strain_energy_density", 1, sed};
  if (fields & PM_FIELD_JACOBIAN) f[nf++] = (pm_field){"jacobian", 1, jac};
  if (r->model->kinds & MPM_KIND_INTERNAL_ENERGY) {
    f[nf++] = (pm_field){"density", 1, rho};
    f[nf++] = (pm_field){"pressure", 1, pres};
    f[nf++] = (pm_field){"internal_energy", 1, ener};
  }
  return pm_results_write_frame(c->results, s->step, s->t, nf, f);
}

/* The solver's observer: energies and output on frames, progress. */
static pm_err observe(void *ctx, const mpm_model *m, const mpm_state *s,
                      const mpm_work *w, const mpm_step_info *info,
                      bool frame) {
  (void)m, (void)w;
  run_ctx *c = ctx;
  if (info->iter_max > c->iter_max_row) c->iter_max_row = info->iter_max;
  if (frame) {
    update_energy(c->run);
    if (c->results) {
      pm_err e = write_frame(c);
      if (!e) e = write_history_row(c);
      if (e) return c->output_err = e;
    }
  }
  if (!c->quiet) {
    char status[96];
    snprintf(status, sizeof status, "step %ld t %.4g", s->step, s->t);
    pm_progress_update(&c->progress, s->t / c->run->model->opt.t_end, status);
  }
  return PM_SUCCESS;
}

/* ---- run ---------------------------------------------------------------- */

/* The run's status and message from the solver's return. */
static void conclude(mpm_run *r, pm_err run_err, bool converged) {
  const mpm_model *m = r->model;
  const mpm_state *s = r->state;
  if (run_err == PM_ERR_UNSTABLE) {
    r->status = MPM_STATUS_UNSTABLE;
    snprintf(r->message, sizeof r->message,
             "%s; dt %.4g s (%s), stable estimate %.4g s", pm_error_message(),
             s->dt, m->opt.dt_fixed > 0 ? "time.dt" : "dt_safety x stable",
             s->dt_stable);
  } else if (run_err) {
    r->status = MPM_STATUS_FAILED;
    snprintf(r->message, sizeof r->message, "%s", pm_error_message());
  } else if (m->opt.qs == PM_QS_NONE) {
    r->status = MPM_STATUS_COMPLETED;
  } else if (converged) {
    r->status = MPM_STATUS_CONVERGED;
  } else {
    r->status = MPM_STATUS_NOT_CONVERGED;
    snprintf(r->message, sizeof r->message,
             "quasi-static residual %.3g above tolerance %.3g at t = %.6g s "
             "after %ld steps (raise time.end or time.max_steps)",
             r->work->residual, m->opt.qs_tolerance, s->t, s->step);
  }
}

static void print_end(const mpm_run *r) {
  const mpm_state *s = r->state;
  fprintf(stderr,
          "%s: %s after %ld steps, t = %.6g s (dt %.4g s), %ld particles, "
          "energy balance error %.3g\n",
          r->scene->name, mpm_status_name(r->status), s->step, s->t, s->dt,
          r->model->n, r->energy_error);
  for (int k = 0; k < 3; k++)
    if (isfinite(r->nrmse[k]))
      fprintf(stderr, "  NRMSE u_%c = %.4e\n", "xyz"[k], r -> nrmse[k]);
  if (s->iter_capped_total > 0)
    fprintf(stderr,
            "  energy iteration hit mpm.fluid.max_iterations = %d on %ld "
            "particle steps\n",
            r->model->opt.max_iterations, s->iter_capped_total);
  pm_timers_print(&r->work->timers, stderr, r->setup_wall + r->wall);
}

pm_err mpm_run_go(mpm_run *r, const char *out_dir, bool quiet) {
  pm_err ret = PM_SUCCESS, run_err = PM_SUCCESS;
  const mpm_model *m = r->model;
  mpm_state *st = r->state;
  const pm_scene *s = r->scene;
  run_ctx *c = NULL;
  PM_TRY(PM_ALLOC(c, 1, "run context"));
  c->run = r;
  c->quiet = quiet;
  if (s->reference_mask) PM_TRY(PM_ALLOC(c->ref, 3 * m->n, "reference"));
  setup_history(c);
  PM_ENSURE(!c->overflow, PM_ERR_SCENE,
            "%s: boundary: expected at most %d history columns (reactions "
            "of every prescribed component), got more: merge boundary "
            "entries",
            s->path, MPM_HIST_MAX);
  if (out_dir) {
    PM_TRY(pm_mkdir_p(out_dir));
    PM_TRY(pm_results_create(out_dir, m->dim, m->n, m->x0, 0, 1, NULL, s->text,
                             PM_VERSION, &c->results));
    PM_TRY(pm_history_open(out_dir, c->n_hist, c->names, &c->history));
  }
  pm_progress_init(&c->progress, stderr, s->name);
  mpm_energies(m, st, &r->kinetic, &r->strain, &r->internal);
  r->energy0 = r->kinetic + r->strain + r->internal;
  r->energy_error = 0;
  double t0 = pm_wtime();
  c->t_start = t0;
  if (out_dir) {
    PM_TRY(write_frame(c));
    PM_TRY(write_history_row(c));
  }
  mpm_run_options opt = {.t_end = m->opt.t_end,
                         .max_steps = m->opt.max_steps,
                         .frame_every = s->output.every};
  mpm_step_info last;
  run_err = mpm_solve(m, st, r->work, &opt, observe, c, &last);
  PM_TRY(c->output_err);
  const bool converged = !run_err && last.converged;
  r->wall = pm_wtime() - t0;
  if (!quiet) pm_progress_finish(&c->progress);
  update_energy(r);
  conclude(r, run_err, converged);
  if (r->status != MPM_STATUS_UNSTABLE && r->status != MPM_STATUS_FAILED) {
    compute_errors(c, st->t);
    /* The last state as a frame, unless it was just written. */
    if (out_dir && st->step % opt.frame_every != 0 && !converged) {
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
    PM_TRY(mpm_report_summary(r, out_dir));
  }
  if (!quiet) print_end(r);
  if (run_err) {
    ret = PM_ERROR(run_err, "%s", r->message);
  } else if (r->status == MPM_STATUS_NOT_CONVERGED) {
    ret = PM_ERROR(PM_ERR_NOT_CONVERGED, "%s", r->message);
  }
done:
  if (c) {
    if (c->results) pm_results_close(c->results, false);
    if (c->history) pm_history_close(c->history, false);
    free(c->ref);
    free(c);
  }
  return ret;
}
