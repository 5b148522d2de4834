/* mpm_backend: sets up an explicit MPM simulation from a scene and runs it
 * for the run driver (pm_run): observer, fields, figures, history, summary
 * and the plan. */
#include "mpm_backend.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gm_inside.h"
#include "gm_shape.h"
#include "mpm_estimate.h"
#include "mpm_implicit.h"
#include "mpm_kind.h"
#include "mpm_par.h"
#include "mpm_pipeline.h"
#include "pm_metrics.h"
#include "pm_omp.h"
#include "pm_par.h"
#include "pm_tensor.h"

/* Doubles per particle of the output buffer: strain energy density, J,
 * density, pressure, internal energy, the stress's von Mises and mean, the
 * displacement (3) and the material; with membranes their normal (3),
 * damage and failed. */
static long scratch_per_particle(const mpm_model *m) {
  return 12 + (m->kinds & MPM_KIND_MEMBRANE ? 5 : 0);
}

static pm_err history_setup(mpm_sim *r);

/* The scene checks: the method's own, then what a run across ranks cannot
 * do yet (mpm_par_check), then for the implicit MPM its own. */
static pm_err check_explicit(const pm_scene *s) {
  PM_CALL(mpm_check_scene(s));
  if (pm_par_active()) PM_CALL(mpm_par_check(s));
  return PM_SUCCESS;
}

static pm_err check_implicit(const pm_scene *s) {
  PM_CALL(check_explicit(s));
  if (pm_par_active()) PM_CALL(mpm_par_check_implicit(s));
  return mpm_implicit_check_scene(s);
}

/* A workspace that holds only the figures of a step (reactions, residual)
 * and the timers: the implicit solver's, and rank 0's view of a run
 * across ranks. */
static pm_err figures_work(const mpm_model *m, mpm_work **out) {
  PM_CALL(PM_ALLOC(*out, 1, "MPM workspace"));
  return PM_ALLOC((*out)->cond.reaction, 3 * m->n_bcs + 1, "reactions");
}

/* Across ranks: this rank's share of the whole model and state, which
 * every rank holds (collective; every rank returns the same error), with
 * the energy accounts of a checkpoint of as many ranks, if given. */
static pm_err ranks_share(mpm_sim *r, const double *accounts) {
  PM_CALL(pm_par_agree(mpm_par_create(r->scene, r->model, r->state, accounts,
                                      &r->local_model, &r->local_state)));
  return pm_par_agree(mpm_work_create(r->local_model, &r->local_work));
}

/* Across ranks, once the run starts: the whole model stays on rank 0 as
 * its view of the run; the other ranks let it go.  Until then every rank
 * holds it, so that a checkpoint is read into it. */
static void release_view(mpm_sim *r) {
  if (pm_par_root() || !r->model) return;
  mpm_state_destroy(r->state);
  mpm_model_destroy(r->model);
  r->state = NULL;
  r->model = NULL;
}

static pm_err ranks_setup(mpm_sim *r) {
  PM_CALL(ranks_share(r, NULL));
  return pm_par_agree(pm_par_root() ? figures_work(r->model, &r->work)
                                    : PM_SUCCESS);
}

/* The simulation of s: explicit (its step's workspace) or implicit (its
 * solver; the workspace holds only the reactions and the timers). */
static pm_err sim_create(const pm_scene *s, bool implicit, mpm_sim **out) {
  pm_err ret = PM_SUCCESS;
  mpm_sim *r = NULL;
  *out = NULL;
  PM_TRY(PM_ALLOC(r, 1, "MPM simulation"));
  r->scene = s;
  double t0 = pm_wtime();
  PM_TRY(pm_par_agree(mpm_model_create(s, &r->model, &r->state)));
  if (implicit && pm_par_active()) {
    /* Each rank's share: the particles of its cells by their reference
     * positions (the grid moves with them: none migrates). */
    PM_TRY(figures_work(r->model, &r->work));
    PM_TRY(pm_par_agree(mpm_par_create(s, r->model, r->state, NULL,
                                       &r->local_model, &r->local_state)));
    PM_TRY(pm_par_agree(
        mpm_implicit_create(s, r->local_model, r->local_state, &r->imp)));
    r->run_min_jacobian = 1;
  } else if (implicit) {
    PM_TRY(figures_work(r->model, &r->work));
    PM_TRY(mpm_implicit_create(s, r->model, r->state, &r->imp));
    r->run_min_jacobian = 1;
  } else if (pm_par_active()) {
    PM_TRY(ranks_setup(r));
  } else {
    PM_TRY(mpm_work_create(r->model, &r->work));
  }
  r->setup_wall = pm_wtime() - t0;
  if (pm_par_root()) { /* the outputs' (rank 0's across ranks) */
    PM_TRY(PM_ALLOC(r->scratch, scratch_per_particle(r->model) * r->model->n,
                    "output buffer"));
    PM_TRY(history_setup(r));
  }
  *out = r;
  r = NULL;
done:
  mpm_sim_destroy(r);
  return ret;
}

pm_err mpm_sim_create(const pm_scene *s, mpm_sim **out) {
  return sim_create(s, false, out);
}

void mpm_sim_destroy(mpm_sim *r) {
  if (!r) return;
  free(r->ckpt_accounts);
  free(r->imp_ranks);
  mpm_work_destroy(r->local_work);
  mpm_state_destroy(r->local_state);
  mpm_model_destroy(r->local_model);
  mpm_implicit_destroy(r->imp);
  mpm_work_destroy(r->work);
  mpm_state_destroy(r->state);
  mpm_model_destroy(r->model);
  for (int b = 0; r->surface && r->model && b < r->scene->n_bodies; b++)
    free(r->surface[b]);
  free(r->surface);
  free(r->scratch);
  free(r);
}

/* Everything the simulation holds: model, state, workspace and buffer
 * (across ranks, rank 0's: its share and the whole run's view). */
static size_t sim_bytes(const mpm_sim *r) {
  size_t bytes =
      mpm_model_bytes(r->model) + mpm_state_bytes(r->model, r->state) +
      mpm_work_bytes(r->model, r->work) +
      scratch_per_particle(r->model) * sizeof(double) * (size_t)r->model->n;
  if (r->local_model) /* (the implicit solver has no step workspace) */
    bytes +=
        mpm_model_bytes(r->local_model) +
        mpm_state_bytes(r->local_model, r->local_state) +
        (r->local_work ? mpm_work_bytes(r->local_model, r->local_work) : 0);
  return bytes;
}

/* ---- run ---------------------------------------------------------------- */

/* The report of the step the state is at (the initial state as step 0). */
static pm_step_report step_report(const mpm_sim *r, bool last) {
  const mpm_state *s = r->state;
  return (pm_step_report){.last = last,
                          .step = s->step,
                          .t = s->t,
                          .residual = r->work->residual,
                          .progress = s->t / r->model->opt.t_end};
}

/* Report a step to the run's observer. */
static pm_err report(mpm_sim *r, bool frame, bool last) {
  pm_step_report rep = step_report(r, last);
  return r->obs ? r->obs->step(r->obs->ctx, &rep, frame) : PM_SUCCESS;
}

/* What the run keeps of a step's figures over all its steps. */
static void note_step(mpm_sim *r, const mpm_state *s, const mpm_work *w,
                      const mpm_step_info *info) {
  r->last = *info;
  if (w->min_jacobian < r->run_min_jacobian) {
    r->run_min_jacobian = w->min_jacobian;
    r->run_min_jacobian_step = s->step;
  }
  if (info->iter_max > r->iter_max_row) r->iter_max_row = info->iter_max;
}

static pm_err observe(void *ctx, const mpm_model *m, const mpm_state *s,
                      const mpm_work *w, const mpm_step_info *info,
                      bool frame) {
  (void)m;
  note_step(ctx, s, w, info);
  return report(ctx, frame, info->last);
}

/* ---- across ranks ---- */

/* Rank 0's view of the last step: the figures every rank shares (the
 * residual, the reactions, the smallest J) and its own timers. */
static void view_figures(mpm_sim *r) {
  const mpm_work *lw = r->local_work;
  mpm_work *w = r->work;
  w->residual = lw->residual;
  w->min_jacobian = lw->min_jacobian;
  w->iter_max = lw->iter_max;
  w->iter_capped = lw->iter_capped;
  if (r->model->n_bcs > 0) /* (a scene without conditions has no array) */
    memcpy(w->cond.reaction, lw->cond.reaction,
           3 * sizeof(double) * (size_t)r->model->n_bcs);
  w->timers = lw->timers;
  mpm_state *v = r->state;
  const mpm_state *ls = r->local_state;
  v->t = ls->t;
  v->step = ls->step;
  v->dt = ls->dt;
  v->dt_stable = ls->dt_stable;
}

/* Every rank's particles into rank 0's view (collective). */
static pm_err gather(mpm_sim *r) {
  PM_CALL(pm_par_agree(
      mpm_par_gather(r->local_model, r->local_state, r->model, r->state)));
  if (r->model) view_figures(r);
  return PM_SUCCESS;
}

static pm_err gather_view(void *r) { return gather(r); }

/* A step of a run across ranks (collective): rank 0 reports it, with the
 * particles gathered where its observer reads them. */
static pm_err share(mpm_sim *r, bool frame, bool last) {
  pm_step_report rep = {0};
  if (r->model) {
    view_figures(r);
    rep = step_report(r, last);
  }
  return pm_observer_share(r->model ? r->obs : NULL, &rep, frame, gather_view,
                           r);
}

static pm_err observe_ranks(void *ctx, const mpm_model *m, const mpm_state *s,
                            const mpm_work *w, const mpm_step_info *info,
                            bool frame) {
  (void)m;
  note_step(ctx, s, w, info);
  return share(ctx, frame, info->last);
}

/* The time loop across ranks: every rank steps its share; rank 0's view
 * is gathered where the run writes, and at the end. */
static pm_err run_ranks(mpm_sim *r, const pm_observer *obs) {
  pm_err e = PM_SUCCESS;
  if (r->resumed) { /* the shares of the state read from the checkpoint */
    mpm_work_destroy(r->local_work);
    mpm_state_destroy(r->local_state);
    mpm_model_destroy(r->local_model);
    r->local_work = NULL;
    r->local_state = NULL;
    r->local_model = NULL;
    PM_CALL(ranks_share(r, r->ckpt_ranks == pm_par_size() ? r->ckpt_accounts
                                                          : NULL));
  }
  release_view(r);
  mpm_model *lm = r->local_model;
  r->obs = obs;
  if (!r->resumed) {
    r->run_min_jacobian = INFINITY;
    r->run_min_jacobian_step = 0;
    if (r->model) { /* the initial state, which rank 0's view holds */
      double kin, strain, internal;
      mpm_energies(r->model, r->state, &kin, &strain, &internal);
      r->energy0 = kin + strain + internal;
      for (long q = 0; q < r->model->n; q++)
        r->run_min_jacobian =
            fmin(r->run_min_jacobian, r->state->vol[q] / r->model->vol0[q]);
    }
    e = share(r, true, false);
  }
  mpm_run_options opt = {.t_end = lm->opt.t_end,
                         .max_steps = lm->opt.max_steps,
                         .frame_every = r->scene->output.every};
  if (!e)
    e = mpm_solve(lm, r->local_state, r->local_work, &opt, observe_ranks, r,
                  &r->last);
  /* The state the run ended in, for the figures (a failure's too). */
  pm_err g = gather(r);
  if (!e) e = g;
  r->obs = NULL;
  mpm_par_counts c;
  mpm_par_get_counts(lm, &c);
  /* A rank's own work: its stages' time less the exchanges (in which it
   * waits for the others). */
  double own = -c.halo_seconds - c.migrate_seconds;
  const pm_timers *t = &r->local_work->timers;
  for (int k = 0; k < t->n; k++) own += t->stage[k].seconds;
  double sums[6] = {c.halo_bytes,
                    c.migrate_bytes,
                    (double)c.migrated,
                    (double)c.grown,
                    own,
                    c.ghost_bytes},
         most[3] = {c.halo_seconds, c.migrate_seconds, own};
  pm_par_sum(sums, 6);
  pm_par_max(most, 3);
  memcpy(r->ranks_counts, sums, 4 * sizeof(double));
  memcpy(r->ranks_counts + 4, most, 2 * sizeof(double));
  r->ranks_counts[6] = most[2];                 /* the busiest rank's */
  r->ranks_counts[7] = sums[4] / pm_par_size(); /* the mean */
  r->ranks_counts[8] = sums[5];
  return e;
}

/* The run's status from the loop's error. */
static void conclude(mpm_sim *r, const mpm_model *m, pm_err e) {
  if (e == PM_ERR_UNSTABLE)
    r->status = PM_STATUS_UNSTABLE;
  else if (e != PM_SUCCESS)
    r->status = PM_STATUS_FAILED;
  else if (m->opt.qs == PM_QS_NONE)
    r->status = PM_STATUS_COMPLETED;
  else
    r->status =
        r->last.converged ? PM_STATUS_CONVERGED : PM_STATUS_NOT_CONVERGED;
}

static pm_err run(void *p, const pm_observer *obs) {
  mpm_sim *r = p;
  if (r->local_model) {
    pm_err e = run_ranks(r, obs);
    conclude(r, r->local_model, e);
    return e;
  }
  mpm_model *m = r->model;
  pm_err e = PM_SUCCESS;
  r->obs = obs;
  if (!r->resumed) { /* a resumed run has these from its checkpoint */
    double kin, strain, internal;
    mpm_energies(m, r->state, &kin, &strain, &internal);
    r->energy0 = kin + strain + internal;
    r->run_min_jacobian = INFINITY;
    r->run_min_jacobian_step = 0;
    for (long q = 0; q < m->n; q++)
      r->run_min_jacobian =
          fmin(r->run_min_jacobian, r->state->vol[q] / m->vol0[q]);
    e = report(r, true, false);
  }
  mpm_run_options opt = {.t_end = m->opt.t_end,
                         .max_steps = m->opt.max_steps,
                         .frame_every = r->scene->output.every};
  if (!e) e = mpm_solve(m, r->state, r->work, &opt, observe, r, &r->last);
  r->obs = NULL;
  conclude(r, m, e);
  return e;
}

/* ---- what the run driver reads ------------------------------------------ */

static void points(void *p, pm_points *pts) {
  const mpm_sim *r = p;
  *pts = (pm_points){.n = r->model->n,
                     .x = r->model->x0,
                     .nodes_per_cell = 1,
                     .n_surface = r->model->n_tris,
                     .surface = r->model->tri};
}

/* u = x - x0 into the buffer's last 3 n. */
static const double *displacement(void *p) {
  mpm_sim *r = p;
  const long n3 = 3 * r->model->n;
  const double *x = r->state->x, *x0 = r->model->x0;
  double *u = r->scratch + 6 * r->model->n;
  PM_OMP(parallel for schedule(static) default(none) shared(n3, x, x0, u))
  for (long i = 0; i < n3; i++) u[i] = x[i] - x0[i];
  return u;
}

/* Per particle into the buffer: strain energy density, J, density,
 * pressure, internal energy (n each, in that order). */
static void particle_fields(mpm_sim *r) {
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

static int fields(void *p, unsigned want, pm_field *f, int max) {
  mpm_sim *r = p;
  const mpm_state *s = r->state;
  const long n = r->model->n;
  const mpm_model *m = r->model;
  int nf = 0;
  if (max < 15) return 0;
  double *sed = r->scratch, *jac = sed + n, *rho = sed + 2 * n,
         *pres = sed + 3 * n, *ener = sed + 4 * n, *mat = sed + 11 * n;
  particle_fields(r);
  /* Each particle's material (the scene's index), to colour by. */
  for (int gi = 0; gi < m->n_groups; gi++)
    for (long p = m->group[gi].begin; p < m->group[gi].end; p++)
      mat[p] = m->group[gi].material;
  f[nf++] = (pm_field){"material", 1, mat};
  if (m->kinds & MPM_KIND_MEMBRANE) {
    double *normal = sed + 12 * n, *damage = sed + 15 * n,
           *failed = sed + 16 * n;
    memset(normal, 0, 5 * sizeof(double) * (size_t)n);
    for (int gi = 0; gi < m->n_groups; gi++)
      if (m->group[gi].kind->surface_fields)
        m->group[gi].kind->surface_fields(m, s, &m->group[gi], normal, damage,
                                          failed);
    f[nf++] = (pm_field){"normal", 3, normal};
    f[nf++] = (pm_field){"damage", 1, damage};
    f[nf++] = (pm_field){"failed", 1, failed};
  }
  /* The particles' current positions are each frame's geometry. */
  f[nf++] = (pm_field){"position", 3, s->x};
  if (want & PM_FIELD_DISPLACEMENT)
    f[nf++] = (pm_field){"displacement", 3, displacement(r)};
  if (want & PM_FIELD_VELOCITY) f[nf++] = (pm_field){"velocity", 3, s->v};
  if (want & PM_FIELD_STRESS) {
    const bool has_pressure = r->model->kinds & MPM_KIND_INTERNAL_ENERGY;
    double *vm = sed + 9 * n, *mean = has_pressure ? NULL : sed + 10 * n;
    pm_stress_invariants(n, s->sigma, vm, mean);
    f[nf++] = (pm_field){"stress", 9, s->sigma};
    f[nf++] = (pm_field){"von_mises", 1, vm};
    if (mean) f[nf++] = (pm_field){"pressure", 1, mean};
  }
  if (want & PM_FIELD_STRAIN_ENERGY_DENSITY)
    f[nf++] = (pm_field){"strain_energy_density", 1, sed};
  if (want & PM_FIELD_JACOBIAN) f[nf++] = (pm_field){"jacobian", 1, jac};
  if (r->model->kinds & MPM_KIND_INTERNAL_ENERGY) {
    f[nf++] = (pm_field){"density", 1, rho};
    f[nf++] = (pm_field){"pressure", 1, pres};
    f[nf++] = (pm_field){"internal_energy", 1, ener};
  }
  return nf;
}

/* Mean strain energy density of the particles that store it, largest von
 * Mises stress and smallest J, with where they are now. */
static void field_figures(mpm_sim *r, pm_figures *f) {
  const mpm_model *m = r->model;
  const mpm_state *s = r->state;
  const double *sed = r->scratch;
  double w = 0, v0 = 0;
  long vm_at = 0, j_at = 0;
  particle_fields(r);
  f->max_von_mises = 0;
  f->end_min_jacobian = INFINITY;
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    const bool elastic = g->kind->flags & MPM_KIND_STRAIN_ENERGY;
    for (long p = g->begin; p < g->end; p++) {
      double vm = pm_t_von_mises(s->sigma + 9 * p);
      if (vm > f->max_von_mises) {
        f->max_von_mises = vm;
        vm_at = p;
      }
      double J = s->vol[p] / m->vol0[p];
      if (J < f->end_min_jacobian) {
        f->end_min_jacobian = J;
        j_at = p;
      }
      if (elastic) {
        w += m->vol0[p] * sed[p];
        v0 += m->vol0[p];
      }
    }
  }
  f->mean_sed = v0 > 0 ? w / v0 : NAN;
  for (int a = 0; a < 3; a++) {
    f->max_von_mises_at[a] = s->x[3 * vm_at + a];
    f->end_min_jacobian_at[a] = s->x[3 * j_at + a];
  }
}

static void figures(void *p, pm_figures *f, bool with_fields) {
  mpm_sim *r = p;
  const mpm_model *m = r->model;
  const mpm_state *s = r->state;
  const pm_timers *t = &r->work->timers;
  f->status = r->status;
  f->dim = m->dim;
  f->points = m->n;
  f->steps = s->step;
  f->time = s->t;
  f->h = m->grid.h;
  f->dt = s->dt;
  f->dt_stable = s->dt_stable / m->opt.dt_safety;
  f->residual = r->work->residual;
  mpm_energies(m, s, &f->kinetic, &f->strain, &f->internal);
  f->interface = 0;
  f->external_work = s->external_work;
  f->dissipated = s->dissipated;
  f->energy0 = r->energy0;
  f->energy_error =
      pm_energy_error(r->energy0, f->kinetic + f->strain + f->internal,
                      s->dissipated, s->external_work);
  f->max_energy_error = NAN; /* reported, not bounded */
  f->min_jacobian = r->run_min_jacobian;
  f->min_jacobian_step = r->run_min_jacobian_step;
  for (int b = 0; b < m->n_bcs && b < PM_FIGURES_MAX_BCS; b++)
    for (int c = 0; c < 3; c++)
      f->reaction[b][c] = r->work->cond.reaction[3 * b + c];
  f->setup_seconds = r->setup_wall;
  f->step_seconds = 0;
  for (int k = 0; k < t->n; k++) f->step_seconds += t->stage[k].seconds;
  f->memory_bytes = sim_bytes(r);
  if (r->imp) { /* no time steps, no energy balance: load steps */
    f->dt = f->dt_stable = 0;
    f->energy_error = NAN;
    f->residual = mpm_implicit_residual(r->imp);
    const pm_load_report *lr = mpm_implicit_report(r->imp);
    f->step_seconds = lr->time_total;
  }
  if (with_fields) field_figures(r, f);
}

/* History columns: the energy iterations (kinds that iterate); each named
 * volume body's centroid displacement; with membranes, the failed points;
 * for each body inside or outside a membrane, the mass of its particles
 * that lies inside the membrane's current surface (does fluid leak
 * through?). */
static void add_hist(mpm_sim *r, const char *fmt, const char *a,
                     const char *b) {
  if (r->n_hist >= PM_HISTORY_MAX) return;
  snprintf(r->hist_store[r->n_hist], sizeof r->hist_store[0], fmt, a, b);
  r->hist_names[r->n_hist] = r->hist_store[r->n_hist];
  r->n_hist++;
}

/* The kind of scene body b's particles. */
static const mpm_kind *body_kind(const mpm_model *m, int b) {
  for (int gi = 0; gi < m->n_groups; gi++)
    if (m->body_begin[b] >= m->group[gi].begin &&
        m->body_end[b] <= m->group[gi].end)
      return m->group[gi].kind;
  return m->group[0].kind;
}

/* Whether some membrane's normals come by isosurface least squares. */
static bool iso_normals_used(const mpm_model *m) {
  for (int b = 0; b < m->n_bodies; b++)
    if (m->body_end[b] > m->body_begin[b] &&
        m->body_normals[b] != PM_NORMALS_CONNECTIVITY)
      return true;
  return false;
}

static pm_err history_setup(mpm_sim *r) {
  const mpm_model *m = r->model;
  const pm_scene *s = r->scene;
  r->n_hist = 0;
  PM_CALL(PM_ALLOC(r->surface, s->n_bodies, "membrane surfaces"));
  if (r->imp) {
    add_hist(r, "newton_iterations%s%s", "", "");
    add_hist(r, "linear_iterations%s%s", "", "");
    add_hist(r, "load_cuts%s%s", "", "");
  }
  if (m->kinds & MPM_KIND_ITERATES) {
    add_hist(r, "energy_iterations%s%s", "", "");
    add_hist(r, "energy_iterations_capped%s%s", "", "");
  }
  for (int b = 0; b < s->n_bodies; b++) {
    const pm_scene_body *body = &s->bodies[b];
    if (!body->name || body->shape == PM_BODY_MEMBRANE ||
        m->body_end[b] == m->body_begin[b])
      continue;
    for (int c = 0; c < m->dim; c++)
      add_hist(r, "%s_u%s", body->name, (const char[]){"xyz"[c], 0});
    if (body_kind(m, b)->flags & MPM_KIND_INTERNAL_ENERGY)
      add_hist(r, "%s_pressure%s", body->name, "");
  }
  if (m->kinds & MPM_KIND_MEMBRANE) add_hist(r, "failed_points%s%s", "", "");
  if (iso_normals_used(m)) {
    add_hist(r, "normals_max_condition%s%s", "", "");
    add_hist(r, "normals_degenerate%s%s", "", "");
    add_hist(r, "normals_merged_cells%s%s", "", "");
  }
  for (int b = 0; b < s->n_bodies; b++) {
    const pm_scene_body *body = &s->bodies[b];
    if ((body->shape == PM_BODY_INSIDE || body->shape == PM_BODY_OUTSIDE) &&
        m->body_end[b] > m->body_begin[b]) {
      const int mb = body->surface_body;
      add_hist(r, "mass_inside_%s_%s", s->bodies[mb].name,
               body->name ? body->name : s->materials[body->material].name);
      if (!r->surface[mb] && m->dim == 3)
        PM_CALL(mpm_triangles_local(m, m->body_tri_begin[mb],
                                    m->body_tri_end[mb], m->body_begin[mb],
                                    &r->surface[mb]));
    }
  }
  return PM_SUCCESS;
}

static int history_names(void *p, const char **names, int max) {
  mpm_sim *r = p;
  int n = r->n_hist < max ? r->n_hist : max;
  for (int k = 0; k < n; k++) names[k] = r->hist_names[k];
  return n;
}

/* In 2D: inside the region membrane body mb's curve encloses now. */
static double mass_inside_curve(const mpm_sim *r, int b, int mb) {
  const mpm_model *m = r->model;
  const double *x = r->state->x;
  gm_shape *in = NULL;
  if (gm_shape_from_curve(m->body_end[mb] - m->body_begin[mb],
                          x + 3 * m->body_begin[mb],
                          m->body_links[mb] == MPM_LINKS_LOOP, m->box_min,
                          m->box_max, false, &in) != PM_SUCCESS)
    return NAN;
  double sum = 0;
  for (long q = m->body_begin[b]; q < m->body_end[b]; q++)
    if (gm_shape_contains(in, x + 3 * q)) sum += m->mass[q];
  gm_shape_destroy(in);
  return sum;
}

/* The mass of body b's particles inside membrane body mb's current
 * surface (NAN when it cannot be built).  The inside test is built anew
 * for each history row: the surface moves. */
static double mass_inside(const mpm_sim *r, int b, int mb) {
  const mpm_model *m = r->model;
  const double *x = r->state->x;
  if (m->dim == 2) return mass_inside_curve(r, b, mb);
  const gm_trisurf sf = {.n_points = m->body_end[mb] - m->body_begin[mb],
                         .x = (double *)(x + 3 * m->body_begin[mb]),
                         .n_tris = m->body_tri_end[mb] - m->body_tri_begin[mb],
                         .tri = r->surface[mb]};
  gm_inside *in = NULL;
  if (gm_inside_create(&sf, &in) != PM_SUCCESS) return NAN;
  double sum = 0;
  const long begin = m->body_begin[b], end = m->body_end[b];
  const double *mp = m->mass;
  PM_OMP(parallel for schedule(static) default(none)
         shared(in, x, mp, begin, end) reduction(+ : sum))
  for (long q = begin; q < end; q++)
    if (gm_inside_contains(in, x + 3 * q)) sum += mp[q];
  gm_inside_destroy(in);
  return sum;
}

/* The mean pressure of body b's particles, weighted by their volumes. */
static double body_pressure(const mpm_sim *r, int b) {
  const mpm_model *m = r->model;
  const mpm_state *st = r->state;
  double *sed = r->scratch, *p = sed + m->n, *e = p + m->n, pv = 0, v = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    if (m->body_begin[b] < g->begin || m->body_end[b] > g->end) continue;
    g->kind->fields(m, st, g, sed, p, e);
  }
  for (long q = m->body_begin[b]; q < m->body_end[b]; q++) {
    pv += p[q] * st->vol[q];
    v += st->vol[q];
  }
  return v > 0 ? pv / v : 0;
}

static void history_values(void *p, double *v) {
  mpm_sim *r = p;
  const mpm_model *m = r->model;
  const pm_scene *s = r->scene;
  const mpm_state *st = r->state;
  int k = 0;
  if (r->imp) {
    v[k++] = r->imp_newton;
    v[k++] = r->imp_linear;
    v[k++] = mpm_implicit_report(r->imp)->cuts;
  }
  if (m->kinds & MPM_KIND_ITERATES) {
    v[k++] = r->iter_max_row;
    v[k++] = (double)(st->iter_capped_total - r->iter_capped_prev);
    r->iter_capped_prev = st->iter_capped_total;
    r->iter_max_row = 0;
  }
  for (int b = 0; b < s->n_bodies && k < r->n_hist; b++) {
    const pm_scene_body *body = &s->bodies[b];
    if (!body->name || body->shape == PM_BODY_MEMBRANE ||
        m->body_end[b] == m->body_begin[b])
      continue;
    double u[3] = {0, 0, 0}, mt = 0;
    for (long q = m->body_begin[b]; q < m->body_end[b]; q++) {
      for (int c = 0; c < 3; c++)
        u[c] += m->mass[q] * (st->x[3 * q + c] - m->x0[3 * q + c]);
      mt += m->mass[q];
    }
    for (int c = 0; c < m->dim; c++) v[k++] = u[c] / mt;
    if (body_kind(m, b)->flags & MPM_KIND_INTERNAL_ENERGY)
      v[k++] = body_pressure(r, b);
  }
  if (m->kinds & MPM_KIND_MEMBRANE) {
    double *normal = r->scratch + 12 * m->n, *damage = normal + 3 * m->n,
           *failed = damage + m->n, nf = 0;
    memset(failed, 0, sizeof(double) * (size_t)m->n);
    for (int gi = 0; gi < m->n_groups; gi++)
      if (m->group[gi].kind->surface_fields)
        m->group[gi].kind->surface_fields(m, st, &m->group[gi], normal, damage,
                                          failed);
    for (long q = 0; q < m->n; q++) nf += failed[q];
    v[k++] = nf;
  }
  if (iso_normals_used(m)) {
    v[k++] = st->iso.max_condition;
    v[k++] = st->iso.degenerate;
    v[k++] = st->iso.cells[2] + st->iso.cells[3];
  }
  for (int b = 0; b < s->n_bodies && k < r->n_hist; b++) {
    const pm_scene_body *body = &s->bodies[b];
    if ((body->shape == PM_BODY_INSIDE || body->shape == PM_BODY_OUTSIDE) &&
        m->body_end[b] > m->body_begin[b])
      v[k++] = mass_inside(r, b, body->surface_body);
  }
}

static const char *basis_name(mpm_basis b) {
  return b == MPM_BASIS_QUADRATIC ? "quadratic" : "linear";
}

/* "usf", "usl", "musl"; upper case with upper. */
static const char *update_name(mpm_update u, bool upper) {
  static const char *const lower_names[] = {"usf", "usl", "musl"};
  static const char *const upper_names[] = {"USF", "USL", "MUSL"};
  return (upper ? upper_names : lower_names)[u];
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
  for (int k = 0; k < d->size; k++)
    PM_CALL(pm_json_integer(j, NULL, d->count[k]));
  PM_CALL(pm_json_end_array(j));
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

static pm_err summary(void *p, pm_json *j) {
  const mpm_sim *r = p;
  const mpm_model *m = r->model;
  const mpm_state *s = r->state;
  PM_CALL(pm_json_integer(j, "particles", m->n));
  PM_CALL(summary_groups(j, m));
  PM_CALL(pm_json_integer(j, "grid_nodes", m->grid.n_nodes));
  PM_CALL(pm_json_number(j, "cell_size", m->grid.h));
  PM_CALL(pm_json_string(j, "shape", basis_name(m->opt.shape)));
  PM_CALL(pm_json_string(j, "update", update_name(m->opt.update, false)));
  PM_CALL(pm_json_number(j, "flip", m->opt.flip));
  if (m->kinds & MPM_KIND_ITERATES) {
    PM_CALL(pm_json_integer(j, "energy_iterations_max", s->iter_max_total));
    PM_CALL(
        pm_json_integer(j, "energy_iterations_capped", s->iter_capped_total));
  }
  if (r->local_model) PM_CALL(summary_ranks(j, r));
  return summary_stage_energy(j, m, s);
}

static const pm_timers *timers(void *p) {
  return &((const mpm_sim *)p)->work->timers;
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

/* Each body's particles: membranes with their triangles, thickness and
 * area; bodies seeded at their own density; moving bodies. */
static void plan_bodies(const mpm_sim *r, FILE *out) {
  const mpm_model *m = r->model;
  const pm_scene *s = r->scene;
  for (int b = 0; b < s->n_bodies; b++) {
    const pm_scene_body *body = &s->bodies[b];
    long n = m->body_end[b] - m->body_begin[b];
    fprintf(out, "  body %d%s%s: %ld particles", b, body->name ? " " : "",
            body->name ? body->name : "", n);
    if (body->shape == PM_BODY_MEMBRANE) {
      long nt = m->body_tri_end[b] - m->body_tri_begin[b];
      double area = 0;
      for (long q = m->body_begin[b]; q < m->body_end[b]; q++)
        area += m->vol0[q] / body->membrane.thickness;
      const int links = m->body_links[b];
      if (links == MPM_LINKS_TRIANGLES)
        fprintf(out, ", membrane of %ld triangles", nt);
      else if (links == MPM_LINKS_NONE)
        fprintf(out, ", membrane of unconnected points");
      else
        fprintf(out, ", membrane along a%s curve",
                links == MPM_LINKS_LOOP ? " closed" : "n open");
      fprintf(out, ", thickness %g m, %s %.6g m%s, normals: %s",
              body->membrane.thickness, m->dim == 3 ? "area" : "length", area,
              m->dim == 3 ? "^2" : " (per unit depth)",
              pm_key_name_of(pm_normals_names, m->body_normals[b]));
    } else if (body->shape == PM_BODY_IMAGE) {
      fprintf(out,
              ", voxels of %s with intensity in [%g, %g], %ld^%d per voxel",
              body->image.file, body->image.label[0], body->image.label[1],
              body->image.per_voxel, m->dim);
    } else if (body->n_ppc) {
      fprintf(out, ", %d x %d x %d per cell", (int)body->ppc[0],
              (int)body->ppc[body->n_ppc == 1 ? 0 : 1],
              m->dim == 3 ? (int)body->ppc[body->n_ppc == 1 ? 0 : 2] : 1);
    }
    if (body->shape == PM_BODY_INSIDE || body->shape == PM_BODY_OUTSIDE)
      fprintf(out, ", %s membrane %s",
              body->shape == PM_BODY_INSIDE ? "inside" : "outside",
              s->bodies[body->surface_body].name);
    if (body->moving) fprintf(out, ", moves as prescribed");
    fprintf(out, "\n");
  }
}

/* How the grid was laid when the loader chose it (a scene made for FPM). */
static void plan_layout(const mpm_model *m, const pm_scene *s, FILE *out) {
  const mpm_layout *l = &m->layout;
  if (!l->mapped) return;
  fprintf(out,
          "             chosen for this scene: %s; room beyond "
          "its faces for the body to deform into (cells below/above):",
          l->h == s->mesh_size
              ? "the cell discretization.mesh_size"
              : "the largest cell up to discretization.mesh_size that "
                "divides domain.box");
  for (int c = 0; c < m->dim; c++)
    fprintf(out, " %c %ld/%ld", "xyz"[c], l -> room[c][0], l -> room[c][1]);
  fprintf(out, "\n");
}

/* The plan's lines from the scene to the number of steps; the steps. */
static double plan_head(const mpm_sim *r, FILE *out) {
  const mpm_model *m = r->model;
  const mpm_state *st = r->state;
  const pm_scene *s = r->scene;
  const mpm_grid *g = &m->grid;
  const mpm_options *o = &m->opt;
  fprintf(out, "scene        %s (%s)\n", s->name, s->path);
  fprintf(out, "method       mpm, %dD%s, %s B-splines, %s, FLIP %g\n", m->dim,
          m->dim == 2 ? " plane strain" : "", basis_name(o->shape),
          update_name(o->update, true), o->flip);
  fprintf(out, "grid         %ld x %ld x %ld nodes, cell %g m\n", g->nn[0],
          g->nn[1], g->nn[2], g->h);
  plan_layout(m, r->scene, out);
  fprintf(out, "particles    %ld (%d x %d x %d per cell)\n", m->n, o->ppc[0],
          o->ppc[1], m->dim == 3 ? o->ppc[2] : 1);
  plan_groups(m, out);
  plan_bodies(r, out);
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
  return steps;
}

static void plan_estimate(double per, double steps, long n, double setup,
                          FILE *out) {
  fprintf(out,
          "estimate     %.3g s per step, %.3g s for %.0f steps on %d "
          "thread%s%s (%.3g particle-steps/s; setup took %.3g s)\n",
          per, per * steps, steps, pm_omp_threads(),
          pm_omp_threads() == 1 ? "" : "s", pm_par_active() ? " per rank" : "",
          n / per, setup);
}

/* The plan across ranks (collective): rank 0's view prints the scene's
 * lines, every rank its share, and a few steps of the shares are timed. */
static pm_err plan_ranks(mpm_sim *r, FILE *out) {
  release_view(r);
  double steps = r->model ? plan_head(r, out) : 0;
  mpm_par_plan(r->local_model, r->local_work, r->model ? out : NULL);
  double t0 = pm_wtime();
  int reps = 0, more = 1;
  for (;;) {
    more = pm_wtime() - t0 < 0.3 && reps < 200;
    pm_par_bcast(&more, sizeof more);
    if (!more) break;
    pm_err e = mpm_step(r->local_model, r->local_state, r->local_work);
    if (!e) e = mpm_xc_migrate(r->local_model, r->local_state, r->local_work);
    if (e) break; /* agreed by every rank */
    reps++;
  }
  if (r->model && reps > 0)
    plan_estimate((pm_wtime() - t0) / reps, steps, r->model->n, r->setup_wall,
                  out);
  return PM_SUCCESS;
}

/* plan --ranks N on one process: how N ranks would share the run. */
static pm_err plan_decomposition(const mpm_sim *r, FILE *out) {
  if (pm_par_plan_ranks() <= 1) return PM_SUCCESS;
  mpm_decomp d;
  PM_CALL(mpm_decomp_create(r->scene, r->model, pm_par_plan_ranks(), &d));
  mpm_decomp_print(&d, r->model, out);
  mpm_decomp_predict(&d, r->model, out);
  mpm_decomp_destroy(&d);
  return PM_SUCCESS;
}

static pm_err plan(void *p, FILE *out) {
  mpm_sim *r = p;
  if (r->local_model) return plan_ranks(r, out);
  const mpm_model *m = r->model;
  mpm_state *st = r->state;
  const double steps = plan_head(r, out);
  fprintf(out,
          "memory       %.1f MiB (model %.1f, state %.1f, workspace %.1f "
          "with %d thread accumulators, output buffers %.1f)\n",
          sim_bytes(r) / 1048576.0, mpm_model_bytes(m) / 1048576.0,
          mpm_state_bytes(m, st) / 1048576.0,
          mpm_work_bytes(m, r->work) / 1048576.0, r->work->nodes.threads,
          9 * sizeof(double) * (size_t)m->n / 1048576.0);
  PM_CALL(plan_decomposition(r, out));
  /* Time a few steps (the state is advanced: a plan is not run after). */
  double t0 = pm_wtime();
  int reps = 0;
  while (pm_wtime() - t0 < 0.3 && reps < 200) {
    if (mpm_step(m, st, r->work) != PM_SUCCESS) break;
    reps++;
  }
  if (reps > 0)
    plan_estimate((pm_wtime() - t0) / reps, steps, m->n, r->setup_wall, out);
  return PM_SUCCESS;
}

static pm_err create(const pm_scene *s, void **out) {
  mpm_sim *r = NULL;
  PM_CALL(mpm_sim_create(s, &r));
  *out = r;
  return PM_SUCCESS;
}

static void destroy(void *p) { mpm_sim_destroy(p); }

/* The ranks a run had and their energy accounts (one process: its own),
 * so that a run resumed on as many ranks goes on as it would have. */
static pm_err ranks_checkpoint(mpm_sim *r, pm_ckpt *ck) {
  const int n = MPM_PAR_ACCOUNTS;
  long ranks = pm_par_size();
  PM_CALL(pm_ckpt_long(ck, "run.ranks", &ranks));
  PM_CHECK(ranks >= 1 && ranks <= 1000000, PM_ERR_IO,
           "%s: run.ranks: expected a count of ranks, got %ld",
           pm_ckpt_path(ck), ranks);
  if (pm_ckpt_reading(ck)) {
    free(r->ckpt_accounts);
    r->ckpt_accounts = NULL;
    PM_CALL(PM_ALLOC(r->ckpt_accounts, n * ranks, "energy accounts"));
    r->ckpt_ranks = (int)ranks;
    return pm_ckpt_doubles(ck, "run.ranks.accounts", n * ranks,
                           r->ckpt_accounts);
  }
  double own[MPM_PAR_ACCOUNTS];
  const double *rows = own;
  if (r->local_model) {
    rows = mpm_par_accounts(r->local_model);
  } else {
    memcpy(own, r->state->energy, sizeof r->state->energy);
    own[n - 2] = r->state->external_work;
    own[n - 1] = r->state->dissipated;
  }
  return pm_ckpt_doubles(ck, "run.ranks.accounts", n * ranks, (double *)rows);
}

/* The state, and what the run reports over all its steps. */
static pm_err checkpoint(void *p, pm_ckpt *ck) {
  mpm_sim *r = p;
  long iter_max_row = r->iter_max_row;
  PM_CALL(mpm_state_checkpoint(r->model, r->state, ck));
  PM_CALL(pm_ckpt_double(ck, "run.energy0", &r->energy0));
  PM_CALL(pm_ckpt_double(ck, "run.min_jacobian", &r->run_min_jacobian));
  PM_CALL(pm_ckpt_long(ck, "run.min_jacobian_step", &r->run_min_jacobian_step));
  PM_CALL(pm_ckpt_long(ck, "run.iter_max_row", &iter_max_row));
  r->iter_max_row = (int)iter_max_row;
  PM_CALL(pm_ckpt_long(ck, "run.iter_capped_prev", &r->iter_capped_prev));
  PM_CALL(ranks_checkpoint(r, ck));
  if (pm_ckpt_reading(ck)) {
    r->resumed = true;
    r->last.step = r->state->step;
    r->last.t = r->state->t;
    r->last.dt = r->state->dt;
  }
  return PM_SUCCESS;
}

const pm_backend mpm_backend = {
    .method = "mpm",
    .description = "explicit Material Point Method",
    .section = &mpm_section,
    .dt_safety = 0.5,
    .ranks = true,
    .check = check_explicit,
    .create = create,
    .estimate_bytes = mpm_estimate_bytes,
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

/* ---- method mpm-implicit ------------------------------------------------ */

static pm_err implicit_create(const pm_scene *s, void **out) {
  mpm_sim *r = NULL;
  PM_CALL(sim_create(s, true, &r));
  *out = r;
  return PM_SUCCESS;
}

/* Across ranks, what rank 0's observer reads of a converged load step:
 * every rank's particles and load stepping's states (collective). */
static pm_err implicit_gather(void *ctx) {
  mpm_sim *r = ctx;
  PM_CALL(pm_par_agree(
      mpm_par_gather(r->local_model, r->local_state, r->model, r->state)));
  return mpm_implicit_gather(r->imp, r->model);
}

/* Each converged load step is a step of the run: t = lambda t_load. */
static pm_err implicit_observe(void *ctx, const mpm_implicit_step *step) {
  mpm_sim *r = ctx;
  const mpm_model *m = r->local_model ? r->local_model : r->model;
  mpm_state *st = r->local_model ? r->local_state : r->state;
  st->step = step->step;
  st->t = step->lambda * m->opt.t_load;
  r->imp_newton = step->newton;
  r->imp_linear = step->linear;
  memcpy(r->work->cond.reaction, mpm_implicit_reactions(r->imp),
         3 * sizeof(double) * (size_t)m->n_bcs);
  r->work->residual = step->residual;
  if (step->min_jacobian < r->run_min_jacobian) {
    r->run_min_jacobian = step->min_jacobian;
    r->run_min_jacobian_step = step->step;
  }
  const bool last = step->lambda >= 1;
  const long every = r->scene->output.every;
  pm_step_report rep = {.last = last,
                        .step = st->step,
                        .t = st->t,
                        .residual = step->residual,
                        .progress = step->lambda};
  const bool frame = last || (every > 0 && st->step % every == 0);
  if (r->local_model)
    return pm_observer_share(pm_par_root() ? r->obs : NULL, &rep, frame,
                             implicit_gather, r);
  return r->obs ? r->obs->step(r->obs->ctx, &rep, frame) : PM_SUCCESS;
}

static pm_err implicit_run(void *p, const pm_observer *obs) {
  mpm_sim *r = p;
  pm_err e = PM_SUCCESS;
  r->obs = obs;
  if (r->local_model) release_view(r);
  if (!r->resumed) {
    r->energy0 = 0;
    r->run_min_jacobian_step = 0;
    /* the initial state: rank 0's view holds it across ranks */
    if (pm_par_root()) e = report(r, true, false);
    if (r->local_model) e = pm_par_agree(e);
  }
  if (!e) e = mpm_implicit_run(r->imp, implicit_observe, r);
  /* Across ranks, the state the run ended in, for the figures (a
   * failure's too), and each rank's share of the unknowns. */
  if (r->local_model) {
    const int size = pm_par_size(), me = pm_par_rank();
    pm_err a = PM_SUCCESS;
    if (!r->imp_ranks) a = PM_ALLOC(r->imp_ranks, 3 * size, "ranks' unknowns");
    if (!(a = pm_par_agree(a))) {
      memset(r->imp_ranks, 0, 3 * (size_t)size * sizeof(long));
      r->imp_ranks[3 * me] = r->local_model->n;
      mpm_implicit_held(r->imp, &r->imp_ranks[3 * me + 1],
                        &r->imp_ranks[3 * me + 2]);
      pm_par_sum_long(r->imp_ranks, 3 * size);
    }
    if (!e) e = a;
    pm_err g = pm_par_agree(
        mpm_par_gather(r->local_model, r->local_state, r->model, r->state));
    if (!e) e = g;
  }
  r->obs = NULL;
  /* the solver's time, as stages */
  const pm_load_report *lr = mpm_implicit_report(r->imp);
  pm_timers *t = &r->work->timers;
  pm_timers_init(t);
  t->stage[pm_timers_add(t, "residual")].seconds = lr->time_residual;
  t->stage[pm_timers_add(t, "tangent")].seconds = lr->time_assembly;
  t->stage[pm_timers_add(t, "linear solve")].seconds = lr->time_linear;
  t->stage[pm_timers_add(t, "other (line search, vectors)")].seconds =
      fmax(0, lr->time_total - lr->time_residual - lr->time_assembly -
                  lr->time_linear);
  r->status = pm_static_status(e);
  return e;
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

static pm_err implicit_summary(void *p, pm_json *j) {
  const mpm_sim *r = p;
  const mpm_model *m = r->model;
  const pm_load_report *lr = mpm_implicit_report(r->imp);
  const mpm_settings *ms = mpm_scene_settings(r->scene);
  long unknowns, entries;
  mpm_implicit_size(r->imp, &unknowns, &entries);
  PM_CALL(pm_json_integer(j, "particles", m->n));
  PM_CALL(summary_groups(j, m));
  PM_CALL(pm_json_integer(j, "grid_nodes", m->grid.n_nodes));
  PM_CALL(pm_json_number(j, "cell_size", m->grid.h));
  PM_CALL(pm_json_string(j, "shape", basis_name(m->opt.shape)));
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

static pm_err implicit_plan(void *p, FILE *out) {
  mpm_sim *r = p;
  const mpm_model *m = r->model;
  const pm_scene *s = r->scene;
  const mpm_grid *g = &m->grid;
  fprintf(out, "scene        %s (%s)\n", s->name, s->path);
  fprintf(out, "method       mpm-implicit, %dD%s, %s B-splines, quasi-static\n",
          m->dim, m->dim == 2 ? " plane strain" : "", basis_name(m->opt.shape));
  fprintf(out, "grid         %ld x %ld x %ld nodes, cell %g m\n", g->nn[0],
          g->nn[1], g->nn[2], g->h);
  plan_layout(m, r->scene, out);
  fprintf(out, "particles    %ld\n", m->n);
  plan_groups(m, out);
  plan_bodies(r, out);
  mpm_implicit_plan(r->imp, out);
  if (r->local_model) /* across ranks: the decomposition, each rank's share */
    mpm_par_plan(r->local_model, NULL, out);
  else
    PM_CALL(plan_decomposition(r, out));
  fprintf(out,
          "memory       %.1f MiB (model %.1f, state %.1f, output %.1f; "
          "PETSc's matrix and solver besides)\n",
          sim_bytes(r) / 1048576.0, mpm_model_bytes(m) / 1048576.0,
          mpm_state_bytes(m, r->state) / 1048576.0,
          scratch_per_particle(m) * sizeof(double) * (size_t)m->n / 1048576.0);
  return PM_SUCCESS;
}

static pm_err implicit_checkpoint(void *p, pm_ckpt *ck) {
  mpm_sim *r = p;
  PM_CALL(mpm_state_checkpoint(r->model, r->state, ck));
  /* A resumed run across ranks: each rank's particles take the state read
   * (they are those of its cells by their reference positions, as at the
   * start). */
  if (r->local_model && pm_ckpt_reading(ck))
    mpm_par_take_state(r->model, r->state, r->local_model, r->local_state);
  PM_CALL(mpm_implicit_checkpoint(r->imp, r->model, ck));
  PM_CALL(pm_ckpt_double(ck, "run.min_jacobian", &r->run_min_jacobian));
  PM_CALL(pm_ckpt_long(ck, "run.min_jacobian_step", &r->run_min_jacobian_step));
  if (pm_ckpt_reading(ck)) {
    r->resumed = true;
    memcpy(r->work->cond.reaction, mpm_implicit_reactions(r->imp),
           3 * sizeof(double) * (size_t)r->model->n_bcs);
  }
  return PM_SUCCESS;
}

const pm_backend mpm_implicit_backend = {
    .method = "mpm-implicit",
    .description = "implicit quasi-static Material Point Method (Newton on "
                   "the grid, PETSc)",
    .section = NULL,
    .dt_safety = 0.5,
    .check = check_implicit,
    .ranks = true,
    .create = implicit_create,
    .estimate_bytes = mpm_estimate_bytes,
    .destroy = destroy,
    .plan = implicit_plan,
    .run = implicit_run,
    .points = points,
    .fields = fields,
    .displacement = displacement,
    .figures = figures,
    .history_names = history_names,
    .history_values = history_values,
    .summary = implicit_summary,
    .timers = timers,
    .checkpoint = implicit_checkpoint,
};
