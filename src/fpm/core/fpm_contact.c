/* fpm_contact: penalty contact of rigid plates and spheres on the boundary
 * points of an FPM body: candidates, forces, tangent, reactions and work. */
#include "fpm_contact.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_omp.h"
#include "pm_rigid.h"

/* Layout of the state: anchors (3 per pair), then per body the reaction,
 * the previous reaction and the previous displacement (9 per body), then
 * the contact energy. */
#define ST_BODY(c, b) (3 * (c)->pair_ptr[(c)->n_bodies] + 9 * (b))

long fpm_contact_state_size(const fpm_contact *c) {
  return c ? 3 * c->pair_ptr[c->n_bodies] + 9 * c->n_bodies + 1 : 0;
}

pm_err fpm_contact_state_init(const fpm_contact *c, double **out) {
  const long n = fpm_contact_state_size(c);
  PM_CALL(PM_ALLOC(*out, n, "contact state"));
  memcpy(*out, c->anchor0,
         3 * (size_t)c->pair_ptr[c->n_bodies] * sizeof(double));
  return PM_SUCCESS;
}

/* Static solves: whether a point at gap g (anchor: its anchor, NaN for
 * none) touches.  An anchored point holds on over the whole load step
 * (fpm_contact_commit lets it go at a converged step where it has come
 * off): its force is then smooth in the displacement, where a release
 * inside the step would make the residual jump by its tangential part and
 * Newton chatter between the two. */
static bool touching_fixed(double g, const double *anchor) {
  return g < 0 || !isnan(anchor[0]);
}

/* The force on a point at x touching (g < 0, normal n) the body displaced
 * by d: sticking to anchor (non-NULL), else pushed along n; its energy. */
static double touch_force(double k, const double d[3], const double x[3],
                          double g, const double n[3], const double *anchor,
                          double F[3]) {
  if (!anchor) {
    for (int a = 0; a < 3; a++) F[a] = -k * g * n[a];
    return 0.5 * k * g * g;
  }
  double e = 0;
  for (int a = 0; a < 3; a++) {
    const double s = x[a] - d[a] - anchor[a];
    F[a] = -k * s;
    e += s * s;
  }
  return 0.5 * k * e;
}

/* dF = -K dx of touch_force at x (g < 0, normal n): k I sticking, else
 * k n n, plus on a sphere the turn of n, dn/dx = (I - n n) / r. */
static void touch_tangent(const pm_scene_bc *bc, double k, double g,
                          const double n[3], bool sticking, double K[9]) {
  memset(K, 0, 9 * sizeof(double));
  if (sticking) {
    K[0] = K[4] = K[8] = k;
    return;
  }
  double q = 0;
  if (bc->on == PM_ON_SPHERE) q = g / (g + bc->rigid_radius);
  for (int a = 0; a < 3; a++)
    for (int b = 0; b < 3; b++)
      K[3 * a + b] = k * (n[a] * n[b] + q * ((a == b) - n[a] * n[b]));
}

bool fpm_contact_point(const pm_scene_bc *bc, double k, const double d[3],
                       const double x[3], double anchor[3], double F[3],
                       double *energy) {
  double n[3];
  const double g = pm_rigid_gap(bc, d, x, n);
  const bool glued = bc->contact == PM_CONTACT_GLUED;
  *energy = 0;
  /* a glued point stays held once anchored, pulled off as well as pushed */
  if (!(g < 0) && !(glued && !isnan(anchor[0]))) {
    F[0] = F[1] = F[2] = 0;
    if (!glued) anchor[0] = anchor[1] = anchor[2] = NAN;
    return false;
  }
  const bool sticking = bc->contact != PM_CONTACT_FRICTIONLESS;
  if (sticking && isnan(anchor[0]))
    for (int a = 0; a < 3; a++) anchor[a] = x[a] - d[a] - g * n[a];
  *energy = touch_force(k, d, x, g, n, sticking ? anchor : NULL, F);
  return true;
}

void fpm_contact_tangent(const pm_scene_bc *bc, double k, const double d[3],
                         const double x[3], const double anchor[3],
                         double K[9]) {
  double n[3];
  const double g = pm_rigid_gap(bc, d, x, n);
  const bool glued = bc->contact == PM_CONTACT_GLUED;
  memset(K, 0, 9 * sizeof(double));
  if (g < 0 || (glued && !isnan(anchor[0])))
    touch_tangent(bc, k, g, n, bc->contact != PM_CONTACT_FRICTIONLESS, K);
}

/* The rigid body's displacement at time t: ramp(t) d(t), times scale. */
static void body_displacement(const pm_scene_bc *bc, double t, double scale,
                              double d[3]) {
  pm_rigid_displacement(bc, t, d);
  for (int a = 0; a < 3; a++) d[a] *= scale;
}

/* Each point's boundary area (sum of its facets' areas) into area (n). */
static void boundary_areas(const gm_dual *d, double *area) {
  for (long f = 0; f < d->n_facets; f++)
    area[d->facet_point[f]] += d->facet_area[f];
}

/* A body that starts inside the deformable body: the first point deeper
 * than the tolerance, at the body's key. */
static pm_err check_start(const fpm_model *m, const fpm_contact *c, int b) {
  const pm_scene *s = m->scene;
  const pm_scene_bc *bc = &s->bcs[c->bc[b]];
  const double zero[3] = {0, 0, 0}, tol = 1e-3 * s->mesh_size;
  char p[64];
  for (long q = c->pair_ptr[b]; q < c->pair_ptr[b + 1]; q++) {
    const long i = c->pair_point[q];
    const double *x = m->x + 3 * i;
    double n[3], g = pm_rigid_gap(bc, zero, x, n);
    if (g < -tol)
      return pm_scene_fail(
          s,
          PM_PATH(p, "boundary.%d.%s", c->bc[b],
                  bc->on == PM_ON_PLATE ? "plate" : "sphere"),
          false,
          "expected a rigid body outside the body at t = 0, got point %ld at "
          "(%g, %g, %g) %g m inside it (the tolerance is 1e-3 mesh_size)",
          fpm_point_id(m, i), x[0], x[1], x[2], -g);
  }
  return PM_SUCCESS;
}

/* The anchors at rest (3 per pair): a glued body's points on its surface
 * at t = 0 (gap at most 1e-9 mesh_size) held where they are from the
 * start, as a face tied to it; NaN for the rest (apart, or not glued). */
static void start_anchors(const fpm_model *m, fpm_contact *c) {
  const double zero[3] = {0, 0, 0}, tol = 1e-9 * m->scene->mesh_size;
  for (long q = 0; q < 3 * c->pair_ptr[c->n_bodies]; q++) c->anchor0[q] = NAN;
  for (int b = 0; b < c->n_bodies; b++) {
    const pm_scene_bc *bc = &m->scene->bcs[c->bc[b]];
    if (bc->contact != PM_CONTACT_GLUED) continue;
    for (long q = c->pair_ptr[b]; q < c->pair_ptr[b + 1]; q++) {
      const double *x = m->x + 3 * c->pair_point[q];
      double n[3];
      const double g = pm_rigid_gap(bc, zero, x, n);
      if (g > tol) continue;
      for (int a = 0; a < 3; a++) c->anchor0[3 * q + a] = x[a] - g * n[a];
    }
  }
}

pm_err fpm_contact_create(const fpm_model *m, const pm_scene *s,
                          fpm_contact **out) {
  pm_err ret = PM_SUCCESS;
  fpm_contact *c = NULL;
  double *area = NULL;
  *out = NULL;
  int nb = 0;
  for (int b = 0; b < s->n_bcs; b++) nb += PM_BC_RIGID(&s->bcs[b]);
  if (nb == 0) return PM_SUCCESS;
  const gm_dual *d = m->dual;
  PM_TRY(PM_ALLOC(c, 1, "contact"));
  PM_TRY(PM_ALLOC(area, m->n, "contact areas"));
  boundary_areas(d, area);
  long nbp = 0;
  for (long i = 0; i < m->n_own; i++) nbp += area[i] > 0;
  c->n_bodies = nb;
  PM_TRY(PM_ALLOC(c->bc, nb, "contact bodies"));
  PM_TRY(PM_ALLOC(c->pair_ptr, nb + 1, "contact pairs"));
  PM_TRY(PM_ALLOC(c->pair_point, nb * nbp, "contact pairs"));
  PM_TRY(PM_ALLOC(c->pair_k, nb * nbp, "contact pairs"));
  PM_TRY(PM_ALLOC(c->anchor0, 3 * nb * nbp, "contact anchors"));
  long q = 0;
  for (int b = 0, k = 0; b < s->n_bcs; b++) {
    const pm_scene_bc *bc = &s->bcs[b];
    if (!PM_BC_RIGID(bc)) continue;
    c->bc[k] = b;
    c->pair_ptr[k] = q;
    for (long i = 0; i < m->n_own; i++) {
      if (!(area[i] > 0)) continue;
      const double E = m->mats[m->mat[i]].youngs_modulus;
      c->pair_point[q] = i;
      c->pair_k[q] = bc->contact_penalty * E * area[i] / s->mesh_size;
      c->max_k_over_m = fmax(c->max_k_over_m, c->pair_k[q] / m->mass[i]);
      q++;
    }
    c->pair_ptr[++k] = q;
  }
  for (int b = 0; b < nb; b++) PM_TRY(check_start(m, c, b));
  start_anchors(m, c);
  *out = c;
  c = NULL;
done:
  free(area);
  fpm_contact_destroy(c);
  return ret;
}

pm_err fpm_contact_refuse_ranks(const pm_scene *s) {
  char p[64];
  for (int b = 0; b < s->n_bcs; b++)
    if (PM_BC_RIGID(&s->bcs[b]))
      return pm_scene_fail(
          s,
          PM_PATH(p, "boundary.%d.%s", b,
                  s->bcs[b].on == PM_ON_PLATE ? "plate" : "sphere"),
          true, "contact needs one process for now, got a run across ranks");
  return PM_SUCCESS;
}

void fpm_contact_destroy(fpm_contact *c) {
  if (!c) return;
  free(c->bc);
  free(c->pair_ptr);
  free(c->pair_point);
  free(c->pair_k);
  free(c->anchor0);
  free(c);
}

/* The rigid bodies' forces at time t (displacements times scale) added to
 * st->f, the reactions and energy kept in st->contact and the energy added
 * to st->penalty_energy; returns |F|^2.  fixed: the anchors are read, not
 * written (a sticking point without one is pushed along the normal). */
static double bodies_force(const fpm_model *m, fpm_state *st, double t,
                           double scale, bool fixed) {
  const fpm_contact *c = m->contact;
  double *restrict S = st->contact, *restrict f = st->f;
  const double *restrict u = st->u, *restrict x = m->x;
  double energy = 0, fsq = 0;
  for (int b = 0; b < c->n_bodies; b++) {
    const pm_scene_bc *bc = &m->scene->bcs[c->bc[b]];
    const long *restrict pt = c->pair_point;
    const double *restrict kq = c->pair_k;
    const long q0 = c->pair_ptr[b], q1 = c->pair_ptr[b + 1];
    double d[3], rx = 0, ry = 0, rz = 0, e = 0, s2 = 0;
    body_displacement(bc, t, scale, d);
    PM_OMP(parallel for schedule(static) default(none)
           reduction(+ : rx, ry, rz, e, s2)
           shared(q0, q1, pt, kq, S, f, u, x, bc, d, fixed))
    for (long q = q0; q < q1; q++) {
      const long i = pt[q];
      double xi[3], F[3], ei, n[3];
      for (int a = 0; a < 3; a++) xi[a] = x[3 * i + a] + u[3 * i + a];
      if (fixed) {
        const double g = pm_rigid_gap(bc, d, xi, n);
        if (!touching_fixed(g, S + 3 * q)) continue;
        const double *anchor = isnan(S[3 * q]) ? NULL : S + 3 * q;
        ei = touch_force(kq[q], d, xi, g, n, anchor, F);
      } else if (!fpm_contact_point(bc, kq[q], d, xi, S + 3 * q, F, &ei)) {
        continue;
      }
      for (int a = 0; a < 3; a++) f[3 * i + a] -= F[a];
      rx += F[0];
      ry += F[1];
      rz += F[2];
      e += ei;
      s2 += F[0] * F[0] + F[1] * F[1] + F[2] * F[2];
    }
    double *R = S + ST_BODY(c, b);
    R[0] = rx;
    R[1] = ry;
    R[2] = rz;
    energy += e;
    fsq += s2;
  }
  S[ST_BODY(c, c->n_bodies)] = energy;
  st->penalty_energy += energy;
  return fsq;
}

void fpm_contact_force(const fpm_model *m, fpm_state *st, double t) {
  if (!m->contact) return;
  st->fext_sq += bodies_force(m, st, t, 1, false);
  st->fext_norm = sqrt(st->fext_sq);
}

void fpm_contact_start_scaled(const fpm_model *m, fpm_state *st, double t,
                              double scale) {
  const fpm_contact *c = m->contact;
  if (!c) return;
  for (int b = 0; b < c->n_bodies; b++) {
    double *B = st->contact + ST_BODY(c, b);
    memcpy(B + 3, B, 3 * sizeof(double));
    body_displacement(&m->scene->bcs[c->bc[b]], t, scale, B + 6);
  }
}

void fpm_contact_start(const fpm_model *m, fpm_state *st, double t) {
  fpm_contact_start_scaled(m, st, t, 1);
}

double fpm_contact_work_scaled(const fpm_model *m, fpm_state *st, double t,
                               double scale) {
  const fpm_contact *c = m->contact;
  if (!c) return 0;
  double work = 0;
  for (int b = 0; b < c->n_bodies; b++) {
    double *B = st->contact + ST_BODY(c, b), d[3];
    body_displacement(&m->scene->bcs[c->bc[b]], t, scale, d);
    for (int a = 0; a < 3; a++) {
      work += 0.5 * (B[3 + a] + B[a]) * (d[a] - B[6 + a]);
      B[3 + a] = B[a];
      B[6 + a] = d[a];
    }
  }
  return work;
}

double fpm_contact_work(const fpm_model *m, fpm_state *st, double t) {
  return fpm_contact_work_scaled(m, st, t, 1);
}

void fpm_contact_reaction(const fpm_model *m, const fpm_state *st, int b,
                          double R[3]) {
  const fpm_contact *c = m->contact;
  if (!c) return;
  for (int k = 0; k < c->n_bodies; k++)
    if (c->bc[k] == b)
      for (int a = 0; a < 3; a++) R[a] += st->contact[ST_BODY(c, k) + a];
}

double fpm_contact_stable_dt(const fpm_contact *c, double dt) {
  if (!c || !(c->max_k_over_m > 0)) return dt;
  return 2 / sqrt(4 / (dt * dt) + c->max_k_over_m);
}

/* ---- static solves: the bodies at scale d(t), anchors held fixed ---- */

double fpm_contact_force_fixed(const fpm_model *m, fpm_state *st, double t,
                               double scale) {
  return m->contact ? bodies_force(m, st, t, scale, true) : 0;
}

void fpm_contact_tangent_fixed(const fpm_model *m, const fpm_state *st,
                               double t, double scale, double *K) {
  const fpm_contact *c = m->contact;
  if (!c) return;
  memset(K, 0, 9 * (size_t)m->n_own * sizeof(double));
  const double *restrict S = st->contact, *restrict u = st->u,
                         *restrict x = m->x;
  for (int b = 0; b < c->n_bodies; b++) {
    const pm_scene_bc *bc = &m->scene->bcs[c->bc[b]];
    const long *restrict pt = c->pair_point;
    const double *restrict kq = c->pair_k;
    const long q0 = c->pair_ptr[b], q1 = c->pair_ptr[b + 1];
    double d[3];
    body_displacement(bc, t, scale, d);
    /* (a point is one pair of each body: no two threads share a block) */
    PM_OMP(parallel for schedule(static) default(none)
           shared(q0, q1, pt, kq, S, u, x, bc, d, K))
    for (long q = q0; q < q1; q++) {
      const long i = pt[q];
      double xi[3], n[3], Kq[9];
      for (int a = 0; a < 3; a++) xi[a] = x[3 * i + a] + u[3 * i + a];
      const double g = pm_rigid_gap(bc, d, xi, n);
      if (!touching_fixed(g, S + 3 * q)) continue;
      touch_tangent(bc, kq[q], g, n, !isnan(S[3 * q]), Kq);
      for (int a = 0; a < 9; a++) K[9 * i + a] += Kq[a];
    }
  }
}

/* Body b of a static solve's contact when it is sticking or glued (NULL if
 * frictionless),
 * with its displacement d at t times scale. */
static const pm_scene_bc *sticking_body(const fpm_model *m, int b, double t,
                                        double scale, double d[3]) {
  const pm_scene_bc *bc = &m->scene->bcs[m->contact->bc[b]];
  if (bc->contact == PM_CONTACT_FRICTIONLESS) return NULL;
  body_displacement(bc, t, scale, d);
  return bc;
}

/* The gap of pair q's point (at xi, the normal into n) to body bc at d. */
static double pair_gap(const fpm_model *m, const fpm_state *st,
                       const pm_scene_bc *bc, const double d[3], long q,
                       double xi[3], double n[3]) {
  const long i = m->contact->pair_point[q];
  for (int a = 0; a < 3; a++) xi[a] = m->x[3 * i + a] + st->u[3 * i + a];
  return pm_rigid_gap(bc, d, xi, n);
}

/* The static solve's updates of the sticking set (anchors and releases,
 * fpm_contact_commit, fpm_contact_touch_fixed, fpm_contact_release_fixed). */
typedef enum { SET_COMMIT, SET_TOUCH, SET_RELEASE } set_update;

/* One pass of an update over the sticking pairs: COMMIT anchors the points
 * touching (gap at most 1e-9 h) without an anchor and lets go those above;
 * TOUCH anchors the penetrating ones without an anchor; RELEASE lets go
 * the anchored points pulled off (let_go: the marks of those let go in
 * the attempt; out: what was done).  Returns how many changed. */
static long update_set(const fpm_model *m, fpm_state *st, double t,
                       double scale, set_update mode, unsigned char *let_go,
                       fpm_contact_release *out) {
  const fpm_contact *c = m->contact;
  if (!c) return 0;
  const double tol = 1e-9 * m->scene->mesh_size;
  long changed = 0;
  for (int b = 0; b < c->n_bodies; b++) {
    double d[3], xi[3], n[3];
    const pm_scene_bc *bc = sticking_body(m, b, t, scale, d);
    if (!bc) continue;
    const bool glued = bc->contact == PM_CONTACT_GLUED;
    for (long q = c->pair_ptr[b]; q < c->pair_ptr[b + 1]; q++) {
      double *A = st->contact + 3 * q;
      const bool loose = isnan(A[0]); /* no anchor */
      if ((mode == SET_TOUCH && !loose) || (mode == SET_RELEASE && loose))
        continue;
      const double g = pair_gap(m, st, bc, d, q, xi, n);
      const bool off = g > tol;
      if (mode == SET_COMMIT ? !off && loose : mode == SET_TOUCH && g < 0) {
        /* the surface point under it: x - d - A = g n, so the sticking
         * force -k (x - d - A) is the normal push -k g n it had: the
         * residual at this state is unchanged */
        for (int a = 0; a < 3; a++) A[a] = xi[a] - d[a] - g * n[a];
        changed++;
        continue;
      }
      /* a glued point is never let go: it is pulled as well as pushed */
      if (mode == SET_TOUCH || !off || loose || glued) continue;
      const long i = c->pair_point[q];
      if (mode == SET_RELEASE && let_go[q]) { /* it grazes: held */
        out->frozen++;
        if (g > out->frozen_gap) out->frozen_first = i, out->frozen_gap = g;
        continue;
      }
      A[0] = A[1] = A[2] = NAN;
      changed++;
      if (mode == SET_COMMIT) continue;
      let_go[q] = 1;
      if (g > out->first_gap) out->first = i, out->first_gap = g;
    }
  }
  return changed;
}

void fpm_contact_commit(const fpm_model *m, fpm_state *st, double t,
                        double scale) {
  update_set(m, st, t, scale, SET_COMMIT, NULL, NULL);
}

/* ---- static solves: the sticking set between Newton iterations ---- */

long fpm_contact_touch_fixed(const fpm_model *m, fpm_state *st, double t,
                             double scale) {
  return update_set(m, st, t, scale, SET_TOUCH, NULL, NULL);
}

long fpm_contact_release_fixed(const fpm_model *m, fpm_state *st, double t,
                               double scale, unsigned char *let_go,
                               fpm_contact_release *out) {
  *out = (fpm_contact_release){.first = -1, .frozen_first = -1};
  return update_set(m, st, t, scale, SET_RELEASE, let_go, out);
}
