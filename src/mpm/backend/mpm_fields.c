/* mpm_fields: what the run driver reads of an MPM simulation: its points,
 * displacement, fields and figures. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_backend_impl.h"
#include "pm_metrics.h"
#include "pm_omp.h"
#include "pm_par.h"
#include "pm_tensor.h"

void mpm_sim_points(void *p, pm_points *pts) {
  const mpm_sim *r = p;
  if (!r->model) { /* across ranks, no whole model: points alone */
    *pts = (pm_points){.n = r->sums.n, .x = r->mesh_x0, .nodes_per_cell = 1};
    return;
  }
  *pts = (pm_points){.n = r->model->n,
                     .x = r->model->x0,
                     .nodes_per_cell = 1,
                     .n_surface = r->model->n_tris,
                     .surface = r->model->tri};
}

/* u = x - x0 of m's particles into u (3 n). */
static const double *displacement(const mpm_model *m, const mpm_state *s,
                                  double *u) {
  const long n3 = 3 * m->n;
  const double *x = s->x, *x0 = m->x0;
  PM_OMP(parallel for schedule(static) default(none) shared(n3, x, x0, u))
  for (long i = 0; i < n3; i++) u[i] = x[i] - x0[i];
  return u;
}

const double *mpm_sim_displacement(void *p) {
  mpm_sim *r = p;
  return displacement(r->model, r->state, r->scratch + 6 * r->model->n);
}

/* Per particle of m into the buffer: strain energy density, J, density,
 * pressure, internal energy (n each, in that order). */
static void model_particle_fields(const mpm_model *m, const mpm_state *s,
                                  double *scratch) {
  const long n = m->n;
  double *sed = scratch, *jac = sed + n, *rho = sed + 2 * n,
         *pres = sed + 3 * n, *ener = sed + 4 * n;
  for (long p = 0; p < n; p++) {
    jac[p] = s->vol[p] / m->vol0[p];
    rho[p] = m->mass[p] / s->vol[p];
  }
  for (int gi = 0; gi < m->n_groups; gi++)
    m->group[gi].kind->fields(m, s, &m->group[gi], sed, pres, ener);
}

long mpm_sim_fields_per_particle(const mpm_model *m, unsigned want) {
  const bool gas = m->kinds & MPM_KIND_INTERNAL_ENERGY;
  long k = 1;
  if (gas || want & (PM_FIELD_STRAIN_ENERGY_DENSITY | PM_FIELD_JACOBIAN))
    k += 5;
  if (m->kinds & MPM_KIND_MEMBRANE) k += 5;
  if (want & PM_FIELD_DISPLACEMENT) k += 3;
  if (want & PM_FIELD_STRESS) k += gas ? 1 : 2;
  return k;
}

/* The fields of m's particles (mpm_sim_fields), computed into scratch
 * (mpm_sim_fields_per_particle doubles a particle, one after another). */
static int model_fields(const mpm_model *m, const mpm_state *s, double *scratch,
                        unsigned want, pm_field *f, int max) {
  const long n = m->n;
  const bool gas = m->kinds & MPM_KIND_INTERNAL_ENERGY;
  int nf = 0;
  if (max < 15) return 0;
  double *next = scratch, *sed = NULL, *jac = NULL, *rho = NULL, *pres = NULL,
         *ener = NULL;
  if (gas || want & (PM_FIELD_STRAIN_ENERGY_DENSITY | PM_FIELD_JACOBIAN)) {
    model_particle_fields(m, s, scratch);
    sed = scratch;
    jac = sed + n;
    rho = sed + 2 * n;
    pres = sed + 3 * n;
    ener = sed + 4 * n;
    next += 5 * n;
  }
  double *mat = next;
  next += n;
  /* Each particle's material (the scene's index), to colour by. */
  for (int gi = 0; gi < m->n_groups; gi++)
    for (long p = m->group[gi].begin; p < m->group[gi].end; p++)
      mat[p] = m->group[gi].material;
  f[nf++] = (pm_field){"material", 1, mat};
  if (m->kinds & MPM_KIND_MEMBRANE) {
    double *normal = next, *damage = next + 3 * n, *failed = next + 4 * n;
    next += 5 * n;
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
  if (want & PM_FIELD_DISPLACEMENT) {
    f[nf++] = (pm_field){"displacement", 3, displacement(m, s, next)};
    next += 3 * n;
  }
  if (want & PM_FIELD_VELOCITY) f[nf++] = (pm_field){"velocity", 3, s->v};
  if (want & PM_FIELD_STRESS) {
    double *vm = next, *mean = gas ? NULL : next + n;
    pm_stress_invariants(n, s->sigma, vm, mean);
    f[nf++] = (pm_field){"stress", 9, s->sigma};
    f[nf++] = (pm_field){"von_mises", 1, vm};
    if (mean) f[nf++] = (pm_field){"pressure", 1, mean};
  }
  if (want & PM_FIELD_STRAIN_ENERGY_DENSITY)
    f[nf++] = (pm_field){"strain_energy_density", 1, sed};
  if (want & PM_FIELD_JACOBIAN) f[nf++] = (pm_field){"jacobian", 1, jac};
  if (gas) {
    f[nf++] = (pm_field){"density", 1, rho};
    f[nf++] = (pm_field){"pressure", 1, pres};
    f[nf++] = (pm_field){"internal_energy", 1, ener};
  }
  return nf;
}

int mpm_sim_fields(void *p, unsigned want, pm_field *f, int max) {
  mpm_sim *r = p;
  return model_fields(r->model, r->state, r->scratch, want, f, max);
}

pm_err mpm_sim_share_scratch(mpm_sim *r, long frame) {
  const mpm_model *m = r->local_model;
  /* The share's buffer grows with the share (migration), as its arrays
   * do: at a frame or a history row, not in a step. */
  if (m->cap <= r->share_scratch_cap) return PM_SUCCESS;
  /* (what a frame takes, and the particle fields of the sums) */
  const long fields = mpm_sim_fields_per_particle(m, r->scene->output.fields),
             per = fields > 5 ? fields : 5;
  double *grown =
      realloc(r->share_scratch, (size_t)(per * m->cap) * sizeof *grown);
  PM_CHECK(grown, PM_ERR_MEMORY,
           "out of memory for the output of %ld particles (frame %ld)", m->cap,
           frame);
  r->share_scratch = grown;
  r->share_scratch_cap = m->cap;
  return PM_SUCCESS;
}

pm_err mpm_sim_piece(void *p, const char *dir, long frame,
                     const pm_step_report *rep, long *n, int *n_fields,
                     pm_field *fields) {
  (void)rep; /* rank 0's alone: the share's state has the step and time */
  mpm_sim *r = p;
  const mpm_model *m = r->local_model;
  const mpm_state *s = r->local_state;
  PM_CALL(mpm_sim_share_scratch(r, frame));
  *n_fields = model_fields(m, s, r->share_scratch, r->scene->output.fields,
                           fields, PM_VIEW_FIELDS);
  *n = m->n;
  return pm_results_write_piece(dir, frame, pm_par_rank(), m->n, m->gid,
                                s->step, s->t, *n_fields, fields);
}

const pm_view_pieces *mpm_sim_pieces(void *p) {
  return pm_view_frame_pieces(&((const mpm_sim *)p)->view);
}

void mpm_sim_field_sums(const mpm_model *m, const mpm_state *s, double *scratch,
                        mpm_sums *out, long at[2]) {
  const double *sed = scratch;
  double w = 0, v0 = 0, vm_most = 0, j_least = INFINITY;
  long vm_at = LONG_MAX, j_at = LONG_MAX, vm_p = 0, j_p = 0;
  model_particle_fields(m, s, scratch);
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    const bool elastic = g->kind->flags & MPM_KIND_STRAIN_ENERGY;
    for (long p = g->begin; p < g->end; p++) {
      /* the first in one process's order among equals */
      const long id = m->gid ? m->gid[p] : p;
      double vm = pm_t_von_mises(s->sigma + 9 * p);
      if (vm > vm_most || (vm == vm_most && id < vm_at)) {
        vm_most = vm;
        vm_at = id;
        vm_p = p;
      }
      double J = s->vol[p] / m->vol0[p];
      if (J < j_least || (J == j_least && id < j_at)) {
        j_least = J;
        j_at = id;
        j_p = p;
      }
      if (elastic) {
        w += m->vol0[p] * sed[p];
        v0 += m->vol0[p];
      }
    }
  }
  out->sed_volume = w;
  out->volume0 = v0;
  out->max_von_mises = vm_most;
  out->min_jacobian = j_least;
  for (int a = 0; a < 3; a++) {
    out->max_von_mises_at[a] = m->n ? s->x[3 * vm_p + a] : 0;
    out->min_jacobian_at[a] = m->n ? s->x[3 * j_p + a] : 0;
  }
  at[0] = vm_at;
  at[1] = j_at;
}

/* Mean strain energy density of the particles that store it, largest von
 * Mises stress and smallest J, with where they are now: of the whole
 * model, or summed over the shares (r->sums). */
static void field_figures(mpm_sim *r, pm_figures *f) {
  mpm_sums own;
  const mpm_sums *u = &r->sums;
  if (r->model) {
    long at[2];
    mpm_sim_field_sums(r->model, r->state, r->scratch, &own, at);
    u = &own;
  }
  f->max_von_mises = u->max_von_mises;
  f->end_min_jacobian = u->min_jacobian;
  f->mean_sed = u->volume0 > 0 ? u->sed_volume / u->volume0 : NAN;
  for (int a = 0; a < 3; a++) {
    f->max_von_mises_at[a] = u->max_von_mises_at[a];
    f->end_min_jacobian_at[a] = u->min_jacobian_at[a];
  }
}

void mpm_sim_figures(void *p, pm_figures *f, bool with_fields) {
  mpm_sim *r = p;
  /* (without the whole model: the share's constants, the run's sums) */
  const mpm_model *m = r->model ? r->model : r->local_model;
  const mpm_state *s = r->state;
  const pm_timers *t = &r->work->timers;
  f->status = r->status;
  f->dim = m->dim;
  f->points = r->model ? m->n : r->sums.n;
  f->steps = s->step;
  f->time = s->t;
  f->h = m->grid.h;
  f->dt = s->dt;
  f->dt_stable = s->dt_stable / m->opt.dt_safety;
  f->residual = r->work->residual;
  if (r->model) {
    mpm_energies(m, s, &f->kinetic, &f->strain, &f->internal);
  } else {
    f->kinetic = r->sums.kinetic;
    f->strain = r->sums.strain;
    f->internal = r->sums.internal;
  }
  /* the implicit F-bar's energy is that of Fbar, not of each F */
  if (r->imp) mpm_implicit_strain_energy(r->imp, &f->strain);
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
  f->memory_bytes = mpm_sim_bytes(r);
  if (r->imp) { /* no time steps: load steps */
    f->dt = f->dt_stable = 0;
    /* The tractions' work is booked, the supports' is not: a balance
     * only where they hold still. */
    if (!mpm_supports_still(m->bcs, m->n_bcs, m->box_min, m->box_max,
                            m->opt.t_load))
      f->energy_error = NAN;
    f->residual = mpm_implicit_residual(r->imp);
    const pm_load_report *lr = mpm_implicit_report(r->imp);
    f->step_seconds = lr->time_total;
  }
  if (with_fields) field_figures(r, f);
}
