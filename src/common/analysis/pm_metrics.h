/* pm_metrics: error norms against reference fields and observed
 * convergence rates, shared by every backend and study. */
#ifndef PM_METRICS_H
#define PM_METRICS_H

/* NRMSE of the FPM paper (eq. 28) for one component: the root of the MEAN
 * square error over the range of the reference,
 *   sqrt(sum_j (u_j - r_j)^2 / n) / (max_j r_j - min_j r_j)
 * over n values taken every stride doubles from u and ref.  (Eq. 28 as
 * printed omits the 1/n; its name and the paper's tables are those of the
 * mean.)  Returns NaN if the reference has no range. */
double pm_nrmse(long n, int stride, const double *u, const double *ref);

/* The same for a vector field of n points ([n][3]; components not in mask
 * are ignored), over the largest magnitude of the reference:
 * sqrt(sum_j |u_j - r_j|^2 / n) / max_j |r_j|.  (That is the range of |r|
 * whenever some point of the reference is at rest, as on a held face; and
 * it stays meaningful for a rigid translation.)  NaN if r is zero. */
double pm_nrmse_vector(long n, unsigned mask, const double *u,
                       const double *ref);

/* Least-squares slope of log(err) against log(h) over n >= 2 pairs: the
 * observed convergence rate q.  NaN if fewer than two positive pairs. */
double pm_convergence_rate(int n, const double *h, const double *err);

/* The invariants of n Cauchy stresses (9 each, row-major) that a reader
 * wants by name: von Mises stress sqrt(3/2 s:s) into von_mises and the
 * pressure -tr(sigma)/3 into pressure (either may be NULL). */
void pm_stress_invariants(long n, const double *sigma, double *von_mises,
                          double *pressure);

#endif
