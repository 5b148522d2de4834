/* fpm_penalty_terms: the state-dependent interface penalties of the flux
 * pass (fpm.stiffening on either jump, fpm.volume_penalty): their forces,
 * energies and exact linearisations, inlined into fpm_force's passes. */
#ifndef FPM_PENALTY_TERMS_H
#define FPM_PENALTY_TERMS_H

#include <math.h>

#include "fpm_gfd.h"
#include "fpm_model.h"
#include "pm_tensor.h"

/* theta (3 x FPM_QFIT) applied to phi: the fit's increment at an offset. */
static inline double fpm_fit_at(const double *theta, int c, const double *phi) {
  const double *t = theta + FPM_QFIT * c;
  double v = 0;
  for (int a = 0; a < FPM_QFIT; a++) v += t[a] * phi[a];
  return v;
}

/* The jump of the quadratic fits: u_i + theta_i phi_i - u_k - theta_k
 * phi_k. */
static inline void fpm_quad_jump(const double *ui, const double *uk,
                                 const double *thi, const double *thk,
                                 const double *phi_i, const double *phi_k,
                                 double *j) {
  for (int c = 0; c < 3; c++)
    j[c] =
        ui[c] - uk[c] + fpm_fit_at(thi, c, phi_i) - fpm_fit_at(thk, c, phi_k);
}

/* The stiffening on jump j: the energy c phi / 4 with s = |j|^2,
 * g = s - t2 and phi = g^3 / s for g > 0, 0 below (phi = g^3 / (g + t2)
 * as a function of g).  t2 = 0 gives the quartic c |j|^4 / 4, and with
 * t2 > 0 phi is twice differentiable at the onset (phi' = phi'' = 0
 * there), so the force and its derivative are continuous.  The onset:
 * with dc NULL, t2 = tau2, fixed ((tau h)^2, fpm.stiffening_spacing:
 * reference); else t2 = tau2 |dc|^2 with dc = x_k + u_k - x_i - u_i the
 * points' deformed distance (seen from i; current), whose derivative
 * dE/ddc = c phi_t tau2 dc / 2 it adds to *sd.  Adds dE/dj = c phi_s j / 2
 * to *s and returns the entry's energy share c phi / 8 (each interface is
 * seen twice).  Linearised (j0, dc0 the base's, j, dc the increments):
 * adds the second derivatives along (j, dc) to *s (and *sd), returns 0. */
static inline double fpm_stiffen(double c, double tau2, const double *j,
                                 const double *j0, const double *dc,
                                 const double *dc0, double *s, double *sd) {
  const double *jb = j0 ? j0 : j, *db = dc0 ? dc0 : dc;
  const double q = pm_v_dot(jb, jb), t2 = db ? tau2 * pm_v_dot(db, db) : tau2;
  const double g = q - t2;
  if (g <= 0) return 0;
  const double x = g / q; /* g / s in (0, 1] */
  const double ps = g * x * (3 - x), pt = -3 * g * x;
  if (j0) {
    const double pss = x * (6 - 6 * x + 2 * x * x), pst = x * (3 * x - 6),
                 ptt = 6 * x;
    const double jd = pm_v_dot(j0, j), dd = dc ? tau2 * pm_v_dot(dc0, dc) : 0;
    const double aj = pss * jd + pst * dd, ad = pst * jd + ptt * dd;
    for (int a = 0; a < 3; a++) {
      s[a] += 0.5 * c * (ps * j[a] + 2 * aj * j0[a]);
      if (dc) sd[a] += 0.5 * c * tau2 * (pt * dc[a] + 2 * ad * dc0[a]);
    }
    return 0;
  }
  for (int a = 0; a < 3; a++) {
    s[a] += 0.5 * c * ps * j[a];
    if (dc) sd[a] += 0.5 * c * tau2 * pt * dc[a];
  }
  return 0.125 * c * g * g * x;
}

/* The stiffening's second derivative in the jump at j0 (onset t2, as
 * fpm_stiffen's), into the 3 x 3 block A: c (phi_s I + 2 phi_ss j0 (x)
 * j0) / 2 (with fpm.stiffening_spacing: current the onset's own
 * derivative left out), for the assembled tangent (its S's blocks), so
 * that it preconditions the exact linearisation closely; 0 below the
 * onset. */
static inline void fpm_stiffen_block(double c, double t2, const double *j0,
                                     double *A) {
  const double q = pm_v_dot(j0, j0), g = q - t2;
  for (int a = 0; a < 9; a++) A[a] = 0;
  if (g <= 0) return;
  const double x = g / q;
  const double ps = g * x * (3 - x), pss = x * (6 - 6 * x + 2 * x * x);
  for (int a = 0; a < 3; a++) {
    A[4 * a] += 0.5 * c * ps;
    for (int b = 0; b < 3; b++) A[3 * a + b] += c * pss * j0[a] * j0[b];
  }
}

/* The stiffening of entry (i, k) on jump j (j0: the base's when
 * linearised): fpm_stiffen with the onset t2 = (tau h_e)^2 of the record,
 * or with fpm.stiffening_spacing: current with its onset on the
 * points' deformed distance dc = d_i - d_k + u_k - u_i (the base's from bu
 * when bui is not NULL, u then the increments), whose derivative it adds
 * to *sd.  Returns the entry's energy share (0 linearised). */
static inline double fpm_stiffen_entry(const fpm_model *m, double c, double t2,
                                       const double *j, const double *j0,
                                       const double *ui, const double *uk,
                                       const double *bui, const double *buk,
                                       const double *di, const double *dk,
                                       double *s, double *sd) {
  if (!m->stiffen_current)
    return fpm_stiffen(c, t2, j, j0, NULL, NULL, s, NULL);
  double dc[3], dc0[3];
  for (int a = 0; a < 3; a++) {
    dc[a] = bui ? uk[a] - ui[a] : di[a] - dk[a] + uk[a] - ui[a];
    dc0[a] = bui ? di[a] - dk[a] + buk[a] - bui[a] : dc[a];
  }
  const double tau2 = m->stiffening_onset * m->stiffening_onset;
  return fpm_stiffen(c, tau2, j, j0, dc, bui ? dc0 : NULL, s, sd);
}

/* The volume penalty of one entry (i, k) on the linear jump j: the energy
 * 1/2 c phi_e |j|^2 with phi_e = (phi_i + phi_k) / 2, phi = (ln J)^2.  Adds
 * its force c phi_e j to s, the weight 1/4 c |j|^2 of dphi_i / dF_i to *a
 * (the derivative through point i's own J, fpm_volume_flux) and returns the
 * energy share 1/4 c phi_e |j|^2.  Linearised (j0 the base's jump, j the
 * increment, dphi_i + dphi_k = dsum): adds c (phi_e j + dsum / 2 j0) to s,
 * 1/2 c j0 . j to *da, 1/4 c |j0|^2 to *a, and returns 0. */
static inline double fpm_volume_entry(double c, double phi_i, double phi_k,
                                      const double *j, const double *j0,
                                      double dsum, double *s, double *a,
                                      double *da) {
  const double pe = 0.5 * (phi_i + phi_k);
  if (j0) {
    for (int q = 0; q < 3; q++) s[q] += c * (pe * j[q] + 0.5 * dsum * j0[q]);
    *da += 0.5 * c * pm_v_dot(j0, j);
    *a += 0.25 * c * pm_v_dot(j0, j0);
    return 0;
  }
  const double jj = pm_v_dot(j, j);
  for (int q = 0; q < 3; q++) s[q] += c * pe * j[q];
  *a += 0.25 * c * jj;
  return 0.25 * c * pe * jj;
}

/* The volume penalty's flux through point i's J (F = I + Hb, the state's
 * or the base's): T += a dphi/dF with dphi/dF = 2 ln J F^-T; linearised
 * along dH (not NULL): T += da dphi/dF + a d2phi/dF2 [dH], with d2phi/dF2
 * [dH] = 2 (G : dH) G - 2 ln J G dH^T G, G = F^-T. */
static inline void fpm_volume_flux(const double *Hb, const double *dH, double a,
                                   double da, double *T) {
  double F[9], G[9];
  for (int q = 0; q < 9; q++) F[q] = Hb[q];
  F[0] += 1;
  F[4] += 1;
  F[8] += 1;
  pm_t_cofactor(F, G);
  const double J = pm_t_det(F), l = log(J);
  for (int q = 0; q < 9; q++) G[q] /= J;
  const double w = dH ? da : a;
  for (int q = 0; q < 9; q++) T[q] += 2 * w * l * G[q];
  if (!dH) return;
  double GdT[9], M[9]; /* G dH^T, then G dH^T G */
  pm_t_mult(G, dH, GdT);
  pm_t_mul(GdT, G, M);
  const double gd = pm_t_ddot(G, dH);
  for (int q = 0; q < 9; q++) T[q] += 2 * a * (gd * G[q] - l * M[q]);
}

/* phi_i = (ln J_i)^2 of the points [0, n) from their J (the force),
 * shared by the team of the enclosing parallel region (no barrier after). */
void fpm_volume_phi(long n, const double *J, double *phi);

/* The base's phi_i and the increments dphi_i = 2 ln J_i F_i^-T : dH_i of
 * the points [0, n) (F = I + bH; phi NULL: only dphi). */
void fpm_volume_dphi(long n, const double *bH, const double *dH, double *phi,
                     double *dphi);

#endif
