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

/* pm_nrmse and pm_nrmse_vector over points held in parts (the ranks'
 * shares of a run): each part sums its points (pm_nrmse_part_add), the
 * parts' sums are summed (d2) and their extremes taken (lo least, hi
 * largest), and the errors are made of them (pm_nrmse_parts), equal to
 * those of the whole to round-off. */
typedef struct {
  double d2[3];        /* squared differences per component */
  double lo[3], hi[3]; /* each component's least and largest reference */
  double most;         /* the largest magnitude of the reference */
} pm_nrmse_part;

/* An empty part's sums (lo +inf, hi -inf). */
void pm_nrmse_part_init(pm_nrmse_part *p);
/* A point's displacement u and reference ref (the components in mask)
 * into p. */
void pm_nrmse_part_add(pm_nrmse_part *p, unsigned mask, const double u[3],
                       const double ref[3]);
/* The NRMSE of each component in mask (NaN elsewhere) into nrmse, and of
 * the field into *vector (one component's own, or pm_nrmse_vector's over
 * two or three), of n points whose parts' sums are p. */
void pm_nrmse_parts(const pm_nrmse_part *p, long n, unsigned mask,
                    double nrmse[3], double *vector);

/* Least-squares slope of log(err) against log(h) over n >= 2 pairs: the
 * observed convergence rate q.  NaN if fewer than two positive pairs. */
double pm_convergence_rate(int n, const double *h, const double *err);

/* The invariants of n Cauchy stresses (9 each, row-major) that a reader
 * wants by name: von Mises stress sqrt(3/2 s:s) into von_mises and the
 * pressure -tr(sigma)/3 into pressure (either may be NULL). */
void pm_stress_invariants(long n, const double *sigma, double *von_mises,
                          double *pressure);

#endif
