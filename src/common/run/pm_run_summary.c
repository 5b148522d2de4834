/* pm_run_summary: the outcome of a run: its status and message, the loaded
 * face's reaction, summary.json and the report on stderr. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "pm_memory.h"
#include "pm_omp.h"
#include "pm_output.h"
#include "pm_run_impl.h"
#include "pm_scene_mirror.h"

static pm_err json_point(pm_json *j, const char *key, int dim,
                         const double x[3]) {
  PM_CALL(pm_json_begin_array(j, key));
  for (int a = 0; a < dim; a++) PM_CALL(pm_json_number(j, NULL, x[a]));
  return pm_json_end_array(j);
}

static pm_err summary_figures(pm_run_ctx *c, pm_json *j) {
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
  if (f->support_speed > 0) {
    PM_CALL(pm_json_number(j, "support_speed", f->support_speed));
    PM_CALL(
        pm_json_number(j, "shear_wave_speed", pm_scene_shear_wave_speed(s)));
  }
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
  if (f->tension) {
    PM_CALL(pm_json_number(j, "max_hydrostatic_tension", f->max_tension));
    PM_CALL(
        json_point(j, "max_hydrostatic_tension_at", f->dim, f->max_tension_at));
  }
  if (f->tension && f->cavitation_load > 0) {
    PM_CALL(pm_json_number(j, "cavitation_load", f->cavitation_load));
    PM_CALL(pm_json_number(j, "cavitation_ratio", f->cavitation_ratio));
    PM_CALL(
        json_point(j, "cavitation_ratio_at", f->dim, f->cavitation_ratio_at));
  }
  return PM_SUCCESS;
}

static pm_err summary_cost(pm_run_ctx *c, pm_json *j) {
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

static pm_err summary_accuracy(pm_run_ctx *c, pm_json *j) {
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
    pm_run_bc_label(s, b, label, sizeof label);
    PM_CALL(pm_json_begin_array(j, label));
    for (int k = 0; k < 3; k++)
      PM_CALL(pm_json_number(j, NULL, o->fig.reaction[b][k]));
    PM_CALL(pm_json_end_array(j));
  }
  PM_CALL(pm_json_end_object(j));
  if (s->mirror_mask) {
    PM_CALL(pm_json_begin_array(j, "symmetry_planes"));
    for (int b = 0; b < s->n_bcs; b++)
      if (s->bcs[b].symmetry)
        PM_CALL(pm_json_string(j, NULL, pm_face_name(s->bcs[b].face)));
    PM_CALL(pm_json_end_array(j));
  }
  return pm_json_number(j, "loaded_reaction", o->loaded_reaction);
}

/* OUT/summary.json.  running: while the run goes on, status "running" and
 * who runs it (a killed run leaves it so; its folder's lock is then free);
 * otherwise the outcome, figures, cost and accuracy. */
pm_err pm_run_write_summary(pm_run_ctx *c, bool running) {
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
    PM_TRY(pm_memory_summary(j));
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

/* The loaded face of s: the condition with the largest prescribed
 * displacement at time.end (at its face's centre) and that component; *bc
 * is -1 when there is none. */
static void loaded_face(const pm_scene *s, int *bc, int *comp) {
  double best = -1;
  *bc = -1;
  *comp = 0;
  for (int b = 0; b < s->n_bcs; b++) {
    const pm_scene_bc *B = &s->bcs[b];
    if (B->symmetry) continue;
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

static bool fast_supports(const pm_scene *s, const pm_figures *f) {
  const double c = pm_scene_shear_wave_speed(s);
  return c > 0 && f->support_speed > PM_QS_SUPPORT_SPEED_FAST * c &&
         f->time < pm_scene_load_end(s);
}

/* Where the solids' hydrostatic tension passed their cavitation load at
 * the end: what that means, into buf (false, buf untouched: it did not). */
static bool cavitation_note(const pm_figures *f, char *buf, size_t size) {
  if (!f->tension || !(f->cavitation_load > 0) || !(f->cavitation_ratio > 1))
    return false;
  const double *x = f->cavitation_ratio_at;
  snprintf(buf, size,
           "the hydrostatic tension reaches %.4g Pa at (%.4g, %.4g, %.4g), "
           "%.2f times its material's cavitation load under hydrostatic "
           "tension (%.4g Pa): where the stress is near hydrostatic the model "
           "admits a second equilibrium past it, a void grown from a point, "
           "which finer discretizations approach and no solver holds off "
           "(docs/formulation.md, \"Cavitation\")",
           f->cavitation_ratio * f->cavitation_load, x[0], x[1], x[2],
           f->cavitation_ratio, f->cavitation_load);
  return true;
}

/* Status and message from the loop's error and the figures. */
void pm_run_conclude(pm_run_ctx *c, pm_err run_err) {
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
  } else if (run_err == PM_ERR_UNSTABLE && fast_supports(s, f)) {
    /* A quasi-static run whose supports outrun the body during the ramp:
     * the body's lag behind them (its inertia, and relaxation's damping
     * dragging on what moves), not the step, is the first suspect. */
    const double end = pm_scene_load_end(s), c_s = pm_scene_shear_wave_speed(s),
                 ratio = f->support_speed / c_s;
    f->status = PM_STATUS_UNSTABLE;
    snprintf(o->message, sizeof o->message,
             "%s; during the ramp (it ends at t = %.4g s) the supports move "
             "at up to %.3g m/s, %.2f of the shear wave speed sqrt(mu/rho) = "
             "%.3g m/s: the body lags behind them (inertia, and the damping's "
             "drag on what moves), stretched near them; a longer time.ramp "
             "(about %.3g s moves them at %.2f of it) keeps the run "
             "quasi-static (stable step %.4g s)",
             pm_error_message(), end, f->support_speed, ratio, c_s,
             end * ratio / PM_QS_SUPPORT_SPEED_HELD, PM_QS_SUPPORT_SPEED_HELD,
             f->dt_stable);
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
  /* A run that did not end converged: the tension may say why. */
  char note[512];
  const size_t len = strlen(o->message);
  if (f->status != PM_STATUS_CONVERGED && len > 0 &&
      cavitation_note(f, note, sizeof note))
    snprintf(o->message + len, sizeof o->message - len, "; %s", note);
  int bc, comp;
  loaded_face(s, &bc, &comp);
  /* The whole body's, where the scene is a part mirrored about planes. */
  o->loaded_reaction =
      bc >= 0
          ? f->reaction[bc][comp] *
                pm_scene_mirror_factor(s, pm_scene_bc_axis(&s->bcs[bc]), comp)
          : NAN;
  o->loaded_axis = bc >= 0 ? comp : -1;
}

void pm_run_report(pm_run_ctx *c) {
  const pm_outcome *o = c->o;
  const pm_figures *f = &o->fig;
  fprintf(stderr,
          "%s: %s after %ld steps, t = %.6g s (dt %.4g s), %ld points, "
          "residual %.3g, energy balance error %.3g\n",
          c->s->name, pm_status_name(f->status), f->steps, f->time, f->dt,
          f->points, f->residual, f->energy_error);
  char note[512];
  if (f->status == PM_STATUS_CONVERGED && cavitation_note(f, note, sizeof note))
    fprintf(stderr, "  note: %s\n", note);
  for (int k = 0; k < 3; k++)
    if (isfinite(o->nrmse[k]))
      fprintf(stderr, "  NRMSE u_%c = %.4e\n", "xyz"[k], o -> nrmse[k]);
  pm_timers t = *c->be->timers(c->sim);
  int id = pm_timers_add(&t, "output");
  if (id >= 0) t.stage[id] = c->out_timer.stage[0];
  pm_timers_print(&t, stderr, f->setup_seconds + f->wall_seconds);
}
