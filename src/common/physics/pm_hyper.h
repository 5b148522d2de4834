/* pm_hyper: the pieces the hyperelastic entries of the table share, written
 * once: kinematics formed from H = F - I, the isochoric invariants Ibar1,
 * Ibar2, Ibar4 with their first and second derivatives in F, and the
 * volumetric terms K/2 (J - 1)^2 and K/2 (ln J)^2.  Values are formed so
 * that they keep their relative accuracy as F -> I.
 *
 * Notation: G = F^-T, cof F = J G, b = F F^T, B = b - I.  An isochoric
 * invariant Ibar = J^-m I has the P-shaped derivative
 *   D = dIbar/dF = J^-m (g - m I G),  g = dI/dF,
 * and along dF (dG = -G dF^T G, dJ = J G : dF)
 *   dD = -m (G : dF) D + J^-m (dg - m (g : dF) G + m I G dF^T G). */
#ifndef PM_HYPER_H
#define PM_HYPER_H

#include <math.h>
#include <stdbool.h>

#include "pm_material.h"
#include "pm_models.h"

/* ---- kinematics ---------------------------------------------------------- */

typedef struct {
  const double *F;
  double H[9];   /* F - I */
  double B[9];   /* b - I = H + H^T + H H^T */
  double J, Jm1; /* J and J - 1 (from H, no cancellation) */
  double lnJ;    /* log1p(J - 1) */
  double Jm23;   /* J^-2/3 */
  double cof[9]; /* cof F = J F^-T */
  double G[9];   /* F^-T */
} pm_hyper_kin;

/* The kinematics of F (kept by pointer: F must outlive k), and J into *J
 * when J is not NULL.  False when J <= 0. */
static inline bool pm_hyper_kinematics(const double F[9], pm_hyper_kin *k,
                                       double *J) {
  k->F = F;
  for (int i = 0; i < 9; i++) k->H[i] = F[i] - (i % 4 == 0);
  k->Jm1 = pm_t_det_minus_one(k->H);
  k->J = 1 + k->Jm1;
  if (J) *J = k->J;
  if (!(k->J > 0)) return false;
  k->lnJ = log1p(k->Jm1);
  k->Jm23 = exp(-2.0 / 3.0 * k->lnJ);
  pm_t_cofactor(F, k->cof);
  for (int i = 0; i < 9; i++) k->G[i] = k->cof[i] / k->J;
  pm_t_mult(k->H, k->H, k->B);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      k->B[3 * i + j] += k->H[3 * i + j] + k->H[3 * j + i];
  return true;
}

/* What every second derivative along one direction dF needs. */
typedef struct {
  const double *dF;
  double GdF;      /* G : dF = dJ / J */
  double GdFtG[9]; /* G dF^T G = -dG */
} pm_hyper_dir;

/* The direction's pieces (dF kept by pointer). */
static inline void pm_hyper_direction(const pm_hyper_kin *k, const double dF[9],
                                      pm_hyper_dir *d) {
  double t[9];
  d->dF = dF;
  d->GdF = pm_t_ddot(k->G, dF);
  pm_t_mult(k->G, dF, t);
  pm_t_mul(t, k->G, d->GdFtG);
}

/* A P-shaped derivative from a symmetric spatial tensor: D = s T G. */
static inline void pm_hyper_pull(const pm_hyper_kin *k, double s,
                                 const double T[9], double D[9]) {
  pm_t_mul(T, k->G, D);
  for (int i = 0; i < 9; i++) D[i] *= s;
}

/* dD along d of D = dIbar/dF, Ibar = J^-m I, given I, g = dI/dF and
 * dg = d(g)[dF] (see the header comment). */
static inline void pm_hyper_iso_dir(const pm_hyper_kin *k,
                                    const pm_hyper_dir *d, double m, double I,
                                    const double g[9], const double dg[9],
                                    const double D[9], double dD[9]) {
  double Jm = exp(-m * k->lnJ), gdF = pm_t_ddot(g, d->dF);
  for (int i = 0; i < 9; i++)
    dD[i] = -m * d->GdF * D[i] +
            Jm * (dg[i] - m * gdF * k->G[i] + m * I * d->GdFtG[i]);
}

/* ---- isochoric invariants ------------------------------------------------ */

/* Ibar1 - 3 and (when Ibar2m3 is not NULL) Ibar2 - 3.  With b = c (I + X),
 * c = tr b / 3 and X traceless, J^2 = c^3 det(I + X), so
 *   Ibar1 = 3 det(I + X)^-1/3,  Ibar2 = (3 - q) det(I + X)^-2/3,
 * q = X : X / 2, det(I + X) = 1 - q + det X: no difference of O(1) terms
 * near F = I.  Far from it (q > 1/2) ln det(I + X) = 2 ln J - 3 ln c is
 * the accurate form. */
static inline void pm_hyper_ibar12(const pm_hyper_kin *k, double *Ibar1m3,
                                   double *Ibar2m3) {
  double X[9], trB3 = pm_t_trace(k->B) / 3;
  pm_t_dev(k->B, X);
  for (int i = 0; i < 9; i++) X[i] /= 1 + trB3;
  double q = 0.5 * pm_t_ddot(X, X);
  double L = q <= 0.5 ? log1p(pm_t_det(X) - q) : 2 * k->lnJ - 3 * log1p(trB3);
  *Ibar1m3 = 3 * expm1(-L / 3);
  if (Ibar2m3) *Ibar2m3 = 3 * expm1(-2 * L / 3) - q * exp(-2 * L / 3);
}

/* D1 = dIbar1/dF = 2 J^-2/3 dev(b) G (dev b = dev B: no cancellation). */
static inline void pm_hyper_ibar1_stress(const pm_hyper_kin *k, double D1[9]) {
  double T[9];
  pm_t_dev(k->B, T);
  pm_hyper_pull(k, 2 * k->Jm23, T, D1);
}

/* dD1 along d (I1 = F : F, g = 2 F, dg = 2 dF, m = 2/3). */
static inline void pm_hyper_ibar1_tangent(const pm_hyper_kin *k,
                                          const pm_hyper_dir *d,
                                          const double D1[9], double dD1[9]) {
  double g[9], dg[9];
  for (int i = 0; i < 9; i++) {
    g[i] = 2 * k->F[i];
    dg[i] = 2 * d->dF[i];
  }
  pm_hyper_iso_dir(k, d, 2.0 / 3.0, pm_t_ddot(k->F, k->F), g, dg, D1, dD1);
}

/* D2 = dIbar2/dF = 2 J^-4/3 dev(I1 b - b^2) G, with
 * dev(I1 b - b^2) = (1 + tr B) dev B - dev B^2. */
static inline void pm_hyper_ibar2_stress(const pm_hyper_kin *k, double D2[9]) {
  double B2[9], T[9], devB[9];
  pm_t_mul(k->B, k->B, B2);
  pm_t_dev(B2, T);
  pm_t_dev(k->B, devB);
  double s = 1 + pm_t_trace(k->B);
  for (int i = 0; i < 9; i++) T[i] = s * devB[i] - T[i];
  pm_hyper_pull(k, 2 * k->Jm23 * k->Jm23, T, D2);
}

/* dD2 along d: I2 = (I1^2 - b : b) / 2, g = 2 (I1 F - b F),
 * dg = 2 (dI1 F + I1 dF - d(b F)), d(bF) = dF C + F dF^T F + b dF. */
static inline void pm_hyper_ibar2_tangent(const pm_hyper_kin *k,
                                          const pm_hyper_dir *d,
                                          const double D2[9], double dD2[9]) {
  const double *F = k->F, *dF = d->dF;
  double b[9], bF[9], C[9], t[9], dbF[9], g[9], dg[9];
  pm_t_mult(F, F, b);
  pm_t_tmul(F, F, C);
  pm_t_mul(b, F, bF);
  pm_t_mul(dF, C, dbF);
  pm_t_mult(F, dF, t);
  pm_t_mul(t, F, g); /* F dF^T F, g as scratch */
  for (int i = 0; i < 9; i++) dbF[i] += g[i];
  pm_t_mul(b, dF, t);
  for (int i = 0; i < 9; i++) dbF[i] += t[i];
  double I1 = pm_t_trace(b), dI1 = 2 * pm_t_ddot(F, dF);
  for (int i = 0; i < 9; i++) {
    g[i] = 2 * (I1 * F[i] - bF[i]);
    dg[i] = 2 * (dI1 * F[i] + I1 * dF[i] - dbF[i]);
  }
  double I2 = 0.5 * (I1 * I1 - pm_t_ddot(b, b));
  pm_hyper_iso_dir(k, d, 4.0 / 3.0, I2, g, dg, D2, dD2);
}

/* Ibar4 - 1 of a unit reference direction a, and (when D4 is not NULL)
 * D4 = dIbar4/dF = 2 J^-2/3 dev(f (x) f) G, f = F a.  I4 - 1 = a.(C - I)a
 * = 2 a.H a + |H a|^2. */
static inline double pm_hyper_ibar4(const pm_hyper_kin *k, const double a[3],
                                    double D4[9]) {
  double Ha[3], f[3];
  pm_t_mulv(k->H, a, Ha);
  for (int i = 0; i < 3; i++) f[i] = a[i] + Ha[i];
  if (D4) {
    double T[9] = {0};
    pm_t_add_outer(T, 1, f, f);
    pm_t_dev(T, T);
    pm_hyper_pull(k, 2 * k->Jm23, T, D4);
  }
  return k->Jm23 * (2 * pm_v_dot(a, Ha) + pm_v_dot(Ha, Ha)) +
         expm1(-2.0 / 3.0 * k->lnJ);
}

/* dD4 along d (I4 = |F a|^2, g = 2 (F a) (x) a, dg = 2 (dF a) (x) a). */
static inline void pm_hyper_ibar4_tangent(const pm_hyper_kin *k,
                                          const pm_hyper_dir *d,
                                          const double a[3], const double D4[9],
                                          double dD4[9]) {
  double f[3], df[3], g[9] = {0}, dg[9] = {0};
  pm_t_mulv(k->F, a, f);
  pm_t_mulv(d->dF, a, df);
  pm_t_add_outer(g, 2, f, a);
  pm_t_add_outer(dg, 2, df, a);
  pm_hyper_iso_dir(k, d, 2.0 / 3.0, pm_v_dot(f, f), g, dg, D4, dD4);
}

/* ---- volumetric terms U(J) ----------------------------------------------- */

/* The key of the bulk modulus of K/2 (J - 1)^2 (required), into slot. */
#define PM_HYPER_BULK_KEY(slot)                                                \
  {                                                                            \
    .name = "bulk_modulus", .type = PM_KEY_NUMBER, .offset = PM_SLOT(slot),    \
    .def = "nan", .flags = PM_KEY_REQUIRED, .range = PM_RANGE_GT, .lo = 0,     \
    .unit = "Pa", .doc = "bulk modulus K of K/2 (J - 1)^2"                     \
  }

typedef struct {
  double U, dU, ddU; /* U(J), U'(J), U''(J) */
} pm_hyper_vol;

/* U = K/2 (J - 1)^2. */
static inline pm_hyper_vol pm_hyper_vol_quadratic(const pm_hyper_kin *k,
                                                  double K) {
  return (pm_hyper_vol){0.5 * K * k->Jm1 * k->Jm1, K * k->Jm1, K};
}

/* U = K/2 (ln J)^2 (Simo-Hughes). */
static inline pm_hyper_vol pm_hyper_vol_log(const pm_hyper_kin *k, double K) {
  return (pm_hyper_vol){0.5 * K * k->lnJ * k->lnJ, K * k->lnJ / k->J,
                        K * (1 - k->lnJ) / (k->J * k->J)};
}

/* The same two energies as functions of J alone (pm_model.volumetric):
 * U, U', U'' into u[0..2]. */
static inline void pm_hyper_u_quadratic(double K, double J, double u[3]) {
  u[0] = 0.5 * K * (J - 1) * (J - 1);
  u[1] = K * (J - 1);
  u[2] = K;
}

static inline void pm_hyper_u_log(double K, double J, double u[3]) {
  const double l = log(J);
  u[0] = 0.5 * K * l * l;
  u[1] = K * l / J;
  u[2] = K * (1 - l) / (J * J);
}

/* P += U' cof F. */
static inline void pm_hyper_vol_stress(const pm_hyper_kin *k, pm_hyper_vol v,
                                       double P[9]) {
  for (int i = 0; i < 9; i++) P[i] += v.dU * k->cof[i];
}

/* dP += U'' dJ cof F + U' d(cof F), d(cof F) = J ((G:dF) G - G dF^T G). */
static inline void pm_hyper_vol_tangent(const pm_hyper_kin *k,
                                        const pm_hyper_dir *d, pm_hyper_vol v,
                                        double dP[9]) {
  double dJ = k->J * d->GdF;
  for (int i = 0; i < 9; i++)
    dP[i] +=
        v.ddU * dJ * k->cof[i] + v.dU * k->J * (d->GdF * k->G[i] - d->GdFtG[i]);
}

/* ---- scalar helpers and checks ------------------------------------------ */

/* e^y - 1 - y without cancellation (Taylor series for |y| <= 1/2, where
 * the difference would lose digits; beyond, at most ~2 bits are lost). */
static inline double pm_hyper_expm1mx(double y) {
  if (fabs(y) > 0.5) return expm1(y) - y;
  double term = 0.5 * y * y, sum = term;
  for (int n = 3; fabs(term) > 1e-17 * sum; n++) {
    term *= y / n;
    sum += term;
  }
  return sum;
}

/* True when every entry of P is finite: x * 0 is a zero for a finite x and
 * NaN for an infinite or NaN one, so one test of the sum answers for all
 * nine, without a branch an entry. */
static inline bool pm_hyper_finite(const double P[9]) {
  double z = 0;
  for (int i = 0; i < 9; i++) z += P[i] * 0.0;
  return isfinite(z);
}

/* Check the model's own keys as read into m: every required NUMBER and
 * NUMBERS key present and every NUMBER in its range.  On failure
 * PM_ERR_ARG, "expected ..., got ...", and *key at the key's name. */
pm_err pm_hyper_check_keys(const pm_material *m, const char **key);

#endif
