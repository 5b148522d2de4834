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

void pm_nrmse_part_init(pm_nrmse_part *p) {
  for (int k = 0; k < 3; k++) {
    p->d2[k] = 0;
    p->lo[k] = INFINITY;
    p->hi[k] = -INFINITY;
  }
  p->most = 0;
}

void pm_nrmse_part_add(pm_nrmse_part *p, unsigned mask, const double u[3],
                       const double ref[3]) {
  double r2 = 0;
  for (int k = 0; k < 3; k++) {
    if (!(mask >> k & 1u)) continue;
    const double d = u[k] - ref[k];
    p->d2[k] += d * d;
    p->lo[k] = fmin(p->lo[k], ref[k]);
    p->hi[k] = fmax(p->hi[k], ref[k]);
    r2 += ref[k] * ref[k];
  }
  p->most = fmax(p->most, sqrt(r2));
}

void pm_nrmse_parts(const pm_nrmse_part *p, long n, unsigned mask,
                    double nrmse[3], double *vector) {
  int components = 0;
  double all = 0;
  *vector = NAN;
  for (int k = 0; k < 3; k++) {
    nrmse[k] = NAN;
    if (!(mask >> k & 1u)) continue;
    if (p->hi[k] > p->lo[k] && n > 0)
      nrmse[k] = sqrt(p->d2[k] / (double)n) / (p->hi[k] - p->lo[k]);
    *vector = nrmse[k];
    all += p->d2[k];
    components++;
  }
  if (components > 1)
    *vector = p->most > 0 && n > 0 ? sqrt(all / (double)n) / p->most : NAN;
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
