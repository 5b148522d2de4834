/* mpm_solid: the solid particle kind: a deformation gradient per particle,
 * F <- (I + dt L) F, and the stress of the material model (neo-Hookean from
 * F, or linear elasticity in the objective Jaumann rate form).  The only
 * file of the MPM that calls the material model. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_state.h"
#include "pm_material.h"
#include "pm_omp.h"

enum { SOLID_F = 0 }; /* state array slots: F, then q and the model's */

typedef struct {
  pm_material mat;
  int q;      /* slot of the artificial viscosity pressure, or -1 */
  int mstate; /* slot of the model's per-particle state, or -1 */
} solid_params;

static pm_err solid_setup(mpm_group *g, const pm_scene_material *sm,
                          const mpm_options *opt) {
  (void)opt;
  solid_params *sp = NULL;
  PM_CALL(PM_ALLOC(sp, 1, "solid constants"));
  sp->mat = sm->mat;
  sp->q = sp->mstate = -1;
  g->params = sp;
  g->viscosity = 0;
  mpm_group_add_array(g, "F", 9);
  if (g->c0 > 0 || g->c1 > 0) {
    sp->q = g->n_arrays;
    mpm_group_add_array(g, "q", 1);
  }
  /* What the model keeps per point (fibre directions): constant, but it
   * travels with the particle. */
  if (sp->mat.state_size > 0) {
    sp->mstate = g->n_arrays;
    mpm_group_add_array(g, "material_state", sp->mat.state_size);
  }
  return PM_SUCCESS;
}

static void solid_seed(const mpm_group *g, mpm_group_state *gs, long k,
                       const pm_scene_body *b, double sigma[9]) {
  (void)sigma;
  const solid_params *sp = g->params;
  pm_t_identity(gs->array[SOLID_F].data + 9 * k);
  if (sp->mstate >= 0)
    sp->mat.model->state_init(&sp->mat, &b->point,
                              gs->array[sp->mstate].data +
                                  (size_t)sp->mat.state_size * k);
}

/* The model's state of the group's particles, and its stride (0: none). */
static const double *model_state(const mpm_group *g, const mpm_state *s,
                                 long *stride) {
  const solid_params *sp = g->params;
  *stride = sp->mat.state_size;
  return sp->mstate >= 0 ? s->group[g->index].array[sp->mstate].data : NULL;
}

static void solid_describe(const mpm_group *g, char *buf, size_t size) {
  const solid_params *sp = g->params;
  if (sp->mat.model->rate)
    snprintf(buf, size, "%s, Jaumann rate form%s", sp->mat.model->name,
             sp->q >= 0 ? ", artificial viscosity (eq. 32)" : "");
  else
    snprintf(buf, size, "%s from F%s", sp->mat.model->name,
             sp->q >= 0 ? ", artificial viscosity (eq. 32)" : "");
}

/* Dilatational wave speed at density rho. */
static inline double p_wave_speed(const pm_material *mat, double rho) {
  return sqrt(mat->wave_modulus / rho);
}

static pm_err solid_stress(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  mpm_state *s = ctx->state;
  mpm_work *w = ctx->work;
  const mpm_group *gr = &m->group[self->group];
  const mpm_grid *g = &m->grid;
  const solid_params *sp = gr->params;
  const pm_material *mat = &sp->mat;
  long mss;
  const double *ms = model_state(gr, s, &mss);
  const double dt = s->dt, h = g->h, c0 = gr->c0, c1 = gr->c1;
  const bool rate = mat->model->rate != NULL;
  const double jmin = m->opt.min_jacobian;
  const long begin = gr->begin, end = gr->end;
  const double *vel = w->nodes.vel_stress, *x = s->x, *mass = m->mass,
               *vol0 = m->vol0;
  double *Fa = s->group[self->group].array[SOLID_F].data, *vol = s->vol,
         *sigma = s->sigma;
  double *qa = sp->q >= 0 ? s->group[self->group].array[sp->q].data : NULL;
  double maxdiv = 0, Jlow = INFINITY;
  PM_OMP(parallel for schedule(static) default(none)
         shared(g, mat, ms, mss, w, dt, h, c0, c1, rate, jmin, begin, end, vel,
                x, mass, vol0, Fa, vol, sigma, qa)
         reduction(max : maxdiv) reduction(min : Jlow))
  for (long p = begin; p < end; p++) {
    long k = p - begin;
    double L[9], D[9], W[9], A[9], Fn[9];
    mpm_velocity_gradient(g, vel, x + 3 * p, L);
    double *F = Fa + 9 * k, *sig = sigma + 9 * p;
    for (int i = 0; i < 9; i++) A[i] = dt * L[i];
    A[0] += 1;
    A[4] += 1;
    A[8] += 1;
    pm_t_mul(A, F, Fn);
    memcpy(F, Fn, sizeof Fn);
    double J = pm_t_det(F);
    if (!(J > jmin) || !isfinite(J)) {
      mpm_fail(w, p,
               J > 0 ? "volume ratio J = %g <= stability.min_jacobian = %g"
                     : "volume ratio J = %g <= 0: inverted (bound %g)",
               J, jmin);
      continue;
    }
    vol[p] = vol0[p] * J;
    Jlow = fmin(Jlow, J);
    mpm_sym_skew(L, D, W);
    double trD = D[0] + D[4] + D[8];
    maxdiv = fmax(maxdiv, fabs(trD));
    if (rate) {
      mat->model->rate(mat, D, W, dt, sig);
      if (qa) sig[0] += qa[k], sig[4] += qa[k], sig[8] += qa[k];
    } else {
      double P[9];
      if (!pm_material_stress(mat, F, ms ? ms + mss * k : NULL, P, NULL,
                              NULL)) {
        mpm_fail(w, p, "stress is not finite (J = %g, |F| = %g)", J,
                 pm_t_norm(F));
        continue;
      }
      /* sigma = P F^T / J */
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
          sig[3 * i + j] = (P[3 * i] * F[3 * j] + P[3 * i + 1] * F[3 * j + 1] +
                            P[3 * i + 2] * F[3 * j + 2]) /
                           J;
    }
    if (qa) {
      double rho = mass[p] / vol[p];
      double q =
          pm_artificial_viscosity(c0, c1, rho, h, p_wave_speed(mat, rho), trD);
      qa[k] = q;
      sig[0] -= q;
      sig[4] -= q;
      sig[8] -= q;
    }
  }
  if (maxdiv > w->max_div) w->max_div = maxdiv;
  if (Jlow < w->min_jacobian) w->min_jacobian = Jlow;
  return mpm_stage_status(ctx, self);
}

static void solid_wave_speeds(const mpm_model *m, const mpm_state *s,
                              const mpm_group *g, double *cp, double *cs) {
  const pm_material *mat = &((const solid_params *)g->params)->mat;
  const long begin = g->begin, end = g->end;
  const double *mass = m->mass, *vol = s->vol;
  /* The particle's own density (a body may set it), which follows its
   * volume. */
  PM_OMP(parallel for schedule(static) default(none)
         shared(mat, begin, end, mass, vol, cp, cs))
  for (long p = begin; p < end; p++) {
    double rho = mass[p] / vol[p];
    cp[p] = p_wave_speed(mat, rho);
    if (cs) cs[p] = sqrt(mat->shear_modulus / rho);
  }
}

static void solid_energies(const mpm_model *m, const mpm_state *s,
                           const mpm_group *g, double *strain,
                           double *internal) {
  (void)internal;
  const pm_material *mat = &((const solid_params *)g->params)->mat;
  const long begin = g->begin, end = g->end;
  long mss;
  const double *ms = model_state(g, s, &mss);
  const double *F = s->group[g->index].array[SOLID_F].data, *vol0 = m->vol0;
  double se = 0; /* from zero, then added (as mpm_fluid.c) */
  PM_OMP(parallel for schedule(static) default(none)
         shared(mat, ms, mss, begin, end, F, vol0) reduction(+ : se))
  for (long p = begin; p < end; p++) {
    const long k = p - begin;
    se +=
        vol0[p] * pm_material_energy(mat, F + 9 * k, ms ? ms + mss * k : NULL);
  }
  *strain += se;
}

static void solid_fields(const mpm_model *m, const mpm_state *s,
                         const mpm_group *g, double *sed, double *pressure,
                         double *energy) {
  (void)m;
  const pm_material *mat = &((const solid_params *)g->params)->mat;
  const long begin = g->begin, end = g->end;
  long mss;
  const double *ms = model_state(g, s, &mss);
  const double *F = s->group[g->index].array[SOLID_F].data, *sigma = s->sigma;
  PM_OMP(parallel for schedule(static) default(none)
         shared(mat, ms, mss, begin, end, F, sigma, sed, pressure, energy))
  for (long p = begin; p < end; p++) {
    const double *sg = sigma + 9 * p;
    const long k = p - begin;
    sed[p] = pm_material_energy(mat, F + 9 * k, ms ? ms + mss * k : NULL);
    pressure[p] = -(sg[0] + sg[4] + sg[8]) / 3.0;
    energy[p] = 0;
  }
}

const mpm_kind mpm_kind_solid = {
    .name = "solid",
    .stage_name = "stress: solid",
    .flags = MPM_KIND_STRAIN_ENERGY,
    .setup = solid_setup,
    .seed = solid_seed,
    .stress = solid_stress,
    .describe = solid_describe,
    .wave_speeds = solid_wave_speeds,
    .energies = solid_energies,
    .fields = solid_fields,
};

bool mpm_solid_access(const mpm_group *g, mpm_state *s, mpm_solid_view *v) {
  if (g->kind != &mpm_kind_solid) return false;
  const solid_params *sp = g->params;
  v->mat = &sp->mat;
  v->F = s->group[g->index].array[SOLID_F].data;
  v->mstate =
      sp->mstate >= 0 ? s->group[g->index].array[sp->mstate].data : NULL;
  v->mstride = sp->mat.state_size;
  return true;
}
