/* pm_tensor: 3x3 tensors as row-major double[9] and 3-vectors as double[3];
 * small inline helpers with no heap. */
#ifndef PM_TENSOR_H
#define PM_TENSOR_H

#include <math.h>
#include <string.h>

static inline void pm_t_identity(double A[9]) {
  memset(A, 0, 9 * sizeof(double));
  A[0] = A[4] = A[8] = 1.0;
}
static inline void pm_t_zero(double A[9]) { memset(A, 0, 9 * sizeof(double)); }
static inline void pm_t_copy(const double A[9], double B[9]) {
  memcpy(B, A, 9 * sizeof(double));
}
static inline double pm_t_trace(const double A[9]) {
  return A[0] + A[4] + A[8];
}
static inline double pm_t_ddot(const double A[9], const double B[9]) {
  double s = 0;
  for (int i = 0; i < 9; i++) s += A[i] * B[i];
  return s;
}
static inline double pm_t_det(const double A[9]) {
  return A[0] * (A[4] * A[8] - A[5] * A[7]) -
         A[1] * (A[3] * A[8] - A[5] * A[6]) +
         A[2] * (A[3] * A[7] - A[4] * A[6]);
}
/* det(I + H) - 1 without cancellation for small H. */
static inline double pm_t_det_minus_one(const double H[9]) {
  double tr = pm_t_trace(H);
  double trH2 = 0;
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) trH2 += H[3 * i + k] * H[3 * k + i];
  return tr + 0.5 * (tr * tr - trH2) + pm_t_det(H);
}
/* Cofactor matrix cof(A) = det(A) A^-T. */
static inline void pm_t_cofactor(const double A[9], double C[9]) {
  C[0] = A[4] * A[8] - A[5] * A[7];
  C[1] = A[5] * A[6] - A[3] * A[8];
  C[2] = A[3] * A[7] - A[4] * A[6];
  C[3] = A[2] * A[7] - A[1] * A[8];
  C[4] = A[0] * A[8] - A[2] * A[6];
  C[5] = A[1] * A[6] - A[0] * A[7];
  C[6] = A[1] * A[5] - A[2] * A[4];
  C[7] = A[2] * A[3] - A[0] * A[5];
  C[8] = A[0] * A[4] - A[1] * A[3];
}
/* B = A^-1; returns det(A) (B is unspecified when it is 0). */
static inline double pm_t_inverse(const double A[9], double B[9]) {
  double C[9];
  pm_t_cofactor(A, C);
  double d = A[0] * C[0] + A[1] * C[1] + A[2] * C[2];
  double id = 1.0 / d;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) B[3 * i + j] = C[3 * j + i] * id;
  return d;
}
static inline void pm_t_transpose(const double A[9], double B[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) B[3 * i + j] = A[3 * j + i];
}
/* C = A B */
static inline void pm_t_mul(const double A[9], const double B[9], double C[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      C[3 * i + j] =
          A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}
/* C = A^T B */
static inline void pm_t_tmul(const double A[9], const double B[9],
                             double C[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      C[3 * i + j] = A[i] * B[j] + A[3 + i] * B[3 + j] + A[6 + i] * B[6 + j];
}
/* C = A B^T */
static inline void pm_t_mult(const double A[9], const double B[9],
                             double C[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      C[3 * i + j] = A[3 * i] * B[3 * j] + A[3 * i + 1] * B[3 * j + 1] +
                     A[3 * i + 2] * B[3 * j + 2];
}
/* D = A - tr(A)/3 I, the deviator */
static inline void pm_t_dev(const double A[9], double D[9]) {
  double p = pm_t_trace(A) / 3;
  for (int i = 0; i < 9; i++) D[i] = A[i] - (i % 4 == 0 ? p : 0);
}
/* y = A x */
static inline void pm_t_mulv(const double A[9], const double x[3],
                             double y[3]) {
  for (int i = 0; i < 3; i++)
    y[i] = A[3 * i] * x[0] + A[3 * i + 1] * x[1] + A[3 * i + 2] * x[2];
}
/* A += s a (x) b */
static inline void pm_t_add_outer(double A[9], double s, const double a[3],
                                  const double b[3]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) A[3 * i + j] += s * a[i] * b[j];
}
static inline double pm_t_norm(const double A[9]) {
  return sqrt(pm_t_ddot(A, A));
}
static inline double pm_v_dot(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline double pm_v_norm(const double a[3]) {
  return sqrt(pm_v_dot(a, a));
}
static inline void pm_v_cross(const double a[3], const double b[3],
                              double c[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
/* Rotation about a unit axis by angle (radians), row-major. */
static inline void pm_t_rotation(const double axis[3], double angle,
                                 double R[9]) {
  double c = cos(angle), s = sin(angle), t = 1 - c;
  double x = axis[0], y = axis[1], z = axis[2];
  R[0] = t * x * x + c;
  R[1] = t * x * y - s * z;
  R[2] = t * x * z + s * y;
  R[3] = t * x * y + s * z;
  R[4] = t * y * y + c;
  R[5] = t * y * z - s * x;
  R[6] = t * x * z - s * y;
  R[7] = t * y * z + s * x;
  R[8] = t * z * z + c;
}

/* Von Mises equivalent of a symmetric stress: sqrt(3/2 s:s), s the
 * deviator. */
static inline double pm_t_von_mises(const double S[9]) {
  double p = (S[0] + S[4] + S[8]) / 3;
  double a = S[0] - p, b = S[4] - p, c = S[8] - p;
  double sh = S[1] * S[1] + S[2] * S[2] + S[5] * S[5];
  return sqrt(1.5 * (a * a + b * b + c * c + 2 * sh));
}

#endif
