/* fpm_gfd: generalized finite-difference gradient operator of the Fragile
 * Points Method, by weighted least squares over each point's support. */
#ifndef FPM_GFD_H
#define FPM_GFD_H

#include "pm_error.h"

/* Largest condition number of a support's scaled moment matrix. */
#define FPM_COND_MAX 1e8

/* Weights g_ik such that grad u_i = sum_k (u_k - u_i) (x) g_ik for the
 * support k in nbr[nbr_ptr[i] .. nbr_ptr[i+1]).  They minimize
 *   sum_k w_ik |u_k - u_i - G (X_k - X_i)|^2,  w_ik = 1 / |X_k - X_i|^2,
 * so a linear field is reproduced exactly; the inverse-square weight makes
 * the fit scale-free and favours the nearest points.  In 2D (dim = 2) the
 * z components of g are zero.
 *   x      3 * n reference positions
 *   g      out, 3 * nbr_ptr[n] weights, one triple per support entry
 *   cond   out (may be NULL), n condition numbers of the scaled moment
 *          matrix sum_k w_ik d_k d_k^T / (sum_k w_ik)
 * Fails with PM_ERR_GEOMETRY naming the worst point (id and position) if a
 * support does not span the space (condition number above cond_max), and
 * with PM_ERR_LINALG when LAPACKE reports a failure. */
pm_err fpm_gfd_weights(int dim, long n, const double *x, const long *nbr_ptr,
                       const long *nbr, double cond_max, double *g,
                       double *cond);

/* Condition of the supports in the current configuration: the moment
 * matrix of each support built from the deformed positions x + u (with the
 * reference weights).  Returns the number of points whose condition number
 * exceeds cond_max; *worst receives the largest condition number and
 * *worst_point its point.  Allocates nothing. */
long fpm_gfd_deformed_condition(int dim, long n, const double *x,
                                const double *u, const long *nbr_ptr,
                                const long *nbr, double cond_max, double *worst,
                                long *worst_point);

/* Slots of a quadratic-fit weight record: the gradient (3) and the
 * symmetric second derivatives xx, yy, zz, xy, yz, xz (6).  The basis a
 * reconstruction evaluates at an offset d is fpm_gfd_phi. */
#define FPM_QFIT 9

/* phi(d) = (d0, d1, d2, d0^2/2, d1^2/2, d2^2/2, d0 d1, d1 d2, d0 d2), so that
 * u(X + d) ~ u(X) + theta . phi(d) for theta the fitted gradient and second
 * derivatives. */
static inline void fpm_gfd_phi(const double d[3], double phi[FPM_QFIT]) {
  phi[0] = d[0];
  phi[1] = d[1];
  phi[2] = d[2];
  phi[3] = 0.5 * d[0] * d[0];
  phi[4] = 0.5 * d[1] * d[1];
  phi[5] = 0.5 * d[2] * d[2];
  phi[6] = d[0] * d[1];
  phi[7] = d[1] * d[2];
  phi[8] = d[0] * d[2];
}

/* Weights q_ik (FPM_QFIT per support entry) of the weighted least-squares
 * quadratic fit about each point,
 *   theta_i = sum_k (u_k - u_i) q_ik  minimizing
 *   sum_k w_ik (u_k - u_i - theta . phi(X_k - X_i))^2,  w_ik = 1/|X_k - X_i|^2,
 * which reproduces quadratic fields exactly (in 2D only the x, y, xx, yy,
 * xy slots are used).  The fit is solved in coordinates scaled by the
 * support's mean distance; cond[i] receives the condition number of its
 * scaled moment matrix (infinite when the support has fewer points than
 * unknowns or LAPACKE fails; the weights of such a point are zero).
 * nbr_ptr/nbr is any support (it need not be the interface adjacency).
 * With select non-NULL only the points where select[i] is set are fitted
 * (the others' q and cond are left as they are). */
void fpm_gfd_quadratic(int dim, long n, const double *x, const long *nbr_ptr,
                       const long *nbr, const unsigned char *select, double *q,
                       double *cond);

#endif
