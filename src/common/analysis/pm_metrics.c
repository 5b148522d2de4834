/* pm_metrics: NRMSE (FPM paper eq. 28) and observed convergence rates. */
#include "pm_metrics.h"

#include <math.h>

#include "pm_omp.h"
#include "pm_tensor.h"

double pm_nrmse(long n, int stride, const double *u, const double *ref) {
  double sum = 0, lo = INFINITY, hi = -INFINITY;
  for (long j = 0; j < n; j++) {
    double d = u[j * stride] - ref[j * stride];
    sum += d * d;
    if (ref[j * stride] < lo) lo = ref[j * stride];
    if (ref[j * stride] > hi) hi = ref[j * stride];
  }
  if (!(hi > lo) || n <= 0) return NAN;
  return sqrt(sum / (double)n) / (hi - lo);
}

double pm_nrmse_vector(long n, unsigned mask, const double *u,
                       const double *ref) {
  double sum = 0, lo = INFINITY, hi = -INFINITY;
  for (long j = 0; j < n; j++) {
    double r2 = 0;
    for (int c = 0; c < 3; c++) {
      if (!(mask & (1u << c))) continue;
      double d = u[3 * j + c] - ref[3 * j + c];
      sum += d * d;
      r2 += ref[3 * j + c] * ref[3 * j + c];
    }
    double r = sqrt(r2);
    lo = fmin(lo, r);
    hi = fmax(hi, r);
  }
  (void)lo;
  if (!(hi > 0) || n <= 0) return NAN;
  return sqrt(sum / (double)n) / hi;
}

double pm_convergence_rate(int n, const double *h, const double *err) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int m = 0;
  for (int k = 0; k < n; k++) {
    if (!(h[k] > 0 && err[k] > 0)) continue;
    double x = log(h[k]), y = log(err[k]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    m++;
  }
  if (m < 2) return NAN;
  double den = m * sxx - sx * sx;
  return den > 0 ? (m * sxy - sx * sy) / den : NAN;
}

void pm_stress_invariants(long n, const double *sigma, double *von_mises,
                          double *pressure) {
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, sigma, von_mises, pressure))
  for (long i = 0; i < n; i++) {
    const double *S = sigma + 9 * i;
    if (von_mises) von_mises[i] = pm_t_von_mises(S);
    if (pressure) pressure[i] = -(S[0] + S[4] + S[8]) / 3;
  }
}
