/* mpm_solid: the solid particle kind: a deformation gradient per particle,
 * F <- (I + dt L) F, and the stress of the material model (neo-Hookean from
 * F, or linear elasticity in the objective Jaumann rate form), with F-bar
 * (mpm.fbar) when the scene asks for it.  The only file of the MPM that
 * calls the material model. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mpm_fbar.h"
#include "mpm_kind.h"
#include "mpm_state.h"
#include "mpm_transfer.h"
#include "pm_material.h"
#include "pm_omp.h"
#include "pm_v4.h"

enum { SOLID_F = 0 }; /* state array slots: F, then q and the model's */

typedef struct {
  pm_material mat;
  int q;              /* slot of the artificial viscosity pressure, or -1 */
  int mstate;         /* slot of the model's per-particle state, or -1 */
  int jbar;           /* slot of Jbar - 1 (F-bar), or -1 */
  mpm_fbar_mode fbar; /* what Jbar averages over */
} solid_params;

static pm_err solid_setup(mpm_group *g, const pm_scene_material *sm,
                          const mpm_options *opt) {
  solid_params *sp = NULL;
  PM_CALL(PM_ALLOC(sp, 1, "solid constants"));
  sp->mat = sm->mat;
  sp->q = sp->mstate = sp->jbar = -1;
  sp->fbar = opt->fbar;
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
  /* The last step's averaged volume ratio: what a rate form's volumetric
   * rate is measured from, and what the energies are of (0 at the start,
   * where F = I). */
  if (sp->fbar != MPM_FBAR_NONE) {
    sp->jbar = g->n_arrays;
    mpm_group_add_array(g, "Jbar_minus_1", 1);
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

/* The group's Jbar - 1 (F-bar), or NULL. */
static double *jbar_of(const solid_params *sp, const mpm_group *g,
                       const mpm_state *s) {
  return sp->jbar >= 0 ? s->group[g->index].array[sp->jbar].data : NULL;
}

/* The deformation gradient the stress and the energy are of: F, or with
 * F-bar Fbar (into Fbar) from Jbar - 1 (jbar, NULL without F-bar). */
static inline const double *stress_F(int dim, const double *F,
                                     const double *jbar, double Fbar[9]) {
  if (!jbar) return F;
  double H[9];
  for (int i = 0; i < 9; i++) H[i] = F[i] - (i % 4 == 0);
  mpm_fbar_apply(dim, pm_t_det_minus_one(H), *jbar, F, Fbar);
  return Fbar;
}

static void solid_describe(const mpm_group *g, char *buf, size_t size) {
  const solid_params *sp = g->params;
  const char *fbar = sp->fbar == MPM_FBAR_CELL
                         ? ", F-bar: J averaged over each cell's particles"
                     : sp->fbar == MPM_FBAR_PATCH
                         ? ", F-bar: J averaged over the nodes' patches"
                         : "";
  if (sp->mat.model->rate)
    snprintf(buf, size, "%s, Jaumann rate form%s%s%s", sp->mat.model->name,
             sp->fbar != MPM_FBAR_NONE ? " with the averaged tr D" : "",
             sp->q >= 0 ? ", artificial viscosity (eq. 32)" : "", fbar);
  else
    snprintf(buf, size, "%s from F%s%s%s", sp->mat.model->name,
             sp->fbar != MPM_FBAR_NONE ? "bar" : "",
             sp->q >= 0 ? ", artificial viscosity (eq. 32)" : "", fbar);
}

/* Dilatational wave speed at density rho. */
static inline double p_wave_speed(const pm_material *mat, double rho) {
  return sqrt(mat->wave_modulus / rho);
}

/* Rows 0 and 1 of a 3 x 3 matrix stored from their vectors four wide (the
 * fourth lane lands on the next row's first entry, written after it),
 * row 2 entry by entry. */
static inline void store_rows(double M[9], pm_v4 r0, pm_v4 r1, pm_v4 r2) {
  pm_v4_store(M, r0);
  pm_v4_store(M + 3, r1);
  M[6] = r2[0];
  M[7] = r2[1];
  M[8] = r2[2];
}

/* Cauchy stress sigma = P F^T / J of the model at F (J its determinant);
 * false when P is not finite.  A row of sigma is one vector: lane by lane
 * the scalar sums and quotients. */
static inline bool cauchy(const pm_material *mat, const double F[9],
                          const double *ms, double J, double sig[9]) {
  double P[9];
  if (!pm_material_stress(mat, F, ms, P, NULL, NULL)) return false;
  const pm_v4 c0 = {F[0], F[3], F[6], F[6]}, c1 = {F[1], F[4], F[7], F[7]},
              c2 = {F[2], F[5], F[8], F[8]};
  pm_v4 r[3];
  for (int i = 0; i < 3; i++)
    r[i] = (P[3 * i] * c0 + P[3 * i + 1] * c1 + P[3 * i + 2] * c2) / J;
  store_rows(sig, r[0], r[1], r[2]);
  return true;
}

/* The artificial viscosity pressure of eq. 32 at density rho and volume
 * rate trD into *q, taken off the normal stresses. */
static inline void viscosity(const pm_material *mat, double c0, double c1,
                             double h, double rho, double trD, double *q,
                             double sig[9]) {
  *q = pm_artificial_viscosity(c0, c1, rho, h, p_wave_speed(mat, rho), trD);
  sig[0] -= *q;
  sig[4] -= *q;
  sig[8] -= *q;
}

/* F <- (I + dt L) F, a row of the product as one vector (lane by lane the
 * sums of pm_t_mul). */
static inline void advance_F(double dt, const double L[9], double F[9]) {
  double A[9];
  for (int i = 0; i < 9; i++) A[i] = dt * L[i];
  A[0] += 1;
  A[4] += 1;
  A[8] += 1;
  const pm_v4 f0 = {F[0], F[1], F[2], F[2]}, f1 = {F[3], F[4], F[5], F[5]},
              f2 = {F[6], F[7], F[8], F[8]};
  pm_v4 r[3];
  for (int i = 0; i < 3; i++)
    r[i] = A[3 * i] * f0 + A[3 * i + 1] * f1 + A[3 * i + 2] * f2;
  store_rows(F, r[0], r[1], r[2]);
}

/* A volume ratio J that stops the run: at or below the bound, or not
 * finite (recorded for particle p).  True when J is fine. */
static inline bool jacobian_ok(mpm_work *w, long p, double J, double jmin) {
  if (J > jmin && isfinite(J)) return true;
  mpm_fail(w, p,
           J > 0 ? "volume ratio J = %g <= stability.min_jacobian = %g"
                 : "volume ratio J = %g <= 0: inverted (bound %g)",
           J, jmin);
  return false;
}

/* What the stress stage reads and writes of a group, bound once for its
 * passes; each thread takes its own copy (firstprivate), so that the
 * fields stay in registers beside the stores to the arrays. */
typedef struct {
  const mpm_grid *g;
  const pm_material *mat;
  const double *ms; /* the model's state, or NULL */
  long mss;         /* its stride */
  double dt, h, c0, c1, jmin;
  bool rate;
  int dim;
  long begin, end;
  const double *vel, *x, *mass, *vol0;
  double *F, *vol, *sigma;
  double *q;    /* artificial viscosity pressure, or NULL */
  double *jbar; /* Jbar - 1 (F-bar), or NULL */
  double *xm;   /* the positions to move (MPM_MOVE_FUSED), or NULL */
  const double *dx;
} solid_view;

static solid_view view_of(const mpm_ctx *ctx, const mpm_group *gr) {
  const mpm_model *m = ctx->model;
  mpm_state *s = ctx->state;
  const solid_params *sp = gr->params;
  solid_view v = {
      .g = &m->grid,
      .mat = &sp->mat,
      .dt = s->dt,
      .h = m->grid.h,
      .c0 = gr->c0,
      .c1 = gr->c1,
      .jmin = m->opt.min_jacobian,
      .rate = sp->mat.model->rate != NULL,
      .dim = m->dim,
      .begin = gr->begin,
      .end = gr->end,
      .vel = ctx->work->nodes.vel_stress,
      .x = s->x,
      .mass = m->mass,
      .vol0 = m->vol0,
      .F = s->group[gr->index].array[SOLID_F].data,
      .vol = s->vol,
      .sigma = s->sigma,
      .q = sp->q >= 0 ? s->group[gr->index].array[sp->q].data : NULL,
      .jbar = jbar_of(sp, gr, s),
  };
  v.ms = model_state(gr, s, &v.mss);
  return v;
}

/* Each particle's own F: deformation and stress in one pass, and with
 * `move` the particle moved once its velocity gradient is read. */
static void stress_own(mpm_ctx *ctx, const mpm_group *gr, bool move) {
  mpm_work *w = ctx->work;
  solid_view v = view_of(ctx, gr);
  v.xm = move ? ctx->state->x : NULL;
  v.dx = w->dx;
  double maxdiv = 0, Jlow = INFINITY;
  PM_OMP(parallel for schedule(static) default(none) firstprivate(v)
         shared(w) reduction(max : maxdiv) reduction(min : Jlow))
  for (long p = v.begin; p < v.end; p++) {
    long k = p - v.begin;
    double L[9], D[9], W[9];
    mpm_velocity_gradient(v.g, v.vel, v.x + 3 * p, L);
    if (v.xm) mpm_move_particle(v.g, w, v.xm, v.dx, p);
    double *F = v.F + 9 * k, *sig = v.sigma + 9 * p;
    advance_F(v.dt, L, F);
    double J = pm_t_det(F);
    if (!jacobian_ok(w, p, J, v.jmin)) continue;
    v.vol[p] = v.vol0[p] * J;
    /* Comparisons, not fmin and fmax (calls into libm here): the same
     * values, a NaN never taken. */
    if (J < Jlow) Jlow = J;
    mpm_sym_skew(L, D, W);
    double trD = D[0] + D[4] + D[8];
    if (fabs(trD) > maxdiv) maxdiv = fabs(trD);
    if (v.rate) {
      v.mat->model->rate(v.mat, D, W, v.dt, sig);
      if (v.q) sig[0] += v.q[k], sig[4] += v.q[k], sig[8] += v.q[k];
    } else if (!cauchy(v.mat, F, v.ms ? v.ms + v.mss * k : NULL, J, sig)) {
      mpm_fail(w, p, "stress is not finite (J = %g, |F| = %g)", J,
               pm_t_norm(F));
      continue;
    }
    if (v.q)
      viscosity(v.mat, v.c0, v.c1, v.h, v.mass[p] / v.vol[p], trD, v.q + k,
                sig);
  }
  if (maxdiv > w->max_div) w->max_div = maxdiv;
  if (Jlow < w->min_jacobian) w->min_jacobian = Jlow;
}

/* F-bar: every particle's F and J first, then the averages of J, then the
 * stress of Fbar = (Jbar / J)^(1/d) F.  A rate form takes the volumetric
 * part of its rate from Jbar, tr Dbar = ln(Jbar / Jbar_last) / dt, and the
 * artificial viscosity sees tr Dbar too; the particle keeps its own F and
 * volume. */
static void stress_fbar(mpm_ctx *ctx, const mpm_group *gr) {
  mpm_work *w = ctx->work;
  mpm_fbar_work *fw = &w->fbar;
  const solid_view v = view_of(ctx, gr);
  double *jm1 = fw->jm1, *qbar = fw->qbar;
  long *cell = fw->cell;
  double maxdiv = 0, Jlow = INFINITY;
  PM_OMP(parallel for schedule(static) default(none) firstprivate(v)
         shared(w, jm1, cell) reduction(max : maxdiv) reduction(min : Jlow))
  for (long p = v.begin; p < v.end; p++) {
    double L[9], H[9];
    mpm_velocity_gradient(v.g, v.vel, v.x + 3 * p, L);
    double *F = v.F + 9 * (p - v.begin);
    advance_F(v.dt, L, F);
    for (int i = 0; i < 9; i++) H[i] = F[i] - (i % 4 == 0);
    jm1[p] = pm_t_det_minus_one(H);
    if (!jacobian_ok(w, p, 1 + jm1[p], v.jmin)) continue;
    v.vol[p] = v.vol0[p] * (1 + jm1[p]);
    Jlow = fmin(Jlow, 1 + jm1[p]);
    maxdiv = fmax(maxdiv, fabs(L[0] + L[4] + L[8]));
    if (cell) cell[p] = mpm_fbar_cell(v.g, v.x + 3 * p);
  }
  if (maxdiv > w->max_div) w->max_div = maxdiv;
  if (Jlow < w->min_jacobian) w->min_jacobian = Jlow;
  if (w->fail.failed) return; /* no average of a failed J */
  const long b = v.begin, n = v.end - v.begin;
  if (cell)
    mpm_fbar_cell_average(fw, n, cell + b, jm1 + b, v.vol0 + b, fw->mean);
  else
    mpm_fbar_patch_average(fw, v.g, n, v.x + 3 * b, jm1 + b, v.vol0 + b,
                           qbar + b);
  const double *mean = fw->mean;
  PM_OMP(parallel for schedule(static) default(none) firstprivate(v)
         shared(w, jm1, qbar, cell, mean))
  for (long p = v.begin; p < v.end; p++) {
    const long k = p - v.begin;
    const double jb = cell ? mean[cell[p]] : qbar[p];
    const double trDbar = (log1p(jb) - log1p(v.jbar[k])) / v.dt;
    double *F = v.F + 9 * k, *sig = v.sigma + 9 * p;
    v.jbar[k] = jb;
    if (v.rate) {
      /* D with its in-plane (2-D) or whole (3-D) trace replaced. */
      double L[9], D[9], W[9];
      mpm_velocity_gradient(v.g, v.vel, v.x + 3 * p, L);
      mpm_sym_skew(L, D, W);
      const double shift = (trDbar - (D[0] + D[4] + D[8])) / v.dim;
      for (int c = 0; c < v.dim; c++) D[4 * c] += shift;
      v.mat->model->rate(v.mat, D, W, v.dt, sig);
      if (v.q) sig[0] += v.q[k], sig[4] += v.q[k], sig[8] += v.q[k];
    } else {
      double Fbar[9];
      mpm_fbar_apply(v.dim, jm1[p], jb, F, Fbar);
      if (!cauchy(v.mat, Fbar, v.ms ? v.ms + v.mss * k : NULL, 1 + jb, sig)) {
        mpm_fail(w, p, "stress is not finite (Jbar = %g, |Fbar| = %g)", 1 + jb,
                 pm_t_norm(Fbar));
        continue;
      }
    }
    if (v.q)
      viscosity(v.mat, v.c0, v.c1, v.h, v.mass[p] / v.vol[p], trDbar, v.q + k,
                sig);
  }
}

static bool solid_moves(const mpm_group *g) {
  return ((const solid_params *)g->params)->fbar == MPM_FBAR_NONE;
}

static pm_err solid_stress(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_group *gr = &ctx->model->group[self->group];
  if (solid_moves(gr))
    stress_own(ctx, gr, self->mode & MPM_MOVE_FUSED);
  else
    stress_fbar(ctx, gr);
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
  const double *jbar = jbar_of(g->params, g, s);
  const int dim = m->dim;
  double se = 0; /* from zero, then added (as mpm_fluid.c) */
  /* With F-bar, the energy of Fbar: that of the stress the step used. */
  PM_OMP(parallel for schedule(static) default(none)
         shared(mat, ms, mss, begin, end, F, vol0, jbar, dim) reduction(+ : se))
  for (long p = begin; p < end; p++) {
    const long k = p - begin;
    double Fbar[9];
    const double *Fs = stress_F(dim, F + 9 * k, jbar ? jbar + k : NULL, Fbar);
    se += vol0[p] * pm_material_energy(mat, Fs, ms ? ms + mss * k : NULL);
  }
  *strain += se;
}

static void solid_fields(const mpm_model *m, const mpm_state *s,
                         const mpm_group *g, double *sed, double *pressure,
                         double *energy) {
  const pm_material *mat = &((const solid_params *)g->params)->mat;
  const long begin = g->begin, end = g->end;
  long mss;
  const double *ms = model_state(g, s, &mss);
  const double *F = s->group[g->index].array[SOLID_F].data, *sigma = s->sigma;
  const double *jbar = jbar_of(g->params, g, s);
  const int dim = m->dim;
  PM_OMP(parallel for schedule(static) default(none)
         shared(mat, ms, mss, begin, end, F, sigma, sed, pressure, energy, jbar,
                dim))
  for (long p = begin; p < end; p++) {
    const double *sg = sigma + 9 * p;
    const long k = p - begin;
    double Fbar[9];
    const double *Fs = stress_F(dim, F + 9 * k, jbar ? jbar + k : NULL, Fbar);
    sed[p] = pm_material_energy(mat, Fs, ms ? ms + mss * k : NULL);
    pressure[p] = -(sg[0] + sg[4] + sg[8]) / 3.0;
    energy[p] = 0;
  }
}

/* Every volume body's material that is not a fluid. */
static bool solid_takes(const pm_scene_material *sm, mpm_body_role role) {
  return role == MPM_BODY_VOLUME && !pm_material_is_fluid(&sm->mat);
}

/* F, q and its model's state, and with F-bar its Jbar - 1 and the
 * workspace's J - 1 and cell or patch average. */
static double solid_doubles(const pm_scene_material *sm, bool fbar) {
  return 9 + 1 + sm->mat.state_size + (fbar ? 3 : 0);
}

const mpm_kind mpm_kind_solid = {
    .name = "solid",
    .stage_name = "stress: solid",
    .flags = MPM_KIND_STRAIN_ENERGY,
    .takes = solid_takes,
    .estimate_doubles = solid_doubles,
    .setup = solid_setup,
    .seed = solid_seed,
    .stress = solid_stress,
    .moves = solid_moves,
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
