/* fpm_gfd: weighted least-squares gradient weights per point; the symmetric
 * moment matrix is diagonalized by LAPACKE so its conditioning is known. */
#include "fpm_gfd.h"

#include <lapacke.h>
#include <math.h>

#include "pm_omp.h"

/* Ainv (m x m) = V diag(1/lam) V^T from LAPACKE_dsyev's eigenvectors V
 * (columns, row-major in A) and eigenvalues lam. */
static void inverse_from_eigen(int m, const double *A, const double *lam,
                               double *Ainv) {
  for (int r = 0; r < m; r++)
    for (int c = 0; c < m; c++) {
      double v = 0;
      for (int k = 0; k < m; k++) v += A[m * r + k] * A[m * c + k] / lam[k];
      Ainv[m * r + c] = v;
    }
}

/* The scaled moment matrix of point i's support (dim x dim, row-major,
 * eigenvalues summing to 1): sum_k w_ik d_k d_k^T / sum_k w_ik with
 * w_ik = 1/|X_k - X_i|^2 and d_k = X_k - X_i, or, with u, the deformed
 * d_k = X_k + u_k - X_i - u_i.  Returns sum_k w_ik. */
static double moments(int dim, long i, const double *x, const double *u,
                      const long *nbr_ptr, const long *nbr, double A[9]) {
  double wsum = 0;
  const double *xi = x + 3 * i;
  for (int k = 0; k < 9; k++) A[k] = 0;
  for (long e = nbr_ptr[i]; e < nbr_ptr[i + 1]; e++) {
    const double *xk = x + 3 * nbr[e];
    double D[3], d[3];
    for (int a = 0; a < 3; a++) {
      D[a] = xk[a] - xi[a];
      d[a] = u ? D[a] + u[3 * nbr[e] + a] - u[3 * i + a] : D[a];
    }
    double w = 1.0 / (D[0] * D[0] + D[1] * D[1] + D[2] * D[2]);
    wsum += w;
    for (int a = 0; a < dim; a++)
      for (int b = 0; b < dim; b++) A[dim * a + b] += w * d[a] * d[b];
  }
  for (int k = 0; k < dim * dim; k++) A[k] /= wsum;
  return wsum;
}

pm_err fpm_gfd_weights(int dim, long n, const double *x, const long *nbr_ptr,
                       const long *nbr, double cond_max, double *g,
                       double *cond) {
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG, "dimension must be 2 or 3");
  long worst = -1;
  double worst_cond = 0;
  int lapack_info = 0;
  long lapack_point = -1;
  PM_OMP(parallel for schedule(dynamic, 256) default(none)
         shared(n, x, nbr_ptr, nbr, g, cond, dim, cond_max, worst, worst_cond,
                lapack_info, lapack_point))
  for (long i = 0; i < n; i++) {
    double A[9], lam[3];
    const double *xi = x + 3 * i;
    if (nbr_ptr[i] == nbr_ptr[i + 1]) { /* a part's edge (fpm_model.h) */
      if (cond) cond[i] = 0;
      continue;
    }
    const double wsum = moments(dim, i, x, NULL, nbr_ptr, nbr, A);
    int info = LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', dim, A, dim, lam);
    double c = (info == 0 && lam[0] > 0) ? lam[dim - 1] / lam[0] : INFINITY;
    if (cond) cond[i] = c;
    if (info != 0) {
      PM_OMP(critical(fpm_gfd_fail)) {
        lapack_info = info;
        lapack_point = i;
      }
      continue;
    }
    if (!(c <= cond_max)) {
      PM_OMP(critical(fpm_gfd_fail))
      if (worst < 0 || !(c <= worst_cond)) {
        worst = i;
        worst_cond = c;
      }
      continue;
    }
    double Ainv[9];
    inverse_from_eigen(dim, A, lam, Ainv);
    for (long e = nbr_ptr[i]; e < nbr_ptr[i + 1]; e++) {
      const double *xk = x + 3 * nbr[e];
      double d[3] = {xk[0] - xi[0], xk[1] - xi[1], xk[2] - xi[2]};
      double w = 1.0 / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / wsum;
      for (int a = 0; a < 3; a++) g[3 * e + a] = 0;
      for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++)
          g[3 * e + a] += Ainv[dim * a + b] * w * d[b];
    }
  }
  if (lapack_info < 0)
    return PM_ERROR(PM_ERR_LINALG,
                    "LAPACKE_dsyev: argument %d is invalid (point %ld)",
                    -lapack_info, lapack_point);
  if (lapack_info > 0)
    return PM_ERROR(PM_ERR_LINALG,
                    "LAPACKE_dsyev did not converge at point %ld "
                    "(%g, %g, %g)",
                    lapack_point, x[3 * lapack_point], x[3 * lapack_point + 1],
                    x[3 * lapack_point + 2]);
  if (worst >= 0)
    return PM_ERROR(PM_ERR_GEOMETRY,
                    "point %ld at (%g, %g, %g): ill-conditioned support: "
                    "%ld neighbours, condition number %.3g > %.3g; the "
                    "support does not span %dD",
                    worst, x[3 * worst], x[3 * worst + 1], x[3 * worst + 2],
                    nbr_ptr[worst + 1] - nbr_ptr[worst], worst_cond, cond_max,
                    dim);
  return PM_SUCCESS;
}

/* Condition number of one support's moment matrix at positions x + u,
 * weighted by the reference distances. */
static double deformed_condition(int dim, long i, const double *x,
                                 const double *u, const long *nbr_ptr,
                                 const long *nbr) {
  double A[9], lam[3];
  moments(dim, i, x, u, nbr_ptr, nbr, A);
  int info = LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'N', 'U', dim, A, dim, lam);
  return (info == 0 && lam[0] > 0) ? lam[dim - 1] / lam[0] : INFINITY;
}

long fpm_gfd_deformed_condition(int dim, long n, const double *x,
                                const double *u, const long *nbr_ptr,
                                const long *nbr, double cond_max, double *worst,
                                long *worst_point) {
  long count = 0, wp = -1;
  double wc = 0;
  PM_OMP(parallel default(none) reduction(+ : count)
         shared(n, x, u, nbr_ptr, nbr, dim, cond_max, wc, wp)) {
    long my_p = -1;
    double my_c = 0;
    PM_OMP(for schedule(dynamic, 256) nowait)
    for (long i = 0; i < n; i++) {
      double c = deformed_condition(dim, i, x, u, nbr_ptr, nbr);
      if (!(c <= cond_max)) count++;
      if (my_p < 0 || !(c <= my_c)) {
        my_c = c;
        my_p = i;
      }
    }
    PM_OMP(critical(fpm_gfd_worst))
    if (my_p >= 0 && (wp < 0 || !(my_c <= wc) || (my_c == wc && my_p < wp))) {
      wc = my_c;
      wp = my_p;
    }
  }
  if (worst) *worst = wc;
  if (worst_point) *worst_point = wp;
  return count;
}

/* The basis of the quadratic fit at the offset of xk from xi scaled by s,
 * into phi; returns the offset's weight 1/|d|^2. */
static double scaled_basis(const double *xi, const double *xk, double s,
                           double phi[FPM_QFIT]) {
  double d[3] = {(xk[0] - xi[0]) / s, (xk[1] - xi[1]) / s, (xk[2] - xi[2]) / s};
  fpm_gfd_phi(d, phi);
  return 1.0 / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

/* One point's quadratic fit: fills q for its support and returns the
 * condition number (infinite when unusable, q then zero). */
static double quadratic_fit(int dim, long i, const double *x,
                            const long *nbr_ptr, const long *nbr, double *q) {
  static const int slots2[] = {0, 1, 3, 4, 6},
                   slots3[] = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  static const int order[FPM_QFIT] = {1, 1, 1, 2, 2, 2, 2, 2, 2};
  const int *slot = dim == 2 ? slots2 : slots3;
  const int m = dim == 2 ? 5 : 9;
  const long b = nbr_ptr[i], e_end = nbr_ptr[i + 1];
  const double *xi = x + 3 * i;
  for (long e = b; e < e_end; e++)
    for (int a = 0; a < FPM_QFIT; a++) q[FPM_QFIT * e + a] = 0;
  if (e_end - b < m) return INFINITY;
  double s = 0;
  for (long e = b; e < e_end; e++) {
    const double *xk = x + 3 * nbr[e];
    s += sqrt((xk[0] - xi[0]) * (xk[0] - xi[0]) +
              (xk[1] - xi[1]) * (xk[1] - xi[1]) +
              (xk[2] - xi[2]) * (xk[2] - xi[2]));
  }
  s /= (double)(e_end - b);
  double A[81] = {0}, lam[9], phi[FPM_QFIT];
  for (long e = b; e < e_end; e++) {
    const double w = scaled_basis(xi, x + 3 * nbr[e], s, phi);
    for (int r = 0; r < m; r++)
      for (int c = 0; c < m; c++)
        A[m * r + c] += w * phi[slot[r]] * phi[slot[c]];
  }
  int info = LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', m, A, m, lam);
  if (info != 0 || !(lam[0] > 0)) return INFINITY;
  const double cond = lam[m - 1] / lam[0];
  double Ainv[81];
  inverse_from_eigen(m, A, lam, Ainv);
  for (long e = b; e < e_end; e++) {
    const double w = scaled_basis(xi, x + 3 * nbr[e], s, phi);
    for (int r = 0; r < m; r++) {
      double v = 0;
      for (int c = 0; c < m; c++) v += Ainv[m * r + c] * w * phi[slot[c]];
      q[FPM_QFIT * e + slot[r]] = v / (order[slot[r]] == 1 ? s : s * s);
    }
  }
  return cond;
}

void fpm_gfd_quadratic(int dim, long n, const double *x, const long *nbr_ptr,
                       const long *nbr, const unsigned char *select, double *q,
                       double *cond) {
  PM_OMP(parallel for schedule(dynamic, 256) default(none)
         shared(n, x, nbr_ptr, nbr, select, q, cond, dim))
  for (long i = 0; i < n; i++)
    if (!select || select[i])
      cond[i] = quadratic_fit(dim, i, x, nbr_ptr, nbr, q);
}
