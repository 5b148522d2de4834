/* mpm_membrane_stress: the membrane's stress stage (the frame carried to
 * the new normal, the strain increment in it, plane stress with the
 * elastodamage of eqs. 38-41) and the law's entry points for tests. */
#include <math.h>
#include <string.h>

#include "mpm_membrane_impl.h"
#include "pm_omp.h"

double mpm_membrane_damage(const pm_scene_damage *dm, double e_max,
                           double *omega, double *failed) {
  membrane_params mp = {.c0 = dm->c0,
                        .c1 = dm->c1,
                        .limit = dm->elastic_limit,
                        .failure = dm->failure,
                        .damage = true};
  return damage_step(&mp, e_max, omega, failed);
}

double mpm_membrane_max_strain(const double e[3]) { return eps_max(e); }

/* The stress stage: steps 3-5 of mpm_membrane.c for the group's points. */
pm_err mpm_membrane_stress(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  mpm_state *s = ctx->state;
  mpm_work *w = ctx->work;
  const int gi = self->group;
  const mpm_group *gr = &m->group[gi];
  const mpm_grid *g = &m->grid;
  const membrane_params *mp = gr->params;
  const long begin = gr->begin, end = gr->end;
  const double dt = s->dt, jmin = m->opt.min_jacobian;
  const double ez_of = -mp->nu / (1 - mp->nu); /* eq. 1 */
  const double *nn = w->scratch[gi];           /* the normal stage's */
  /* The strain follows the velocity that moves the points (MUSL's remapped
   * velocity differs from it by the particles' noise, and a membrane whose
   * strain and positions part creeps without stretching). */
  const double *vel =
      m->opt.update == MPM_MUSL ? w->nodes.vel_new : w->nodes.vel_stress;
  const double *x = s->x, *vol0 = m->vol0;
  mpm_group_state *gs = &s->group[gi];
  double *frame = gs->array[MEM_FRAME].data, *eps = gs->array[MEM_STRAIN].data;
  double *om = mp->damage ? gs->array[MEM_OMEGA].data : NULL;
  double *failed = mp->damage ? gs->array[MEM_FAILED].data : NULL;
  double *vol = s->vol, *sigma = s->sigma;
  double lost = 0, Jlow = INFINITY;
  PM_OMP(parallel for schedule(static) default(none)
         shared(g, mp, w, begin, end, dt, jmin, ez_of, nn, vel, x, vol0,
                frame, eps, om, failed, vol, sigma)
         reduction(+ : lost) reduction(min : Jlow))
  for (long p = begin; p < end; p++) {
    const long k = p - begin;
    double L[9], D[9], W[9], n1[3];
    double *f = frame + 9 * k, *e = eps + 3 * k, *sig = sigma + 9 * p;
    mpm_velocity_gradient(g, vel, x + 3 * p, L);
    mpm_sym_skew(L, D, W);
    /* The spin about the normal: the axial vector of W along n. */
    const double *n0 = f + 6;
    double spin = W[7] * n0[0] + W[2] * n0[1] + W[3] * n0[2];
    /* The new normal, on the side of the old one (a fitted normal's sign
     * is arbitrary; S must not see a flip). */
    memcpy(n1, nn + 3 * k, sizeof n1);
    if (!(pm_v_norm(n1) > 0.5)) memcpy(n1, n0, sizeof n1);
    if (pm_v_dot(n1, n0) < 0)
      for (int d = 0; d < 3; d++) n1[d] = -n1[d];
    mpm_membrane_carry_frame(f, spin * dt, n1);
    /* The strain increment in the frame. */
    const double *e1 = f, *e2 = f + 3;
    double De1[3], De2[3];
    for (int i = 0; i < 3; i++) {
      De1[i] = D[3 * i] * e1[0] + D[3 * i + 1] * e1[1] + D[3 * i + 2] * e1[2];
      De2[i] = D[3 * i] * e2[0] + D[3 * i + 1] * e2[1] + D[3 * i + 2] * e2[2];
    }
    e[0] += dt * pm_v_dot(e1, De1);
    e[1] += dt * pm_v_dot(e2, De2);
    e[2] += dt * pm_v_dot(e1, De2);
    double J = 1 + (1 + ez_of) * (e[0] + e[1]);
    if (!(J > jmin) || !isfinite(J)) {
      mpm_fail(w, p,
               "membrane area-thickness ratio J = %g <= %g (the membrane is "
               "compressed through itself)",
               J, jmin);
      continue;
    }
    vol[p] = vol0[p] * J;
    Jlow = fmin(Jlow, J);
    double d = 1.0;
    if (mp->damage) {
      double d_old = factor_of(mp, om, failed, k);
      double w_old = plane_energy(mp, e, d_old);
      d = damage_step(mp, eps_max(e), &om[k], &failed[k]);
      lost += vol0[p] * (w_old - plane_energy(mp, e, d));
    }
    double sl[3];
    plane_stress(mp, e, d, sl);
    to_global(f, sl, sig);
  }
  if (Jlow < w->min_jacobian) w->min_jacobian = Jlow;
  if (mp->damage) mpm_book_dissipated(ctx, self, lost);
  return mpm_stage_status(ctx, self);
}
