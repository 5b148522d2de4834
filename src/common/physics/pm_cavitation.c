/* pm_cavitation: the void's branch of an isotropic solid under hydrostatic
 * tension, by shooting (pm_cavitation.h). */
#include "pm_cavitation.h"

#include <math.h>
#include <stdbool.h>

/* P of F = diag(l1, l, l): dW/dlambda_r into *p1, the two hoop
 * derivatives' sum into *p23 (either may be NULL), and dP_11 / dl1 into
 * *d1 where d1 is not NULL. */
static bool principal(const pm_material *m, double l1, double l, double *p1,
                      double *p23, double *d1) {
  const double F[9] = {l1, 0, 0, 0, l, 0, 0, 0, l};
  double P[9];
  if (!pm_material_stress(m, F, NULL, P, NULL, NULL)) return false;
  if (p1) *p1 = P[0];
  if (p23) *p23 = P[4] + P[8];
  if (d1) {
    const double dF[9] = {1, 0, 0, 0, 0, 0, 0, 0, 0};
    double dP[9];
    if (!pm_material_tangent(m, F, NULL, dF, dP)) return false;
    *d1 = dP[0];
  }
  return isfinite(P[0]) && isfinite(P[4]) && isfinite(P[8]);
}

/* The sign of dW/dlambda_r(x, l) - t: a stress the model cannot give is
 * taken as compression's below (x tiny) and tension's above. */
static double residual(const pm_material *m, double x, double l, double t,
                       bool below) {
  double p1;
  if (!principal(m, x, l, &p1, NULL, NULL)) return below ? -INFINITY : INFINITY;
  return p1 - t;
}

/* The radial stretch x with dW/dlambda_r(x, l) = t (it grows with x):
 * bracketed outward from *out (the last one found: the next is near it;
 * 1 where none), then Newton's steps kept inside the bracket. */
static bool radial_stretch(const pm_material *m, double l, double t,
                           double *out) {
  const double x0 = *out > 0 && isfinite(*out) ? *out : 1;
  double lo = x0, hi = x0;
  while (residual(m, hi, l, t, false) < 0)
    if ((hi *= 2) > 1e30) return false;
  while (residual(m, lo, l, t, true) > 0)
    if ((lo /= 2) < 1e-300) return false;
  if (lo == hi) {
    *out = x0;
    return true;
  }
  double x = hi / lo > 4 ? sqrt(lo * hi) : 0.5 * (lo + hi);
  for (int it = 0; it < 100; it++) {
    double p1, d1;
    if (!principal(m, x, l, &p1, NULL, &d1)) {
      x = hi / lo > 4 ? sqrt(lo * hi) : 0.5 * (lo + hi);
      continue;
    }
    const double f = p1 - t;
    if (f < 0)
      lo = x;
    else
      hi = x;
    if (f == 0 || hi - lo <= 4e-16 * x) break;
    double next = x - f / d1;
    if (!(d1 > 0) || !(next > lo && next < hi))
      next = hi / lo > 4 ? sqrt(lo * hi) : 0.5 * (lo + hi);
    if (fabs(next - x) <= 1e-15 * x) {
      x = next;
      break;
    }
    x = next;
  }
  *out = x;
  return isfinite(x) && x > 0;
}

/* d(r, q)/ds at s = ln R; *l1: the radial stretch there (in: the last). */
static bool rhs(const pm_material *m, double s, const double y[2], double dy[2],
                double *l1) {
  const double R = exp(s), l = y[0] / R;
  double p23;
  if (!(l > 0) || !radial_stretch(m, l, y[1] / (R * R), l1)) return false;
  if (!principal(m, *l1, l, NULL, &p23, NULL)) return false;
  dy[0] = R * *l1;
  dy[1] = R * R * p23;
  return isfinite(dy[0]) && isfinite(dy[1]);
}

/* Dormand and Prince's pair: nodes, the stages' weights, the fifth-order
 * weights and the error's (fifth minus fourth). */
static const double C[7] = {0, 1. / 5, 3. / 10, 4. / 5, 8. / 9, 1, 1};
static const double A[7][6] = {
    {0},
    {1. / 5},
    {3. / 40, 9. / 40},
    {44. / 45, -56. / 15, 32. / 9},
    {19372. / 6561, -25360. / 2187, 64448. / 6561, -212. / 729},
    {9017. / 3168, -355. / 33, 46732. / 5247, 49. / 176, -5103. / 18656},
    {35. / 384, 0, 500. / 1113, 125. / 192, -2187. / 6784, 11. / 84}};
static const double E[7] = {
    71. / 57600,      0,         -71. / 16695, 71. / 1920,
    -17253. / 339200, 22. / 525, -1. / 40};

double pm_cavitation_tension(const pm_material *m, double a, double c) {
  if (pm_material_is_fluid(m) || m->state_size > 0 || !(a > 0) || !(c > a) ||
      !(c < 1))
    return NAN;
  const double rtol = 1e-11, atol[2] = {1e-18, 1e-18 * m->shear_modulus};
  double s = log(a), h = 1e-3, y[2] = {c, 0}, k[7][2], l1 = 0;
  const double end = 0; /* ln B, B = 1 */
  if (!rhs(m, s, y, k[0], &l1)) return NAN;
  for (long step = 0; step < 20000 && s < end; step++) {
    if (s + h > end) h = end - s;
    double yt[2], err = 0;
    bool ok = true;
    for (int st = 1; st < 7 && ok; st++) {
      for (int i = 0; i < 2; i++) {
        double sum = 0;
        for (int j = 0; j < st; j++) sum += A[st][j] * k[j][i];
        yt[i] = y[i] + h * sum;
      }
      ok = rhs(m, s + C[st] * h, yt, k[st], &l1);
    }
    if (ok)
      for (int i = 0; i < 2; i++) {
        double e = 0;
        for (int j = 0; j < 7; j++) e += E[j] * k[j][i];
        const double sc = atol[i] + rtol * fmax(fabs(y[i]), fabs(yt[i]));
        err = fmax(err, fabs(h * e) / sc);
      }
    if (!ok || !isfinite(err) || err > 1) {
      h *= ok && isfinite(err) ? fmax(0.2, 0.9 * pow(err, -0.2)) : 0.25;
      if (h < 1e-14) return NAN;
      continue;
    }
    s += h;
    y[0] = yt[0];
    y[1] = yt[1];
    k[0][0] = k[6][0]; /* the last stage is the next step's first */
    k[0][1] = k[6][1];
    h *= err > 0 ? fmin(5, 0.9 * pow(err, -0.2)) : 5;
  }
  if (s < end) return NAN;
  /* The radial Cauchy stress at R = 1: P_11 lambda_r / J = P_11 / l^2. */
  double p1;
  const double l = y[0];
  if (!radial_stretch(m, l, y[1], &l1) || !principal(m, l1, l, &p1, NULL, NULL))
    return NAN;
  return p1 / (l * l);
}

double pm_cavitation_load(const pm_material *m) {
  return pm_cavitation_tension(m, 1e-13, 1e-4);
}
