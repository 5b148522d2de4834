/* pm_run: the one driver of every method: outputs, history, summary,
 * progress and timings around a backend's time loop. */
#include "pm_run.h"

#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "pm_memory.h"
#include "pm_metrics.h"
#include "pm_omp.h"
#include "pm_output.h"
#include "pm_par.h"
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
  pm_timers out_timer; /* the stages this driver times */
  int tm_output, tm_checkpoint;
  pm_outcome *o;
  /* output folder, checkpoints and resuming */
  const char *out_dir;
  pm_outdir *outdir;
  long history_rows;
  long ckpt_every;       /* steps (0: never) */
  double ckpt_seconds;   /* wall time (0: never) */
  double ckpt_last_wall; /* when the last one was written */
  long ckpt_step;        /* the step of the last one (-1: none) */
  long ckpt_count;       /* checkpoints written by this process */
  long resumes;          /* how often this run was resumed */
  long resumed_from;     /* the step it was last resumed from (0: none) */
  char ckpt_note[512];   /* why no checkpoint was written, if one failed */
  bool extra_frame;      /* the last frame is a signal's, off the schedule */
  /* what wants decided for the next step: the signal it ends on (0: none)
   * and whether a checkpoint is written after it */
  bool decided;
  int decided_sig;
  bool decided_ckpt;
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
  PM_CALL(pm_history_row(c->history, row));
  PM_CALL(pm_history_sync(c->history));
  c->history_rows++;
  return PM_SUCCESS;
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
 * run that does not reach the end of its step can still be stopped).
 * Across ranks every one is caught: mpirun forwards the signal it gets,
 * a batch system or timeout signals every process besides, so rank 0 may
 * get two at once; mpirun's SIGKILL, after odls_base_sigkill_timeout, is
 * the hard stop. */
static void catch_interrupts(struct sigaction old[2]) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = pm_par_active() ? 0 : SA_RESETHAND;
  sigaction(SIGINT, &sa, &old[0]);
  sigaction(SIGTERM, &sa, &old[1]);
}

static void release_interrupts(const struct sigaction old[2]) {
  sigaction(SIGINT, &old[0], NULL);
  sigaction(SIGTERM, &old[1], NULL);
}

/* ---- checkpoints -------------------------------------------------------- */

/* The driver's items of a checkpoint, before the backend's: what the run
 * is (program version, method, scene file, its text and the overrides) and
 * how far its outputs go.  Reading fills h (strings malloc'd). */
typedef struct {
  char *version, *method, *scene_path, *scene_text, *overrides;
  long frames, history_rows, threads, resumes, step;
  double wall_seconds, output_seconds, checkpoint_seconds;
} ckpt_header;

static void header_free(ckpt_header *h) {
  free(h->version);
  free(h->method);
  free(h->scene_path);
  free(h->scene_text);
  free(h->overrides);
  memset(h, 0, sizeof *h);
}

static pm_err header_items(pm_ckpt *ck, ckpt_header *h) {
  PM_CALL(pm_ckpt_string(ck, "run.version", &h->version));
  PM_CALL(pm_ckpt_string(ck, "run.method", &h->method));
  PM_CALL(pm_ckpt_string(ck, "run.scene_path", &h->scene_path));
  PM_CALL(pm_ckpt_string(ck, "run.scene_text", &h->scene_text));
  PM_CALL(pm_ckpt_string(ck, "run.overrides", &h->overrides));
  PM_CALL(pm_ckpt_long(ck, "run.step", &h->step));
  PM_CALL(pm_ckpt_long(ck, "run.frames", &h->frames));
  PM_CALL(pm_ckpt_long(ck, "run.history_rows", &h->history_rows));
  PM_CALL(pm_ckpt_long(ck, "run.threads", &h->threads));
  PM_CALL(pm_ckpt_long(ck, "run.resumes", &h->resumes));
  PM_CALL(pm_ckpt_double(ck, "run.wall_seconds", &h->wall_seconds));
  PM_CALL(pm_ckpt_double(ck, "run.output_seconds", &h->output_seconds));
  return pm_ckpt_double(ck, "run.checkpoint_seconds", &h->checkpoint_seconds);
}

/* The --set overrides as one string, one per line. */
static char *join_overrides(const pm_scene *s) {
  size_t len = 1;
  for (int k = 0; k < s->n_overrides; k++) len += strlen(s->overrides[k]) + 1;
  char *buf = malloc(len), *p = buf;
  if (!buf) return NULL;
  for (int k = 0; k < s->n_overrides; k++)
    p += sprintf(p, "%s\n", s->overrides[k]);
  *p = '\0';
  return buf;
}

/* Write OUT/checkpoint.h5 of the state after step (replacing the older
 * one).  PM_ERR_ARG when the method cannot checkpoint this scene. */
static pm_err write_checkpoint(run_ctx *c, long step) {
  pm_err ret = PM_SUCCESS;
  pm_ckpt *ck = NULL;
  const pm_scene *s = c->s;
  ckpt_header h = {
      .version = (char *)PM_VERSION,
      .method = s->method,
      .scene_path = s->path,
      .scene_text = s->text,
      .overrides = join_overrides(s),
      .step = step,
      /* A signal's frame is not one of the run's: a resumed run drops
       * it, so that its results are those of an uninterrupted run. */
      .frames = pm_results_frames(c->results) - c->extra_frame,
      .history_rows = c->history_rows - c->extra_frame,
      .threads = pm_omp_threads(),
      .resumes = c->resumes,
      .wall_seconds = pm_wtime() - c->t_start,
      .output_seconds = pm_timers_seconds(&c->out_timer, c->tm_output),
      .checkpoint_seconds = pm_timers_seconds(&c->out_timer, c->tm_checkpoint),
  };
  char *overrides = h.overrides;
  PM_ENSURE(c->be->checkpoint, PM_ERR_ARG, "method %s cannot write checkpoints",
            s->method);
  PM_ENSURE(overrides, PM_ERR_MEMORY, "cannot join the scene's overrides");
  pm_timers_start(&c->out_timer, c->tm_checkpoint);
  PM_TRY(pm_ckpt_create(c->out_dir, &ck));
  PM_TRY(header_items(ck, &h));
  PM_TRY(c->be->checkpoint(c->sim, ck));
  pm_ckpt *done_ck = ck;
  ck = NULL;
  PM_TRY(pm_ckpt_finish(done_ck));
  c->ckpt_step = step;
  c->ckpt_count++;
  c->ckpt_last_wall = pm_wtime();
done:
  pm_timers_stop(&c->out_timer, c->tm_checkpoint);
  pm_ckpt_abort(ck);
  free(overrides);
  return ret;
}

/* A checkpoint is due after step (not the initial state). */
static bool checkpoint_due(const run_ctx *c, const pm_step_report *r) {
  const long step = r->step;
  /* None after the last step: there is nothing to resume. */
  if (step <= 0 || step == c->ckpt_step || r->last) return false;
  if (c->ckpt_every > 0 && step % c->ckpt_every == 0) return true;
  return c->ckpt_seconds > 0 &&
         pm_wtime() - c->ckpt_last_wall >= c->ckpt_seconds;
}

/* After a signal, the state after this step becomes the last frame and a
 * checkpoint; on the run's last step the run simply ends.  Decided once
 * per step: by wants when the backend asks first, else by observe. */
static void decide(run_ctx *c, const pm_step_report *r) {
  if (c->decided) return;
  c->decided = true;
  c->decided_sig = r->last ? 0 : interrupt_signal;
  c->decided_ckpt =
      c->results && (checkpoint_due(c, r) || (c->decided_sig && r->step > 0));
}

static bool wants(void *ctx, const pm_step_report *r, bool frame) {
  run_ctx *c = ctx;
  decide(c, r);
  return frame || c->decided_sig || c->decided_ckpt;
}

static pm_err observe(void *ctx, const pm_step_report *r, bool frame) {
  run_ctx *c = ctx;
  decide(c, r);
  c->decided = false;
  const int sig = c->decided_sig;
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
    c->extra_frame = !frame;
  }
  if (c->decided_ckpt) {
    pm_err e = write_checkpoint(c, r->step);
    if (e == PM_ERR_ARG && sig) /* the method cannot: say so, go on */
      snprintf(c->ckpt_note, sizeof c->ckpt_note, "no checkpoint: %s",
               pm_error_message());
    else
      PM_CALL(e);
  }
  if (!sig) return PM_SUCCESS;
  if (c->ckpt_step == r->step)
    return PM_ERROR(PM_ERR_INTERRUPTED,
                    "interrupted by %s after step %ld, t = %.6g s (results up "
                    "to this step kept; `pointmech resume %s` continues from "
                    "its checkpoint)",
                    signal_name(sig), r->step, r->t, c->out_dir);
  return PM_ERROR(PM_ERR_INTERRUPTED,
                  "interrupted by %s after step %ld, t = %.6g s (results up "
                  "to this step kept%s%s)",
                  signal_name(sig), r->step, r->t, c->ckpt_note[0] ? "; " : "",
                  c->ckpt_note);
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
  PM_CALL(pm_json_number(j, "output",
                         pm_timers_seconds(&c->out_timer, c->tm_output)));
  PM_CALL(pm_json_number(j, "checkpoint",
                         pm_timers_seconds(&c->out_timer, c->tm_checkpoint)));
  PM_CALL(pm_json_end_object(j));
  PM_CALL(pm_json_integer(j, "checkpoints", c->ckpt_count));
  PM_CALL(pm_json_integer(j, "checkpoint_step", c->ckpt_step));
  PM_CALL(pm_json_integer(j, "resumes", c->resumes));
  return pm_json_integer(j, "resumed_from_step", c->resumed_from);
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

/* OUT/summary.json.  running: while the run goes on, status "running" and
 * who runs it (a killed run leaves it so; its folder's lock is then free);
 * otherwise the outcome, figures, cost and accuracy. */
static pm_err write_summary(run_ctx *c, bool running) {
  pm_err ret = PM_SUCCESS;
  pm_json *j = NULL;
  char path[PM_PATH_MAX + 1];
  const pm_scene *s = c->s;
  PM_TRY(pm_path_join(path, sizeof path, c->out_dir, "summary.json"));
  PM_TRY(pm_json_open(path, &j));
  PM_TRY(pm_json_begin_object(j, NULL));
  PM_TRY(pm_json_run_header(j, s->path, s->name, s->method, s->n_overrides,
                            s->overrides));
  if (running) {
    PM_TRY(pm_json_string(j, "status", "running"));
    PM_TRY(pm_json_integer(j, "pid", (long long)getpid()));
    PM_TRY(pm_json_integer(j, "started", (long long)time(NULL)));
    PM_TRY(pm_json_integer(j, "resumes", c->resumes));
    PM_TRY(pm_json_integer(j, "resumed_from_step", c->resumed_from));
  } else {
    PM_TRY(pm_json_string(j, "status", pm_status_name(c->o->fig.status)));
    if (c->o->message[0]) PM_TRY(pm_json_string(j, "message", c->o->message));
    PM_TRY(pm_json_integer(j, "frames", pm_results_frames(c->results)));
    PM_TRY(summary_figures(c, j));
    PM_TRY(summary_cost(c, j));
    PM_TRY(summary_accuracy(c, j));
    if (c->be->summary) PM_TRY(c->be->summary(c->sim, j));
  }
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
  } else if (run_err == PM_ERR_NOT_CONVERGED) {
    /* A solve by load steps that could not go on: its message names the
     * step, the load and the cause. */
    f->status = PM_STATUS_NOT_CONVERGED;
    snprintf(o->message, sizeof o->message, "%s", pm_error_message());
  } else if (run_err == PM_ERR_UNSTABLE &&
             (strstr(pm_error_message(), PM_EXPR_NOT_FINITE) ||
              s->time.qs == PM_QS_STATIC || f->dt == 0)) {
    /* A condition's expression, or a static solve (load steps, no time
     * step), not the step: no advice on dt. */
    f->status = PM_STATUS_UNSTABLE;
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

/* What a resumed run starts from: the checkpoint being read (positioned
 * after the driver's items) and its header. */
typedef struct {
  pm_ckpt *ck;
  ckpt_header h;
} resume_info;

static pm_outdir_mode outdir_mode(unsigned flags) {
  return flags & PM_RUN_OVERWRITE ? PM_OUTDIR_OVERWRITE : PM_OUTDIR_NEW;
}

/* outdir: the folder, claimed by the caller (taken over), or NULL. */
static pm_err open_outputs(run_ctx *c, const char *out_dir, unsigned flags,
                           pm_outdir **outdir, resume_info *rs) {
  /* PETSc starts MPI, which may start a helper process; it must not
   * inherit the run's open files (results.h5's lock would outlive the
   * run), so a scene solved by Newton's method starts PETSc first. */
  if (c->s->time.qs == PM_QS_STATIC) PM_CALL(pm_petsc_init());
  c->out_dir = out_dir;
  if (outdir && *outdir) {
    c->outdir = *outdir;
    *outdir = NULL;
  } else {
    PM_CALL(pm_outdir_claim(out_dir, outdir_mode(flags), &c->outdir));
  }
  if (rs) {
    PM_CALL(pm_results_reopen(out_dir, c->pts.n, rs->h.frames, &c->results));
    c->history_rows = rs->h.history_rows;
    PM_CALL(pm_history_open(out_dir, c->n_cols, c->names, c->history_rows,
                            &c->history));
  } else {
    PM_CALL(pm_results_create_ex(out_dir, c->s->dimension, &c->pts, c->s->text,
                                 PM_VERSION, &c->results));
    PM_CALL(pm_history_open(out_dir, c->n_cols, c->names, -1, &c->history));
  }
  return write_summary(c, true);
}

/* Read the backend's items of a checkpoint and check it whole. */
static pm_err restore(run_ctx *c, resume_info *rs) {
  PM_CHECK(c->be->checkpoint, PM_ERR_ARG, "method %s cannot resume",
           c->s->method);
  PM_CALL(c->be->checkpoint(c->sim, rs->ck));
  pm_ckpt *ck = rs->ck;
  rs->ck = NULL;
  PM_CALL(pm_ckpt_finish(ck));
  c->resumes = rs->h.resumes + 1;
  c->resumed_from = rs->h.step;
  c->ckpt_step = rs->h.step;
  c->out_timer.stage[c->tm_output].seconds = rs->h.output_seconds;
  c->out_timer.stage[c->tm_checkpoint].seconds = rs->h.checkpoint_seconds;
  if (rs->h.threads != pm_omp_threads())
    fprintf(stderr,
            "pointmech: warning: the checkpoint was written on %ld threads, "
            "this run has %d: results differ from an uninterrupted run at "
            "round-off (set OMP_NUM_THREADS=%ld to repeat it bit for bit)\n",
            rs->h.threads, pm_omp_threads(), rs->h.threads);
  return PM_SUCCESS;
}

static pm_err run_sim(const pm_scene *s, void *sim, const char *out_dir,
                      unsigned flags, pm_outcome *o, pm_outdir **outdir,
                      resume_info *rs) {
  pm_err ret = PM_SUCCESS, run_err = PM_SUCCESS;
  run_ctx *c = NULL;
  const bool quiet = flags & PM_RUN_QUIET;
  bool agreed = false; /* across ranks: the others heard how setup went */
  void (*old_xfsz)(int) = SIG_ERR;
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
  c->tm_checkpoint = pm_timers_add(&c->out_timer, "checkpoint");
  c->ckpt_step = -1;
  c->ckpt_every = s->output.checkpoint.every;
  c->ckpt_seconds = 60 * s->output.checkpoint.minutes;
  c->be->points(sim, &c->pts);
  PM_TRY(setup_columns(c));
  if (s->reference_mask) {
    PM_TRY(PM_ALLOC(c->ref, 3 * c->pts.n, "reference field"));
    for (int k = 0; k < 3; k++)
      if ((s->reference_mask >> k & 1u) && pm_expr_uses(s->reference[k], 't'))
        c->ref_time = true;
    fill_reference(c, 0);
  }
  if (rs) PM_TRY(restore(c, rs));
  pm_progress_init(&c->progress, stderr, s->name);
  /* A full disk or the file size limit fails a write (EFBIG) instead of
   * killing the process, so that the run can say what happened. */
  old_xfsz = signal(SIGXFSZ, SIG_IGN);
  if (out_dir) PM_TRY(open_outputs(c, out_dir, flags, outdir, rs));
  pm_observer obs = {.ctx = c, .step = observe, .wants = wants};
  c->t_start = pm_wtime() - (rs ? rs->h.wall_seconds : 0);
  c->ckpt_last_wall = pm_wtime();
  struct sigaction old_handlers[2];
  catch_interrupts(old_handlers);
  /* Across ranks, the others wait here for this rank's outputs. */
  agreed = true;
  PM_TRY(pm_par_agree(PM_SUCCESS));
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
    pm_history *h = c->history;
    c->history = NULL;
    PM_TRY(pm_history_close(h));
    PM_TRY(write_summary(c, false));
  }
  if (!quiet) report(c);
  if (run_err != PM_SUCCESS)
    ret = PM_ERROR(run_err, "%s", o->message);
  else if (o->fig.status == PM_STATUS_NOT_CONVERGED)
    ret = PM_ERROR(PM_ERR_NOT_CONVERGED, "%s", o->message);
done:
  if (!agreed) pm_par_agree(ret ? ret : PM_ERR_INTERNAL);
  if (old_xfsz != SIG_ERR) signal(SIGXFSZ, old_xfsz);
  if (c) {
    pm_results_close(c->results, o->fig.status != PM_STATUS_NOT_RUN);
    if (c->history) pm_history_close(c->history);
    pm_outdir_release(c->outdir);
    free(c->ref);
    free(c);
  }
  return ret;
}

pm_err pm_run_sim(const pm_scene *s, void *sim, const char *out_dir,
                  unsigned flags, pm_outcome *o) {
  return run_sim(s, sim, out_dir, flags, o, NULL, NULL);
}

/* Refuse to start once a run of this process was interrupted. */
static pm_err check_not_interrupted(pm_outcome *o) {
  memset(o, 0, sizeof *o);
  o->fig.status = PM_STATUS_FAILED;
  const int sig = interrupt_signal;
  if (!sig) return PM_SUCCESS;
  o->fig.status = PM_STATUS_INTERRUPTED;
  return PM_ERROR(PM_ERR_INTERRUPTED,
                  "not started: an earlier run was interrupted by %s",
                  signal_name(sig));
}

/* A rank other than 0 of a run across ranks: it steps its share and joins
 * the collectives of rank 0's observer, which writes everything; a signal
 * is rank 0's to act on. */
static pm_err run_worker(const pm_scene *s, void *sim, pm_outcome *o) {
  struct sigaction ignore, old[2];
  memset(&ignore, 0, sizeof ignore);
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGINT, &ignore, &old[0]);
  sigaction(SIGTERM, &ignore, &old[1]);
  pm_err e = pm_par_agree(PM_SUCCESS); /* rank 0's outputs are open */
  if (!e) e = s->backend->run(sim, NULL);
  release_interrupts(old);
  if (e) snprintf(o->message, sizeof o->message, "%s", pm_error_message());
  return e;
}

pm_err pm_run_scene(const pm_scene *s, const char *out_dir, unsigned flags,
                    pm_outcome *o) {
  pm_err ret = PM_SUCCESS;
  void *sim = NULL;
  pm_outdir *outdir = NULL;
  const bool ranks = pm_par_active(), root = pm_par_root();
  PM_CALL(check_not_interrupted(o));
  PM_CALL(pm_par_agree(pm_memory_check(s)));
  /* The folder first: a busy or taken one is refused before the setup
   * (across ranks, rank 0 writes everything). */
  if (out_dir && root)
    ret = pm_outdir_claim(out_dir, outdir_mode(flags), &outdir);
  if (ranks) ret = pm_par_agree(ret);
  if (ret) goto done;
  PM_TRY(s->backend->create(s, &sim));
  if (root)
    ret = run_sim(s, sim, out_dir, flags, o, &outdir, NULL);
  else
    ret = run_worker(s, sim, o);
done:
  if (sim) s->backend->destroy(sim);
  pm_outdir_release(outdir);
  return ret;
}

/* The overrides of a checkpoint (one per line) as an argument vector
 * pointing into text (changed in place). */
static int split_overrides(char *text, char **argv, int max) {
  int n = 0;
  for (char *p = text; *p && n < max;) {
    char *nl = strchr(p, '\n');
    if (nl) *nl = '\0';
    argv[n++] = p;
    if (!nl) break;
    p = nl + 1;
  }
  return n;
}

/* What every rank reads and checks before a resumed run is set up: rank 0
 * claims the folder and checks that its run can be resumed; each rank
 * opens the checkpoint, reads the driver's items and loads the scene they
 * name, which must be the one the checkpoint was made of. */
static pm_err resume_open(const char *out_dir, resume_info *rs,
                          pm_outdir **outdir, pm_scene **s, char **argv) {
  if (pm_par_root()) {
    PM_CALL(pm_outdir_claim(out_dir, PM_OUTDIR_RESUME, outdir));
    /* A run that ended by itself has nothing to resume; one that was
     * interrupted, killed (still "running") or failed on I/O has. */
    char status[64];
    pm_summary_status(out_dir, status, sizeof status);
    PM_CHECK(!status[0] || !strcmp(status, "interrupted") ||
                 !strcmp(status, "running") || !strcmp(status, "failed"),
             PM_ERR_ARG,
             "cannot resume '%s': its run has ended (status \"%s\"); start "
             "a new run (--overwrite) to run it again",
             out_dir, status);
  }
  PM_CALL(pm_ckpt_open(out_dir, &rs->ck));
  PM_CALL(header_items(rs->ck, &rs->h));
  PM_CHECK(strcmp(rs->h.version, PM_VERSION) == 0, PM_ERR_ARG,
           "cannot resume '%s': its checkpoint was written by pointmech %s, "
           "this is pointmech %s",
           out_dir, rs->h.version, PM_VERSION);
  int n_sets = split_overrides(rs->h.overrides, argv, 256);
  PM_CALL(
      pm_scene_load(rs->h.scene_path, n_sets, (const char *const *)argv, s));
  PM_CHECK(strcmp((*s)->text, rs->h.scene_text) == 0, PM_ERR_ARG,
           "cannot resume '%s': the scene %s has changed since its "
           "checkpoint (step %ld); restore it, or start a new run",
           out_dir, rs->h.scene_path, rs->h.step);
  PM_CHECK(strcmp((*s)->method, rs->h.method) == 0, PM_ERR_ARG,
           "cannot resume '%s': the checkpoint is of method %s, the scene "
           "now names %s",
           out_dir, rs->h.method, (*s)->method);
  return PM_SUCCESS;
}

/* A rank other than 0 resuming a run across ranks: it reads the
 * backend's items of the checkpoint too (into the whole state it holds
 * until the run starts), then steps its share. */
static pm_err resume_worker(const pm_scene *s, void *sim, resume_info *rs,
                            pm_outcome *o) {
  pm_err e = s->backend->checkpoint
                 ? s->backend->checkpoint(sim, rs->ck)
                 : PM_ERROR(PM_ERR_ARG, "method %s cannot resume", s->method);
  if (!e) {
    pm_ckpt *ck = rs->ck;
    rs->ck = NULL;
    e = pm_ckpt_finish(ck);
  }
  if (e) return pm_par_agree(e); /* rank 0 hears it before its run */
  return run_worker(s, sim, o);
}

pm_err pm_resume(const char *out_dir, unsigned flags, pm_outcome *o) {
  pm_err ret = PM_SUCCESS;
  resume_info rs = {0};
  pm_outdir *outdir = NULL;
  pm_scene *s = NULL;
  void *sim = NULL;
  char *argv[256];
  PM_CALL(check_not_interrupted(o));
  PM_TRY(pm_par_agree(resume_open(out_dir, &rs, &outdir, &s, argv)));
  PM_TRY(pm_par_agree(pm_memory_check(s)));
  PM_TRY(s->backend->create(s, &sim));
  if (pm_par_root())
    ret = run_sim(s, sim, out_dir, flags, o, &outdir, &rs);
  else
    ret = resume_worker(s, sim, &rs, o);
done:
  if (sim) s->backend->destroy(sim);
  pm_scene_destroy(s);
  pm_ckpt_abort(rs.ck);
  pm_outdir_release(outdir);
  header_free(&rs.h);
  return ret;
}

pm_err pm_plan_scene(const pm_scene *s, FILE *out) {
  void *sim = NULL;
  PM_CALL(pm_par_agree(pm_memory_check(s)));
  PM_CALL(s->backend->create(s, &sim));
  pm_err e = s->backend->plan(sim, out);
  if (e == PM_SUCCESS) pm_memory_plan(s, out);
  s->backend->destroy(sim);
  return e;
}
