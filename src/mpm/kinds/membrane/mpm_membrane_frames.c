/* mpm_membrane_frames: a membrane point's frame (e1, e2 in the tangent
 * plane, n the normal): made from a normal, and carried over a step by
 * the in-plane spin and the rotation S of eqs. 9-22. */
#include <math.h>
#include <string.h>

#include "mpm_membrane_impl.h"

/* e1, e2 in the plane of n: e1 from the axis least aligned with n. */
void mpm_membrane_frame_from_normal(const double n[3], double f[9]) {
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
    mpm_membrane_frame_from_normal(n1, f);
    return;
  }
  for (int i = 0; i < 3; i++) e1[i] = a[i] / len;
  pm_v_cross(n1, e1, b);
  memcpy(e2, b, sizeof b);
  memcpy(n0, n1, 3 * sizeof(double));
}
