/* pm_run: the one driver of every method: outputs, history, summary,
 * progress and timings around a backend's time loop. */
#include "pm_run.h"

#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>

#include "pm_memory.h"
#include "pm_metrics.h"
#include "pm_omp.h"
#include "pm_output.h"
#include "pm_petsc.h"

#define RUN_COLS (32 + PM_HISTORY_MAX + 3 * PM_FIGURES_MAX_BCS)
#define RUN_FIELDS 16

/* The shared history columns, in order. */
static const char *const shared_cols[] = {
    "time",           "step",          "wall_seconds",    "dt",
    "kinetic_energy", "strain_energy", "internal_energy", "interface_energy",
    "external_work",  "dissipated",    "energy_error",    "residual",
    "min_jacobian"};
#define N_SHARED ((int)(sizeof shared_cols / sizeof *shared_cols))

typedef struct {
  const pm_scene *s;
  const pm_backend *be;
  void *sim;
  pm_results *results;
  pm_history *history;
  pm_progress progress;
  bool show_progress;
  pm_points pts;
  int n_cols, n_own;
  const char *names[RUN_COLS];
  char names_buf[RUN_COLS][64];
  int react_bc[RUN_COLS], react_comp[RUN_COLS];
  double row[RUN_COLS];
  double *ref; /* 3 n reference displacement, or NULL */
  bool ref_time;
  double t_start;
  pm_timers out_timer; /* output: the one stage this driver times */
  int tm_output;
  pm_outcome *o;
} run_ctx;

/* ---- errors against the scene's reference field ------------------------- */

/* Serial: an expression is not thread-safe. */
static void fill_reference(run_ctx *c, double t) {
  const pm_scene *s = c->s;
  for (int k = 0; k < 3; k++) {
    if (!(s->reference_mask >> k & 1u)) continue;
    for (long i = 0; i < c->pts.n; i++) {
      const double *X = c->pts.x + 3 * i;
      c->ref[3 * i + k] = pm_expr_eval(s->reference[k], X[0], X[1], X[2], t);
    }
  }
}

/* NRMSE (eq. 28) of each reference component, and of the field: one
 * component's own, or the vector form over the largest |reference|. */
static void compute_errors(run_ctx *c, double t) {
  pm_outcome *o = c->o;
  const unsigned mask = c->s->reference_mask;
  int n_ref = 0;
  for (int k = 0; k < 3; k++) o->nrmse[k] = NAN;
  o->nrmse_vector = NAN;
  if (!c->ref) return;
  if (c->ref_time) fill_reference(c, t);
  const double *u = c->be->displacement(c->sim);
  for (int k = 0; k < 3; k++) {
    if (!(mask >> k & 1u)) continue;
    o->nrmse[k] = pm_nrmse(c->pts.n, 3, u + k, c->ref + k);
    o->nrmse_vector = o->nrmse[k];
    n_ref++;
  }
  if (n_ref > 1) o->nrmse_vector = pm_nrmse_vector(c->pts.n, mask, u, c->ref);
}

/* ---- history ------------------------------------------------------------ */

static void add_col(run_ctx *c, const char *name) {
  snprintf(c->names_buf[c->n_cols], sizeof c->names_buf[0], "%s", name);
  c->names[c->n_cols] = c->names_buf[c->n_cols];
  c->react_bc[c->n_cols] = -1;
  c->n_cols++;
}

/* A name for boundary condition b in columns and the summary. */
static void bc_label(const pm_scene *s, int b, char *buf, size_t size) {
  if (s->bcs[b].on == PM_ON_REGION)
    snprintf(buf, size, "boundary.%d", b);
  else
    snprintf(buf, size, "%s", s->bcs[b].surface);
}

static pm_err setup_columns(run_ctx *c) {
  const pm_scene *s = c->s;
  const char *own[PM_HISTORY_MAX];
  for (int k = 0; k < N_SHARED; k++) add_col(c, shared_cols[k]);
  c->n_own = c->be->history_names
                 ? c->be->history_names(c->sim, own, PM_HISTORY_MAX)
                 : 0;
  for (int k = 0; k < c->n_own; k++) add_col(c, own[k]);
  PM_CHECK(s->n_bcs <= PM_FIGURES_MAX_BCS, PM_ERR_SCENE,
           "%s: boundary: expected at most %d conditions, got %d", s->path,
           PM_FIGURES_MAX_BCS, s->n_bcs);
  for (int b = 0; b < s->n_bcs; b++) {
    unsigned mask = s->bcs[b].disp_mask | s->bcs[b].velocity_mask;
    for (int k = 0; k < 3; k++) {
      if (!(mask >> k & 1u)) continue;
      char label[32], name[48];
      bc_label(s, b, label, sizeof label);
      snprintf(name, sizeof name, "reaction_%s_%c", label, "xyz"[k]);
      add_col(c, name);
      c->react_bc[c->n_cols - 1] = b;
      c->react_comp[c->n_cols - 1] = k;
    }
  }
  for (int k = 0; k < 3; k++)
    if (s->reference_mask >> k & 1u) {
      char name[16];
      snprintf(name, sizeof name, "nrmse_u_%c", "xyz"[k]);
      add_col(c, name);
    }
  return PM_SUCCESS;
}

static pm_err write_row(run_ctx *c) {
  pm_figures f;
  memset(&f, 0, sizeof f);
  c->be->figures(c->sim, &f, false);
  double *row = c->row;
  const double shared[N_SHARED] = {
      f.time,        (double)f.steps, pm_wtime() - c->t_start,
      f.dt,          f.kinetic,       f.strain,
      f.internal,    f.interface,     f.external_work,
      f.dissipated,  f.energy_error,  f.residual,
      f.min_jacobian};
  int k = 0;
  for (; k < N_SHARED; k++) row[k] = shared[k];
  if (c->n_own) c->be->history_values(c->sim, row + k);
  k += c->n_own;
  for (; k < c->n_cols && c->react_bc[k] >= 0; k++)
    row[k] = f.reaction[c->react_bc[k]][c->react_comp[k]];
  if (c->ref) {
    compute_errors(c, f.time);
    for (int comp = 0; comp < 3; comp++)
      if (c->s->reference_mask >> comp & 1u) row[k++] = c->o->nrmse[comp];
  }
  return pm_history_row(c->history, row);
}

static pm_err write_frame(run_ctx *c, const pm_step_report *r) {
  pm_field fields[RUN_FIELDS];
  int nf = c->be->fields(c->sim, c->s->output.fields, fields, RUN_FIELDS);
  PM_CALL(pm_results_write_frame(c->results, r->step, r->t, nf, fields));
  return write_row(c);
}

/* SIGINT or SIGTERM received during a run (0: none).  Sticky for the
 * process: once a run is interrupted, pm_run_scene starts no other (a
 * study's remaining levels are refused without being set up). */
static volatile sig_atomic_t interrupt_signal;

static void on_interrupt(int sig) { interrupt_signal = sig; }

static const char *signal_name(int sig) {
  return sig == SIGINT ? "SIGINT" : "SIGTERM";
}

/* Catch SIGINT and SIGTERM once each (a second one acts as usual, so a
 * run that does not reach the end of its step can still be stopped). */
static void catch_interrupts(struct sigaction old[2]) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &sa, &old[0]);
  sigaction(SIGTERM, &sa, &old[1]);
}

static void release_interrupts(const struct sigaction old[2]) {
  sigaction(SIGINT, &old[0], NULL);
  sigaction(SIGTERM, &old[1], NULL);
}

static pm_err observe(void *ctx, const pm_step_report *r, bool frame) {
  run_ctx *c = ctx;
  /* After a signal, the state after this step becomes the last frame. */
  const int sig = interrupt_signal;
  if (c->show_progress) {
    char status[96];
    snprintf(status, sizeof status, "t=%.4g s  step %ld  residual %.2e", r->t,
             r->step, r->residual);
    pm_progress_update(&c->progress, r->progress, status);
  }
  if ((frame || sig) && c->results) {
    pm_timers_start(&c->out_timer, c->tm_output);
    pm_err e = write_frame(c, r);
    pm_timers_stop(&c->out_timer, c->tm_output);
    PM_CALL(e);
  }
  if (!sig) return PM_SUCCESS;
  return PM_ERROR(PM_ERR_INTERRUPTED,
                  "interrupted by %s after step %ld, t = %.6g s (results up "
                  "to this step kept)",
                  signal_name(sig), r->step, r->t);
}

/* ---- summary ------------------------------------------------------------ */

static pm_err json_point(pm_json *j, const char *key, int dim,
                         const double x[3]) {
  PM_CALL(pm_json_begin_array(j, key));
  for (int a = 0; a < dim; a++) PM_CALL(pm_json_number(j, NULL, x[a]));
  return pm_json_end_array(j);
}

static pm_err summary_figures(run_ctx *c, pm_json *j) {
  const pm_figures *f = &c->o->fig;
  const pm_scene *s = c->s;
  PM_CALL(pm_json_integer(j, "dimension", f->dim));
  PM_CALL(pm_json_integer(j, "points", f->points));
  PM_CALL(pm_json_number(j, "h", f->h));
  PM_CALL(pm_json_integer(j, "steps", f->steps));
  PM_CALL(pm_json_number(j, "time", f->time));
  PM_CALL(pm_json_number(j, "dt", f->dt));
  PM_CALL(pm_json_number(j, "dt_stable", f->dt_stable));
  PM_CALL(pm_json_number(j, "dt_safety", s->time.dt_safety));
  PM_CALL(pm_json_number(j, "residual", f->residual));
  PM_CALL(pm_json_bool(j, "converged", f->status == PM_STATUS_CONVERGED));
  PM_CALL(pm_json_number(j, "kinetic_energy", f->kinetic));
  PM_CALL(pm_json_number(j, "strain_energy", f->strain));
  PM_CALL(pm_json_number(j, "internal_energy", f->internal));
  PM_CALL(pm_json_number(j, "interface_energy", f->interface));
  PM_CALL(pm_json_number(j, "initial_energy", f->energy0));
  PM_CALL(pm_json_number(j, "external_work", f->external_work));
  PM_CALL(pm_json_number(j, "dissipated", f->dissipated));
  PM_CALL(pm_json_number(j, "energy_balance_error", f->energy_error));
  PM_CALL(pm_json_number(j, "max_energy_error", f->max_energy_error));
  PM_CALL(pm_json_number(j, "min_jacobian", f->min_jacobian));
  PM_CALL(pm_json_integer(j, "min_jacobian_step", f->min_jacobian_step));
  PM_CALL(pm_json_number(j, "end_min_jacobian", f->end_min_jacobian));
  PM_CALL(json_point(j, "end_min_jacobian_at", f->dim, f->end_min_jacobian_at));
  PM_CALL(pm_json_number(j, "mean_strain_energy_density", f->mean_sed));
  PM_CALL(pm_json_number(j, "max_von_mises", f->max_von_mises));
  PM_CALL(json_point(j, "max_von_mises_at", f->dim, f->max_von_mises_at));
  return PM_SUCCESS;
}

static pm_err summary_cost(run_ctx *c, pm_json *j) {
  const pm_figures *f = &c->o->fig;
  const pm_timers *t = c->be->timers(c->sim);
  int threads = pm_omp_threads();
  double ps =
      f->step_seconds > 0 ? (double)f->points * f->steps / f->step_seconds : 0;
  PM_CALL(pm_json_number(j, "wall_seconds", f->wall_seconds));
  PM_CALL(pm_json_number(j, "setup_seconds", f->setup_seconds));
  PM_CALL(pm_json_number(j, "step_seconds", f->step_seconds));
  PM_CALL(pm_json_integer(j, "threads", threads));
  PM_CALL(pm_json_number(j, "point_steps_per_second", ps));
  PM_CALL(pm_json_number(j, "point_steps_per_second_per_core", ps / threads));
  PM_CALL(pm_json_number(j, "seconds_per_point_step", ps > 0 ? 1 / ps : NAN));
  PM_CALL(pm_json_integer(j, "memory_bytes", (long long)f->memory_bytes));
  PM_CALL(pm_json_begin_object(j, "stage_seconds"));
  for (int k = 0; k < t->n; k++)
    PM_CALL(pm_json_number(j, t->stage[k].name, t->stage[k].seconds));
  PM_CALL(pm_json_number(j, "output", pm_timers_seconds(&c->out_timer, 0)));
  return pm_json_end_object(j);
}

static pm_err summary_accuracy(run_ctx *c, pm_json *j) {
  const pm_outcome *o = c->o;
  const pm_scene *s = c->s;
  if (isfinite(o->nrmse_vector))
    PM_CALL(pm_json_number(j, "nrmse_displacement", o->nrmse_vector));
  PM_CALL(pm_json_begin_object(j, "nrmse"));
  for (int k = 0; k < 3; k++) {
    char key[8] = {'u', '_', "xyz"[k], 0};
    if (isfinite(o->nrmse[k])) PM_CALL(pm_json_number(j, key, o->nrmse[k]));
  }
  PM_CALL(pm_json_end_object(j));
  PM_CALL(pm_json_begin_object(j, "reactions"));
  for (int b = 0; b < s->n_bcs; b++) {
    if (!(s->bcs[b].disp_mask | s->bcs[b].velocity_mask)) continue;
    char label[32];
    bc_label(s, b, label, sizeof label);
    PM_CALL(pm_json_begin_array(j, label));
    for (int k = 0; k < 3; k++)
      PM_CALL(pm_json_number(j, NULL, o->fig.reaction[b][k]));
    PM_CALL(pm_json_end_array(j));
  }
  return pm_json_end_object(j);
}

static pm_err write_summary(run_ctx *c, const char *out_dir) {
  pm_err ret = PM_SUCCESS;
  pm_json *j = NULL;
  char path[PM_PATH_MAX + 1];
  const pm_scene *s = c->s;
  PM_TRY(pm_path_join(path, sizeof path, out_dir, "summary.json"));
  PM_TRY(pm_json_open(path, &j));
  PM_TRY(pm_json_begin_object(j, NULL));
  PM_TRY(pm_json_run_header(j, s->path, s->name, s->method, s->n_overrides,
                            s->overrides));
  PM_TRY(pm_json_string(j, "status", pm_status_name(c->o->fig.status)));
  if (c->o->message[0]) PM_TRY(pm_json_string(j, "message", c->o->message));
  PM_TRY(summary_figures(c, j));
  PM_TRY(summary_cost(c, j));
  PM_TRY(summary_accuracy(c, j));
  if (c->be->summary) PM_TRY(c->be->summary(c->sim, j));
  PM_TRY(pm_json_end_object(j));
  ret = pm_json_close(j, true);
  j = NULL;
done:
  if (j) pm_json_close(j, false);
  return ret;
}

/* ---- the run ------------------------------------------------------------ */

/* The loaded face of s: the condition with the largest prescribed
 * displacement at time.end (at its face's centre) and that component; *bc
 * is -1 when there is none. */
static void loaded_face(const pm_scene *s, int *bc, int *comp) {
  double best = -1;
  *bc = -1;
  *comp = 0;
  for (int b = 0; b < s->n_bcs; b++) {
    const pm_scene_bc *B = &s->bcs[b];
    double x[3];
    for (int a = 0; a < 3; a++) x[a] = 0.5 * (s->box_min[a] + s->box_max[a]);
    if (B->on == PM_ON_FACE)
      x[pm_face_axis(B->face)] = pm_face_plane(B->face, s->box_min, s->box_max);
    for (int k = 0; k < 3; k++) {
      if (!(B->disp_mask & (1u << k))) continue;
      double v = fabs(pm_expr_eval(B->disp[k], x[0], x[1], x[2], s->time.end));
      if (v > best) {
        best = v;
        *bc = b;
        *comp = k;
      }
    }
  }
}

/* Status and message from the loop's error and the figures. */
static void conclude(run_ctx *c, pm_err run_err) {
  pm_outcome *o = c->o;
  const pm_scene *s = c->s;
  pm_figures *f = &o->fig;
  if (run_err == PM_ERR_INTERRUPTED) {
    f->status = PM_STATUS_INTERRUPTED;
    snprintf(o->message, sizeof o->message, "%s", pm_error_message());
  } else if (run_err == PM_ERR_UNSTABLE) {
    f->status = PM_STATUS_UNSTABLE;
    snprintf(o->message, sizeof o->message,
             "%s; dt %.4g s (%s), stable step %.4g s: reduce "
             "time.dt_safety or time.dt",
             pm_error_message(), f->dt,
             s->time.dt > 0 ? "set by time.dt" : "dt_safety x stable step",
             f->dt_stable);
  } else if (run_err != PM_SUCCESS) {
    f->status = PM_STATUS_FAILED;
    snprintf(o->message, sizeof o->message, "%s", pm_error_message());
  } else if (f->status == PM_STATUS_NOT_CONVERGED) {
    snprintf(o->message, sizeof o->message,
             "quasi-static residual %.3g above tolerance %.3g at t = %.6g s "
             "after %ld steps (raise time.end or time.max_steps)",
             f->residual, s->time.qs_tolerance, f->time, f->steps);
  }
  int bc, comp;
  loaded_face(s, &bc, &comp);
  o->loaded_reaction = bc >= 0 ? f->reaction[bc][comp] : NAN;
  o->loaded_axis = bc >= 0 ? comp : -1;
}

static void report(run_ctx *c) {
  const pm_outcome *o = c->o;
  const pm_figures *f = &o->fig;
  fprintf(stderr,
          "%s: %s after %ld steps, t = %.6g s (dt %.4g s), %ld points, "
          "residual %.3g, energy balance error %.3g\n",
          c->s->name, pm_status_name(f->status), f->steps, f->time, f->dt,
          f->points, f->residual, f->energy_error);
  for (int k = 0; k < 3; k++)
    if (isfinite(o->nrmse[k]))
      fprintf(stderr, "  NRMSE u_%c = %.4e\n", "xyz"[k], o -> nrmse[k]);
  pm_timers t = *c->be->timers(c->sim);
  int id = pm_timers_add(&t, "output");
  if (id >= 0) t.stage[id] = c->out_timer.stage[0];
  pm_timers_print(&t, stderr, f->setup_seconds + f->wall_seconds);
}

static pm_err open_outputs(run_ctx *c, const char *out_dir) {
  /* PETSc starts MPI, which may start a helper process; it must not
   * inherit the run's open files (results.h5's lock would outlive the
   * run), so a scene solved by Newton's method starts PETSc first. */
  if (c->s->time.qs == PM_QS_STATIC) PM_CALL(pm_petsc_init());
  PM_CALL(pm_mkdir_p(out_dir));
  PM_CALL(pm_results_create(out_dir, c->s->dimension, c->pts.n, c->pts.x,
                            c->pts.n_cells, c->pts.nodes_per_cell, c->pts.cells,
                            c->s->text, PM_VERSION, &c->results));
  return pm_history_open(out_dir, c->n_cols, c->names, &c->history);
}

pm_err pm_run_sim(const pm_scene *s, void *sim, const char *out_dir, bool quiet,
                  pm_outcome *o) {
  pm_err ret = PM_SUCCESS, run_err = PM_SUCCESS;
  run_ctx *c = NULL;
  memset(o, 0, sizeof *o);
  for (int k = 0; k < 3; k++) o->nrmse[k] = NAN;
  o->nrmse_vector = o->loaded_reaction = NAN;
  o->loaded_axis = -1;
  PM_TRY(PM_ALLOC(c, 1, "run context"));
  c->s = s;
  c->be = s->backend;
  c->sim = sim;
  c->o = o;
  c->show_progress = !quiet;
  c->tm_output = pm_timers_add(&c->out_timer, "output");
  c->be->points(sim, &c->pts);
  PM_TRY(setup_columns(c));
  if (s->reference_mask) {
    PM_TRY(PM_ALLOC(c->ref, 3 * c->pts.n, "reference field"));
    for (int k = 0; k < 3; k++)
      if ((s->reference_mask >> k & 1u) && pm_expr_uses(s->reference[k], 't'))
        c->ref_time = true;
    fill_reference(c, 0);
  }
  pm_progress_init(&c->progress, stderr, s->name);
  if (out_dir) PM_TRY(open_outputs(c, out_dir));
  pm_observer obs = {.ctx = c, .step = observe};
  c->t_start = pm_wtime();
  struct sigaction old_handlers[2];
  catch_interrupts(old_handlers);
  run_err = c->be->run(sim, &obs);
  release_interrupts(old_handlers);
  if (!quiet) pm_progress_finish(&c->progress);
  c->be->figures(sim, &o->fig, true);
  o->fig.wall_seconds = pm_wtime() - c->t_start;
  conclude(c, run_err);
  if (o->fig.status != PM_STATUS_UNSTABLE && o->fig.status != PM_STATUS_FAILED)
    compute_errors(c, o->fig.time);
  if (out_dir) {
    /* Frames written before a failure are good: keep them. */
    pm_results *r = c->results;
    c->results = NULL;
    PM_TRY(pm_results_close(r, true));
    pm_history *h = c->history;
    c->history = NULL;
    PM_TRY(pm_history_close(h, true));
    PM_TRY(write_summary(c, out_dir));
  }
  if (!quiet) report(c);
  if (run_err != PM_SUCCESS)
    ret = PM_ERROR(run_err, "%s", o->message);
  else if (o->fig.status == PM_STATUS_NOT_CONVERGED)
    ret = PM_ERROR(PM_ERR_NOT_CONVERGED, "%s", o->message);
done:
  if (c) {
    if (c->results) pm_results_close(c->results, false);
    if (c->history) pm_history_close(c->history, false);
    free(c->ref);
    free(c);
  }
  return ret;
}

pm_err pm_run_scene(const pm_scene *s, const char *out_dir, bool quiet,
                    pm_outcome *o) {
  void *sim = NULL;
  memset(o, 0, sizeof *o);
  o->fig.status = PM_STATUS_FAILED;
  const int sig = interrupt_signal;
  if (sig) {
    o->fig.status = PM_STATUS_INTERRUPTED;
    return PM_ERROR(PM_ERR_INTERRUPTED,
                    "not started: an earlier run was interrupted by %s",
                    signal_name(sig));
  }
  PM_CALL(pm_memory_check(s));
  PM_CALL(s->backend->create(s, &sim));
  pm_err e = pm_run_sim(s, sim, out_dir, quiet, o);
  s->backend->destroy(sim);
  return e;
}

pm_err pm_plan_scene(const pm_scene *s, FILE *out) {
  void *sim = NULL;
  PM_CALL(pm_memory_check(s));
  PM_CALL(s->backend->create(s, &sim));
  pm_err e = s->backend->plan(sim, out);
  if (e == PM_SUCCESS) pm_memory_plan(s, out);
  s->backend->destroy(sim);
  return e;
}
