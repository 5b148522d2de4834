/* mpm_membrane: the membrane particle kind (section 2.1 of
 * papers/mpm-fluid-membrane-zona-piezo-icsi.txt, eqs. 1-22, and the
 * elastodamage of eqs. 38-41).  One layer of points on the vertices of a
 * triangulated surface; each carries a local frame (e1, e2 in the tangent
 * plane, n the normal), its in-plane strain in that frame, and, with
 * damage, the damage variable omega and a failed flag.
 *
 * Each step:
 *   1. the triangles' unit normals from the current positions;
 *   2. each point's normal, the mean of its triangles' (eq. 8);
 *   3. the frame carried to it: first turned about the old normal by the
 *      grid's in-plane spin, then by the rotation S of eqs. 9-22 that takes
 *      the old normal to the new one and keeps what is perpendicular to
 *      both;
 *   4. the strain increment of the grid's rate of deformation, in the frame
 *      (eq. 5 applied to the increment), added to the frame's strain;
 *   5. plane stress (eqs. 1-2 with sigma_z' = 0 and no out-of-plane shear),
 *      scaled by the elastodamage secant stiffness, rotated back (eq. 7).
 *
 * The paper adds strain increments in the global axes and rotates the
 * total; a membrane that turns then sees its strain turn out of its plane.
 * Keeping the strain in the frame and the frame turning with the material
 * makes a rigid rotation leave the stress unchanged in the frame (the
 * frame-update test checks it). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gm_trisurf.h"
#include "mpm_kind.h"
#include "mpm_state.h"
#include "pm_omp.h"

/* State array slots. */
enum { MEM_FRAME = 0, MEM_STRAIN = 1, MEM_OMEGA = 2, MEM_FAILED = 3 };

typedef struct {
  double E, nu;
  double C;       /* plane-stress modulus E / (1 - nu^2) */
  double G;       /* E / (2 (1 + nu)) */
  bool damage;    /* eqs. 38-41 */
  double c0, c1;  /* eq. 39 */
  double limit;   /* S_L, eq. 40 */
  double failure; /* eps_max at failure */
  /* point -> triangles, both counted within the group (gm_trisurf's
   * incidence of the group's surface) */
  long *inc_start, *inc_tri;
} membrane_params;

static pm_err membrane_setup(mpm_group *g, const pm_scene_material *sm,
                             const mpm_options *opt) {
  (void)opt;
  membrane_params *mp = NULL;
  PM_CALL(PM_ALLOC(mp, 1, "membrane constants"));
  g->params = mp;
  mp->E = sm->mat.youngs_modulus;
  mp->nu = sm->mat.poisson_ratio;
  mp->C = mp->E / (1 - mp->nu * mp->nu);
  mp->G = mp->E / (2 * (1 + mp->nu));
  mp->damage = sm->damage.given;
  mp->c0 = sm->damage.c0;
  mp->c1 = sm->damage.c1;
  mp->limit = sm->damage.elastic_limit;
  mp->failure = sm->damage.failure;
  g->viscosity = 0;
  mpm_group_add_array(g, "frame", 9);
  mpm_group_add_array(g, "membrane_strain", 3);
  if (mp->damage) {
    mpm_group_add_array(g, "omega", 1);
    mpm_group_add_array(g, "failed", 1);
  }
  return PM_SUCCESS;
}

static void membrane_release(mpm_group *g) {
  membrane_params *mp = g->params;
  if (!mp) return;
  free(mp->inc_start);
  free(mp->inc_tri);
}

static void membrane_seed(const mpm_group *g, mpm_group_state *gs, long k,
                          const pm_scene_body *b, double sigma[9]) {
  (void)g, (void)b, (void)sigma;
  /* The frame needs the surface: mpm_kind.finish sets it. */
  memset(gs->array[MEM_FRAME].data + 9 * k, 0, 9 * sizeof(double));
}

static void membrane_describe(const mpm_group *g, char *buf, size_t size) {
  const membrane_params *mp = g->params;
  if (mp->damage)
    snprintf(buf, size,
             "membrane: normals by connectivity (eq. 8), frame by S (eqs. "
             "9-22), plane stress E = %g, nu = %g, elastodamage (eqs. 38-41, "
             "c0 = %g, c1 = %g, S_L = %g), fails at eps_max = %g",
             mp->E, mp->nu, mp->c0, mp->c1, mp->limit, mp->failure);
  else
    snprintf(buf, size,
             "membrane: normals by connectivity (eq. 8), frame by S (eqs. "
             "9-22), plane stress E = %g, nu = %g",
             mp->E, mp->nu);
}

/* ---- the membrane law ----------------------------------------------------
 * In the frame: strain e = (e11, e22, e12) (tensor shear), secant factor
 * d in [0, 1], stress s = d C(e).  Energy W = 1/2 s : e per reference
 * volume. */

static inline double eps_max(const double e[3]) {
  double a = 0.5 * (e[0] + e[1]), b = 0.5 * (e[0] - e[1]);
  return a + sqrt(b * b + e[2] * e[2]);
}

static inline void plane_stress(const membrane_params *mp, const double e[3],
                                double d, double s[3]) {
  s[0] = d * mp->C * (e[0] + mp->nu * e[1]);
  s[1] = d * mp->C * (e[1] + mp->nu * e[0]);
  s[2] = d * 2 * mp->G * e[2];
}

static inline double plane_energy(const membrane_params *mp, const double e[3],
                                  double d) {
  double s[3];
  plane_stress(mp, e, d, s);
  return 0.5 * (s[0] * e[0] + s[1] * e[1] + 2 * s[2] * e[2]);
}

/* The secant factor of eq. 39: 1 + 2 c0 (exp(-c1 omega) - 1), at least 0
 * (a secant stiffness does not turn negative). */
static inline double secant(const membrane_params *mp, double omega) {
  return fmax(0.0, 1.0 + 2.0 * mp->c0 * (exp(-mp->c1 * omega) - 1.0));
}

/* The point's factor d from its damage state (1 without damage). */
static inline double factor_of(const membrane_params *mp, const double *om,
                               const double *failed, long k) {
  if (!mp->damage) return 1.0;
  return failed[k] > 0 ? 0.0 : secant(mp, om[k]);
}

/* Eqs. 38-40 at the largest principal strain e_max: failure at the
 * failure strain, omega on the damage surface f = 0 when e_max passes it;
 * returns the secant factor. */
static inline double damage_step(const membrane_params *mp, double e_max,
                                 double *omega, double *failed) {
  if (*failed <= 0 && e_max >= mp->failure) *failed = 1;
  if (*failed <= 0 && e_max > mp->limit * (1 + *omega))
    *omega = e_max / mp->limit - 1;
  return *failed > 0 ? 0.0 : secant(mp, *omega);
}

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

/* ---- normals and frames ------------------------------------------------- */

/* Unit normals of triangles [t0, t1) from positions x into tn (3 each,
 * indexed t - t0); zero for a degenerate triangle. */
static void triangle_normals(const mpm_model *m, const double *x, long t0,
                             long t1, double *tn) {
  const long *tri = m->tri;
  PM_OMP(parallel for schedule(static) default(none)
         shared(tri, x, t0, t1, tn))
  for (long t = t0; t < t1; t++) {
    const double *a = x + 3 * tri[3 * t], *b = x + 3 * tri[3 * t + 1],
                 *c = x + 3 * tri[3 * t + 2];
    double u[3], v[3], n[3];
    for (int i = 0; i < 3; i++) u[i] = b[i] - a[i], v[i] = c[i] - a[i];
    pm_v_cross(u, v, n);
    double len = pm_v_norm(n);
    for (int i = 0; i < 3; i++) tn[3 * (t - t0) + i] = len > 0 ? n[i] / len : 0;
  }
}

/* The mean of point k's triangles' unit normals, normalised (eq. 8); false
 * when it vanishes. */
static inline bool point_normal(const membrane_params *mp, long k,
                                const double *tn, double n[3]) {
  n[0] = n[1] = n[2] = 0;
  for (long j = mp->inc_start[k]; j < mp->inc_start[k + 1]; j++) {
    const double *a = tn + 3 * mp->inc_tri[j];
    for (int i = 0; i < 3; i++) n[i] += a[i];
  }
  double len = pm_v_norm(n);
  if (!(len > 1e-12)) return false;
  for (int i = 0; i < 3; i++) n[i] /= len;
  return true;
}

/* e1, e2 in the plane of n: e1 from the axis least aligned with n. */
static void frame_from_normal(const double n[3], double f[9]) {
  int a = 0;
  for (int i = 1; i < 3; i++)
    if (fabs(n[i]) < fabs(n[a])) a = i;
  double e1[3] = {0, 0, 0};
  e1[a] = 1;
  double dot = pm_v_dot(e1, n);
  for (int i = 0; i < 3; i++) e1[i] -= dot * n[i];
  double len = pm_v_norm(e1);
  for (int i = 0; i < 3; i++) e1[i] /= len;
  double e2[3];
  pm_v_cross(n, e1, e2);
  memcpy(f, e1, sizeof e1);
  memcpy(f + 3, e2, sizeof e2);
  memcpy(f + 6, n, 3 * sizeof(double));
}

/* v <- S v, the rotation of eq. 22 taking unit n0 to unit n1 and keeping
 * w = n0 x n1: S v = w^ (w^.v) + c (v - w^ (w^.v)) + n1 (n0.v) - n0 (n1.v),
 * c = n0.n1 (S = I when w vanishes). */
static inline void rotate_s(const double n0[3], const double n1[3],
                            double v[3]) {
  double w[3];
  pm_v_cross(n0, n1, w);
  double s = pm_v_norm(w);
  if (!(s > 0)) return;
  for (int i = 0; i < 3; i++) w[i] /= s;
  double c = pm_v_dot(n0, n1), wv = pm_v_dot(w, v), a = pm_v_dot(n0, v),
         b = pm_v_dot(n1, v), r[3];
  for (int i = 0; i < 3; i++)
    r[i] = w[i] * wv + c * (v[i] - w[i] * wv) + n1[i] * a - n0[i] * b;
  memcpy(v, r, sizeof r);
}

/* Carry frame f (e1, e2, n) over the step: turn e1, e2 about n by the
 * in-plane spin angle phi, then apply S from n to n1, and make the frame
 * orthonormal again (e1 projected, e2 = n1 x e1). */
void mpm_membrane_carry_frame(double f[9], double phi, const double n1[3]) {
  double *e1 = f, *e2 = f + 3, *n0 = f + 6;
  double c = cos(phi), s = sin(phi), a[3], b[3];
  for (int i = 0; i < 3; i++) {
    a[i] = c * e1[i] + s * e2[i];
    b[i] = -s * e1[i] + c * e2[i];
  }
  rotate_s(n0, n1, a);
  double dot = pm_v_dot(a, n1);
  for (int i = 0; i < 3; i++) a[i] -= dot * n1[i];
  double len = pm_v_norm(a);
  if (!(len > 0)) {
    frame_from_normal(n1, f);
    return;
  }
  for (int i = 0; i < 3; i++) e1[i] = a[i] / len;
  pm_v_cross(n1, e1, b);
  memcpy(e2, b, sizeof b);
  memcpy(n0, n1, 3 * sizeof(double));
}

/* sigma = sum_ab s_ab e_a (x) e_b over the frame's tangent vectors. */
static inline void to_global(const double f[9], const double s[3],
                             double sig[9]) {
  const double *e1 = f, *e2 = f + 3;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      sig[3 * i + j] = s[0] * e1[i] * e1[j] + s[1] * e2[i] * e2[j] +
                       s[2] * (e1[i] * e2[j] + e2[i] * e1[j]);
}

/* Normals by connectivity and frames of the group's points (setup). */
static pm_err membrane_finish(const mpm_model *m, mpm_group *g, mpm_state *s) {
  membrane_params *mp = g->params;
  const long t0 = m->tri_begin[g->index], t1 = m->tri_end[g->index];
  const long np = g->end - g->begin;
  double *tn = NULL;
  pm_err ret = PM_SUCCESS;
  /* Incidence: each point's triangles, of the group's surface. */
  long *local = NULL;
  PM_TRY(mpm_triangles_local(m, t0, t1, g->begin, &local));
  gm_trisurf sf = {.n_points = np,
                   .x = s->x + 3 * g->begin,
                   .n_tris = t1 - t0,
                   .tri = local};
  ret = gm_trisurf_incidence(&sf, &mp->inc_start, &mp->inc_tri);
  free(local);
  if (ret) goto done;
  PM_TRY(PM_ALLOC(tn, 3 * (t1 - t0) + 3, "triangle normals"));
  triangle_normals(m, s->x, t0, t1, tn);
  double *frame = s->group[g->index].array[MEM_FRAME].data;
  for (long k = 0; k < np; k++) {
    double n[3];
    PM_ENSURE(point_normal(mp, k, tn, n), PM_ERR_SCENE,
              "membrane %s: point %ld at (%g, %g, %g) has no normal (it "
              "belongs to no triangle, or its triangles' normals cancel)",
              g->name, g->begin + k, s->x[3 * (g->begin + k)],
              s->x[3 * (g->begin + k) + 1], s->x[3 * (g->begin + k) + 2]);
    frame_from_normal(n, frame + 9 * k);
  }
done:
  free(tn);
  return ret;
}

static long membrane_scratch(const mpm_model *m, const mpm_group *g) {
  return 3 * (m->tri_end[g->index] - m->tri_begin[g->index]);
}

/* ---- the stage ---------------------------------------------------------- */

static pm_err membrane_stress(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  mpm_state *s = ctx->state;
  mpm_work *w = ctx->work;
  const int gi = self->group;
  const mpm_group *gr = &m->group[gi];
  const mpm_grid *g = &m->grid;
  const membrane_params *mp = gr->params;
  const long t0 = m->tri_begin[gi], t1 = m->tri_end[gi];
  const long begin = gr->begin, end = gr->end;
  const double dt = s->dt, jmin = m->opt.min_jacobian;
  const double ez_of = -mp->nu / (1 - mp->nu); /* eq. 1 */
  double *tn = w->scratch[gi];
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
  triangle_normals(m, x, t0, t1, tn);
  PM_OMP(parallel for schedule(static) default(none)
         shared(g, mp, w, begin, end, dt, jmin, ez_of, tn, vel, x, vol0,
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
    if (!point_normal(mp, k, tn, n1)) memcpy(n1, n0, sizeof n1);
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

static void membrane_wave_speeds(const mpm_model *m, const mpm_state *s,
                                 const mpm_group *g, double *cp, double *cs) {
  const membrane_params *mp = g->params;
  const long begin = g->begin, end = g->end;
  const double *mass = m->mass, *vol = s->vol;
  PM_OMP(parallel for schedule(static) default(none)
         shared(mp, begin, end, mass, vol, cp, cs))
  for (long p = begin; p < end; p++) {
    double rho = mass[p] / vol[p];
    cp[p] = sqrt(mp->C / rho);
    if (cs) cs[p] = sqrt(mp->G / rho);
  }
}

static void membrane_energies(const mpm_model *m, const mpm_state *s,
                              const mpm_group *g, double *strain,
                              double *internal) {
  (void)internal;
  const membrane_params *mp = g->params;
  const mpm_group_state *gs = &s->group[g->index];
  const double *eps = gs->array[MEM_STRAIN].data, *vol0 = m->vol0;
  const double *om = mp->damage ? gs->array[MEM_OMEGA].data : NULL;
  const double *failed = mp->damage ? gs->array[MEM_FAILED].data : NULL;
  const long begin = g->begin, end = g->end;
  double se = 0; /* from zero, then added (as mpm_fluid.c) */
  PM_OMP(parallel for schedule(static) default(none)
         shared(mp, eps, vol0, om, failed, begin, end) reduction(+ : se))
  for (long p = begin; p < end; p++) {
    const long k = p - begin;
    se += vol0[p] * plane_energy(mp, eps + 3 * k, factor_of(mp, om, failed, k));
  }
  *strain += se;
}

static void membrane_fields(const mpm_model *m, const mpm_state *s,
                            const mpm_group *g, double *sed, double *pressure,
                            double *energy) {
  (void)m;
  const membrane_params *mp = g->params;
  const mpm_group_state *gs = &s->group[g->index];
  const double *eps = gs->array[MEM_STRAIN].data, *sigma = s->sigma;
  const double *om = mp->damage ? gs->array[MEM_OMEGA].data : NULL;
  const double *failed = mp->damage ? gs->array[MEM_FAILED].data : NULL;
  for (long p = g->begin; p < g->end; p++) {
    const long k = p - g->begin;
    const double *sg = sigma + 9 * p;
    sed[p] = plane_energy(mp, eps + 3 * k, factor_of(mp, om, failed, k));
    pressure[p] = -(sg[0] + sg[4] + sg[8]) / 3.0;
    energy[p] = 0;
  }
}

static void membrane_surface_fields(const mpm_model *m, const mpm_state *s,
                                    const mpm_group *g, double *normal,
                                    double *damage, double *failed_out) {
  (void)m;
  const membrane_params *mp = g->params;
  const mpm_group_state *gs = &s->group[g->index];
  const double *frame = gs->array[MEM_FRAME].data;
  const double *om = mp->damage ? gs->array[MEM_OMEGA].data : NULL;
  const double *failed = mp->damage ? gs->array[MEM_FAILED].data : NULL;
  for (long p = g->begin; p < g->end; p++) {
    const long k = p - g->begin;
    for (int c = 0; c < 3; c++) normal[3 * p + c] = frame[9 * k + 6 + c];
    damage[p] = 1.0 - factor_of(mp, om, failed, k);
    failed_out[p] = mp->damage && failed[k] > 0 ? 1.0 : 0.0;
  }
}

const mpm_kind mpm_kind_membrane = {
    .name = "membrane",
    .stage_name = "stress: membrane",
    .flags = MPM_KIND_STRAIN_ENERGY | MPM_KIND_MEMBRANE,
    .setup = membrane_setup,
    .release = membrane_release,
    .seed = membrane_seed,
    .finish = membrane_finish,
    .scratch = membrane_scratch,
    .stress = membrane_stress,
    .describe = membrane_describe,
    .wave_speeds = membrane_wave_speeds,
    .energies = membrane_energies,
    .fields = membrane_fields,
    .surface_fields = membrane_surface_fields,
};
