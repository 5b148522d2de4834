/* pm_metrics: error norms against reference fields and observed
 * convergence rates, shared by every backend and study. */
#ifndef PM_METRICS_H
#define PM_METRICS_H

/* NRMSE of the FPM paper (eq. 28) for one component:
 *   sqrt(sum_j (u_j - r_j)^2) / (max_j r_j - min_j r_j)
 * over n values taken every stride doubles from u and ref.  Returns NaN if
 * the reference has no range. */
double pm_nrmse(long n, int stride, const double *u, const double *ref);

/* Least-squares slope of log(err) against log(h) over n >= 2 pairs: the
 * observed convergence rate q.  NaN if fewer than two positive pairs. */
double pm_convergence_rate(int n, const double *h, const double *err);

#endif
