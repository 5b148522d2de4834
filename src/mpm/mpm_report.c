/* mpm_report: summary.json and the plan of an MPM run. */
#include "mpm_report.h"

#include <math.h>

#include "mpm_kind.h"
#include "pm_files.h"
#include "pm_omp.h"

static const char *shape_name(pm_shape s) {
  return s == PM_SHAPE_QUADRATIC ? "quadratic" : "linear";
}

/* "usf", "usl", "musl"; upper case with upper. */
static const char *update_name(pm_update u, bool upper) {
  static const char *const lower_names[] = {"usf", "usl", "musl"};
  static const char *const upper_names[] = {"USF", "USL", "MUSL"};
  return (upper ? upper_names : lower_names)[u];
}

/* Everything the run holds: model, state, workspace and output buffer. */
static size_t run_bytes(const mpm_run *r) {
  return mpm_model_bytes(r->model) + mpm_state_bytes(r->model, r->state) +
         mpm_work_bytes(r->model, r->work) +
         9 * sizeof(double) * (size_t)r->model->n;
}

static pm_err summary_groups(pm_json *j, const mpm_model *m) {
  PM_CALL(pm_json_begin_object(j, "groups"));
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    PM_CALL(pm_json_begin_object(j, g->name));
    PM_CALL(pm_json_integer(j, "particles", g->end - g->begin));
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

static pm_err summary_figures(pm_json *j, const mpm_run *r) {
  mpm_field_figures ff;
  mpm_run_field_figures(r, &ff);
  PM_CALL(pm_json_number(j, "mean_strain_energy_density",
                         ff.mean_strain_energy_density));
  PM_CALL(pm_json_number(j, "max_von_mises", ff.max_von_mises));
  PM_CALL(
      pm_json_integer(j, "max_von_mises_particle", ff.max_von_mises_particle));
  PM_CALL(pm_json_number(j, "min_jacobian", ff.min_jacobian));
  return pm_json_integer(j, "min_jacobian_particle", ff.min_jacobian_particle);
}

static pm_err summary_timing(pm_json *j, const mpm_run *r) {
  const pm_timers *t = &r->work->timers;
  PM_CALL(pm_json_number(j, "wall_seconds", r->wall));
  PM_CALL(pm_json_number(j, "setup_seconds", r->setup_wall));
  int threads = pm_omp_threads();
  /* Particle-steps per second of the step alone (the stages), without
   * output. */
  double step_s = 0;
  for (int k = 0; k < t->n; k++) step_s += t->stage[k].seconds;
  double ps = step_s > 0 ? (double)r->model->n * r->state->step / step_s : 0;
  PM_CALL(pm_json_number(j, "step_seconds", step_s));
  PM_CALL(pm_json_integer(j, "threads", threads));
  PM_CALL(pm_json_number(j, "particle_steps_per_second", ps));
  PM_CALL(
      pm_json_number(j, "particle_steps_per_second_per_core", ps / threads));
  PM_CALL(pm_json_integer(j, "memory_bytes", (long long)run_bytes(r)));
  PM_CALL(pm_json_begin_object(j, "stage_seconds"));
  for (int k = 0; k < t->n; k++)
    PM_CALL(pm_json_number(j, t->stage[k].name, t->stage[k].seconds));
  return pm_json_end_object(j);
}

static pm_err summary_errors(pm_json *j, const mpm_run *r) {
  const mpm_model *m = r->model;
  if (isfinite(r->nrmse_vector))
    PM_CALL(pm_json_number(j, "nrmse_displacement", r->nrmse_vector));
  PM_CALL(pm_json_begin_object(j, "nrmse"));
  for (int c = 0; c < 3; c++) {
    char key[8] = {'u', '_', "xyz"[c], 0};
    if (isfinite(r->nrmse[c])) PM_CALL(pm_json_number(j, key, r->nrmse[c]));
  }
  PM_CALL(pm_json_end_object(j));
  PM_CALL(pm_json_begin_object(j, "reactions"));
  for (int b = 0; b < m->n_bcs; b++) {
    if (!(m->bcs[b].disp_mask | m->bcs[b].vel_mask)) continue;
    PM_CALL(pm_json_begin_array(j, pm_face_name(m->bcs[b].face)));
    for (int c = 0; c < 3; c++)
      PM_CALL(pm_json_number(j, NULL, r->work->cond.reaction[3 * b + c]));
    PM_CALL(pm_json_end_array(j));
  }
  return pm_json_end_object(j);
}

static pm_err summary_body(pm_json *j, const mpm_run *r) {
  const mpm_model *m = r->model;
  const mpm_state *s = r->state;
  const pm_scene *sc = r->scene;
  PM_CALL(pm_json_run_header(j, sc->path, sc->name, "mpm", sc->n_overrides,
                             sc->overrides));
  PM_CALL(pm_json_string(j, "status", mpm_status_name(r->status)));
  if (r->message[0]) PM_CALL(pm_json_string(j, "message", r->message));
  PM_CALL(pm_json_integer(j, "dimension", m->dim));
  PM_CALL(pm_json_integer(j, "points", m->n));
  PM_CALL(pm_json_integer(j, "particles", m->n));
  PM_CALL(summary_groups(j, m));
  PM_CALL(pm_json_integer(j, "grid_nodes", m->grid.n_nodes));
  PM_CALL(pm_json_number(j, "cell_size", m->grid.h));
  PM_CALL(pm_json_number(j, "mesh_size", sc->mesh_size));
  PM_CALL(pm_json_string(j, "shape", shape_name(m->opt.shape)));
  PM_CALL(pm_json_string(j, "update", update_name(m->opt.update, false)));
  PM_CALL(pm_json_number(j, "flip", m->opt.flip));
  PM_CALL(pm_json_number(j, "dt", s->dt));
  PM_CALL(pm_json_number(j, "dt_stable", s->dt_stable));
  PM_CALL(pm_json_integer(j, "steps", s->step));
  PM_CALL(pm_json_number(j, "time", s->t));
  PM_CALL(pm_json_number(j, "residual", r->work->residual));
  PM_CALL(pm_json_bool(j, "converged", r->status == MPM_STATUS_CONVERGED));
  PM_CALL(pm_json_number(j, "kinetic_energy", r->kinetic));
  PM_CALL(pm_json_number(j, "strain_energy", r->strain));
  if (m->kinds & MPM_KIND_INTERNAL_ENERGY)
    PM_CALL(pm_json_number(j, "internal_energy", r->internal));
  if (m->kinds & MPM_KIND_ITERATES) {
    PM_CALL(pm_json_integer(j, "energy_iterations_max", s->iter_max_total));
    PM_CALL(
        pm_json_integer(j, "energy_iterations_capped", s->iter_capped_total));
  }
  PM_CALL(pm_json_number(j, "initial_energy", r->energy0));
  PM_CALL(pm_json_number(j, "external_work", s->external_work));
  PM_CALL(pm_json_number(j, "dissipated", s->dissipated));
  PM_CALL(summary_stage_energy(j, m, s));
  PM_CALL(pm_json_number(j, "energy_balance_error", r->energy_error));
  PM_CALL(summary_figures(j, r));
  PM_CALL(summary_timing(j, r));
  return summary_errors(j, r);
}

pm_err mpm_report_summary(const mpm_run *r, const char *out_dir) {
  pm_err ret = PM_SUCCESS;
  pm_json *j = NULL;
  char path[4096];
  PM_TRY(pm_path_join(path, sizeof path, out_dir, "summary.json"));
  PM_TRY(pm_json_open(path, &j));
  PM_TRY(pm_json_begin_object(j, NULL));
  PM_TRY(summary_body(j, r));
  PM_TRY(pm_json_end_object(j));
  ret = pm_json_close(j, true);
  j = NULL;
done:
  if (j) pm_json_close(j, false);
  return ret;
}

/* ---- plan --------------------------------------------------------------- */

static void plan_groups(const mpm_model *m, FILE *out) {
  size_t common = mpm_particle_bytes_common();
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    size_t own = mpm_group_bytes_per_particle(g);
    fprintf(out,
            "  group %-8s %ld particles, %s, %zu bytes per particle (%zu "
            "common + %zu:",
            g->name, g->end - g->begin, g->kind->name, common + own, common,
            own);
    for (int k = 0; k < g->n_arrays; k++)
      fprintf(out, " %s", g->layout[k].name);
    fprintf(out, "%s)\n", own ? "" : " none");
  }
}

pm_err mpm_run_plan(mpm_run *r, FILE *out) {
  const mpm_model *m = r->model;
  mpm_state *st = r->state;
  const pm_scene *s = r->scene;
  const mpm_grid *g = &m->grid;
  const mpm_options *o = &m->opt;
  fprintf(out, "scene        %s (%s)\n", s->name, s->path);
  fprintf(out, "method       mpm, %dD%s, %s B-splines, %s, FLIP %g\n", m->dim,
          m->dim == 2 ? " plane strain" : "", shape_name(o->shape),
          update_name(o->update, true), o->flip);
  fprintf(out, "grid         %ld x %ld x %ld nodes, cell %g m\n", g->nn[0],
          g->nn[1], g->nn[2], g->h);
  fprintf(out, "particles    %ld (%d x %d x %d per cell)\n", m->n, o->ppc[0],
          o->ppc[1], m->dim == 3 ? o->ppc[2] : 1);
  plan_groups(m, out);
  fprintf(out, "pipeline\n");
  for (int k = 0; k < m->pipeline.n; k++)
    fprintf(out, "  %2d. %-20s %s\n", k + 1, m->pipeline.stage[k].name,
            m->pipeline.stage[k].detail);
  fprintf(out, "dt           %.4g s (%s); stable estimate %.4g s\n", st->dt,
          o->dt_fixed > 0 ? "time.dt" : "dt_safety x stable, each step",
          st->dt_stable);
  if (o->dt_fixed > st->dt_stable)
    fprintf(out,
            "             warning: time.dt is %.2f x the stable estimate\n",
            o->dt_fixed / st->dt_stable);
  double steps = ceil(o->t_end / st->dt);
  if (o->max_steps > 0 && steps > o->max_steps) steps = (double)o->max_steps;
  fprintf(out, "steps        %.0f to t = %g s%s%s\n", steps, o->t_end,
          o->qs != PM_QS_NONE ? " (at most: stops when converged)" : "",
          o->dt_fixed > 0 ? "" : " (at the first step's dt; the step adapts)");
  fprintf(out,
          "memory       %.1f MiB (model %.1f, state %.1f, workspace %.1f "
          "with %d thread accumulators, output buffers %.1f)\n",
          run_bytes(r) / 1048576.0, mpm_model_bytes(m) / 1048576.0,
          mpm_state_bytes(m, st) / 1048576.0,
          mpm_work_bytes(m, r->work) / 1048576.0, r->work->nodes.threads,
          9 * sizeof(double) * (size_t)m->n / 1048576.0);
  /* Time a few steps (the state is advanced: a plan is not run after). */
  double t0 = pm_wtime();
  int reps = 0;
  while (pm_wtime() - t0 < 0.3 && reps < 200) {
    if (mpm_step(m, st, r->work) != PM_SUCCESS) break;
    reps++;
  }
  if (reps > 0) {
    double per = (pm_wtime() - t0) / reps;
    fprintf(out,
            "estimate     %.3g s per step, %.3g s for %.0f steps on %d "
            "thread%s (%.3g particle-steps/s; setup took %.3g s)\n",
            per, per * steps, steps, pm_omp_threads(),
            pm_omp_threads() == 1 ? "" : "s", m->n / per, r->setup_wall);
  }
  return PM_SUCCESS;
}
