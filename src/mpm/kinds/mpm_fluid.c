/* mpm_fluid: the fluid particle kind (section 2.2 of
 * papers/mpm-fluid-membrane-zona-piezo-icsi.txt, eqs. 23-33): density,
 * specific internal energy and equation-of-state pressure per particle,
 * the density by eq. 25, and the energy and pressure iteratively (steps
 * 1-6) or from the previous stress. */
#include <math.h>
#include <stdio.h>

#include "mpm_kind.h"
#include "mpm_state.h"
#include "pm_fluid.h"
#include "pm_omp.h"

enum { FLUID_RHO = 0, FLUID_E = 1, FLUID_P = 2, FLUID_Q = 3 }; /* slots */

typedef struct {
  pm_fluid fl;
  bool iterative;   /* steps 1-6, else eq. 27 only */
  double tolerance; /* of the iteration, relative */
  int cap;          /* iterations at most */
} fluid_params;

static pm_err fluid_setup(mpm_group *g, const pm_scene_material *sm,
                          const mpm_options *opt) {
  fluid_params *fp = NULL;
  PM_CALL(PM_ALLOC(fp, 1, "fluid constants"));
  fp->fl = sm->mat.fluid;
  fp->iterative = opt->energy_update == MPM_ENERGY_ITERATIVE;
  fp->tolerance = opt->energy_tolerance;
  fp->cap = opt->max_iterations;
  g->params = fp;
  /* The viscous term of the stable step. */
  g->viscosity = 2 * fp->fl.viscosity + fabs(fp->fl.bulk_viscosity);
  mpm_group_add_array(g, "density", 1);
  mpm_group_add_array(g, "energy", 1);
  mpm_group_add_array(g, "pressure", 1);
  if (g->c0 > 0 || g->c1 > 0) mpm_group_add_array(g, "q", 1);
  return PM_SUCCESS;
}

static void fluid_seed(const mpm_group *g, mpm_group_state *gs, long k,
                       const pm_scene_body *b, double sigma[9]) {
  const fluid_params *fp = g->params;
  const double rho0 = b->density, p0 = b->pressure;
  gs->array[FLUID_RHO].data[k] = rho0;
  gs->array[FLUID_P].data[k] = p0;
  gs->array[FLUID_E].data[k] = pm_eos_energy(&fp->fl, rho0, p0);
  sigma[0] = sigma[4] = sigma[8] = -p0;
}

static void fluid_describe(const mpm_group *g, char *buf, size_t size) {
  const fluid_params *fp = g->params;
  snprintf(buf, size, "density (eq. 25), %s EOS, %s energy update%s%s",
           pm_eos_name(fp->fl.eos),
           fp->iterative ? "iterative (steps 1-6)" : "non-iterative",
           fp->fl.viscosity > 0 || fp->fl.bulk_viscosity > 0
               ? ", viscous stress (eq. 23)"
               : "",
           g->n_arrays > FLUID_Q ? ", artificial viscosity (eq. 32)" : "");
}

/* Internal energy and pressure at the new density rho from the start of
 * the step's energy e0 and stress sig, with tau : D and tr D of the step
 * and the artificial viscosity q; *iterations receives the iterations
 * taken, negated when they hit the cap. */
static inline double energy_update(const fluid_params *fp, double rho,
                                   double e0, const double sig[9],
                                   const double D[9], double tauD, double trD,
                                   double q, double dt, double *P_out,
                                   int *iterations) {
  const pm_fluid *fl = &fp->fl;
  double c = dt / rho;
  double e = e0 + c * pm_t_ddot(sig, D); /* eq. 27 */
  double P = pm_eos_pressure(fl, rho, e);
  int m = 1;
  if (fp->iterative) {
    double work_prev = 0, work = 0;
    for (;; m++) {
      P = pm_eos_pressure(fl, rho, e);       /* eq. 28 */
      work = tauD - (P + q) * trD;           /* eq. 29 */
      double e_next = m == 1 ? e0 + c * work /* eq. 30 */
                             : e0 + c * 0.5 * (work_prev + work);
      double change = fabs(e_next - e);
      work_prev = work;
      e = e_next;
      if (change <= fp->tolerance * (fabs(e) + fabs(e0)) || change == 0) break;
      if (m >= fp->cap) {
        m = -m;
        break;
      }
    }
    /* Eq. 31: the stress of the last iteration. */
  } else {
    P = pm_eos_pressure(fl, rho, e);
  }
  *P_out = P;
  *iterations = m;
  return e;
}

static pm_err fluid_stress(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  mpm_state *s = ctx->state;
  mpm_work *w = ctx->work;
  const mpm_group *gr = &m->group[self->group];
  const mpm_grid *g = &m->grid;
  const fluid_params *fp = gr->params;
  const pm_fluid *fl = &fp->fl;
  const double dt = s->dt, h = g->h, c0 = gr->c0, c1 = gr->c1;
  const long begin = gr->begin, end = gr->end;
  const double *vel = w->nodes.vel_stress, *x = s->x, *mass = m->mass,
               *vol0 = m->vol0;
  mpm_array *arr = s->group[self->group].array;
  double *rho_a = arr[FLUID_RHO].data, *e_a = arr[FLUID_E].data,
         *p_a = arr[FLUID_P].data, *vol = s->vol, *sigma = s->sigma;
  double *qa = gr->n_arrays > FLUID_Q ? arr[FLUID_Q].data : NULL;
  double maxdiv = 0, Jlow = INFINITY;
  int itmax = 0;
  long capped = 0;
  /* Chunks dealt in turn: the iterations of the energy update gather at
   * the shock and the fan, which a thread's one block would hold alone. */
  PM_OMP(parallel for schedule(static, 256) default(none)
         shared(g, fp, fl, w, dt, h, c0, c1, begin, end, vel, x, mass, vol0,
                rho_a, e_a, p_a, vol, sigma, qa)
         reduction(max : maxdiv, itmax) reduction(+ : capped)
         reduction(min : Jlow))
  for (long p = begin; p < end; p++) {
    long k = p - begin;
    double L[9], D[9], W[9], tau[9];
    mpm_velocity_gradient(g, vel, x + 3 * p, L);
    mpm_sym_skew(L, D, W);
    double trD = D[0] + D[4] + D[8];
    maxdiv = fmax(maxdiv, fabs(trD));
    double den = 1.0 + dt * trD;
    if (!(den > 0)) {
      mpm_fail(w, p,
               "density update failed: 1 + dt div v = %g <= 0 (div v = %g "
               "1/s)",
               den, trD);
      continue;
    }
    double rho = rho_a[k] / den; /* eq. 25 */
    double *sig = sigma + 9 * p;
    pm_fluid_viscous_stress(fl, D, tau);
    double a = pm_eos_sound_speed(fl, rho, p_a[k]);
    double q = qa ? pm_artificial_viscosity(c0, c1, rho, h, a, trD) : 0.0;
    /* sigma : D = tau : D - (P + q) tr D */
    double tauD = pm_t_ddot(tau, D);
    double P;
    int it;
    double e =
        energy_update(fp, rho, e_a[k], sig, D, tauD, trD, q, dt, &P, &it);
    if (it < 0) {
      capped++;
      it = -it;
    }
    if (it > itmax) itmax = it;
    if (!(P + fl->p_inf > 0) || !isfinite(e)) {
      /* No real sound speed: the state has left the equation of state
       * (cavitation, or an energy driven negative). */
      mpm_fail(w, p,
               "pressure %g Pa <= -p_inf: no sound speed (internal energy %g "
               "J/kg)",
               P, e);
      continue;
    }
    rho_a[k] = rho;
    e_a[k] = e;
    p_a[k] = P;
    if (qa) qa[k] = q;
    vol[p] = mass[p] / rho;
    Jlow = fmin(Jlow, vol[p] / vol0[p]);
    for (int i = 0; i < 9; i++) sig[i] = tau[i];
    sig[0] -= P + q;
    sig[4] -= P + q;
    sig[8] -= P + q;
  }
  if (maxdiv > w->max_div) w->max_div = maxdiv;
  if (Jlow < w->min_jacobian) w->min_jacobian = Jlow;
  if (itmax > w->iter_max) w->iter_max = itmax;
  w->iter_capped += capped;
  return mpm_stage_status(ctx, self);
}

static void fluid_wave_speeds(const mpm_model *m, const mpm_state *s,
                              const mpm_group *g, double *cp, double *cs) {
  (void)m;
  const pm_fluid *fl = &((const fluid_params *)g->params)->fl;
  const long begin = g->begin, end = g->end;
  const double *rho = s->group[g->index].array[FLUID_RHO].data,
               *P = s->group[g->index].array[FLUID_P].data;
  PM_OMP(parallel for schedule(static) default(none)
         shared(fl, begin, end, rho, P, cp, cs))
  for (long p = begin; p < end; p++) {
    cp[p] = pm_eos_sound_speed(fl, rho[p - begin], P[p - begin]);
    if (cs) cs[p] = 0;
  }
}

static void fluid_energies(const mpm_model *m, const mpm_state *s,
                           const mpm_group *g, double *strain,
                           double *internal) {
  (void)strain;
  const long begin = g->begin, end = g->end;
  const double *e = s->group[g->index].array[FLUID_E].data, *mass = m->mass;
  /* From zero, then added: with two threads the sum is then the same
   * whichever thread's share comes first. */
  double ie = 0;
  PM_OMP(parallel for schedule(static) default(none)
         shared(begin, end, e, mass) reduction(+ : ie))
  for (long p = begin; p < end; p++) ie += mass[p] * e[p - begin];
  *internal += ie;
}

static void fluid_fields(const mpm_model *m, const mpm_state *s,
                         const mpm_group *g, double *sed, double *pressure,
                         double *energy) {
  (void)m;
  const long begin = g->begin, end = g->end;
  const double *e = s->group[g->index].array[FLUID_E].data,
               *P = s->group[g->index].array[FLUID_P].data;
  PM_OMP(parallel for schedule(static) default(none)
         shared(begin, end, e, P, sed, pressure, energy))
  for (long p = begin; p < end; p++) {
    sed[p] = 0;
    pressure[p] = P[p - begin];
    energy[p] = e[p - begin];
  }
}

/* A volume body's fluid material. */
static bool fluid_takes(const pm_scene_material *sm, mpm_body_role role) {
  return role == MPM_BODY_VOLUME && pm_material_is_fluid(&sm->mat);
}

/* Density, energy, pressure and q. */
static double fluid_doubles(const pm_scene_material *sm, bool fbar) {
  (void)sm, (void)fbar;
  return 4;
}

const mpm_kind mpm_kind_fluid = {
    .name = "fluid",
    .stage_name = "stress: fluid",
    .flags = MPM_KIND_INTERNAL_ENERGY | MPM_KIND_ITERATES,
    .takes = fluid_takes,
    .estimate_doubles = fluid_doubles,
    .setup = fluid_setup,
    .seed = fluid_seed,
    .stress = fluid_stress,
    .describe = fluid_describe,
    .wave_speeds = fluid_wave_speeds,
    .energies = fluid_energies,
    .fields = fluid_fields,
};
