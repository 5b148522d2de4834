/* pm_eigen: cyclic Jacobi for symmetric 3x3 matrices.  Each rotation zeroes
 * one off-diagonal entry; an entry is dropped only once it no longer
 * changes the diagonal beside it in floating point, so the eigenvalues keep
 * the accuracy of the matrix's entries, whatever its scale. */
#include "pm_eigen.h"

#include <math.h>

/* Zero a[p][q] of the symmetric working copy a (r the third index) by a
 * rotation in the (p, q) plane, accumulated into V. */
static void rotate(double a[3][3], double V[9], int p, int q, int r) {
  double apq = a[p][q], h = a[q][q] - a[p][p], t;
  if (fabs(h) + 100 * fabs(apq) == fabs(h)) {
    t = apq / h; /* theta = h / (2 apq) too large to square */
  } else {
    double theta = 0.5 * h / apq;
    t = 1 / (fabs(theta) + sqrt(1 + theta * theta));
    if (theta < 0) t = -t;
  }
  double c = 1 / sqrt(1 + t * t), s = t * c, tau = s / (1 + c);
  a[p][p] -= t * apq;
  a[q][q] += t * apq;
  a[p][q] = a[q][p] = 0;
  double arp = a[r][p], arq = a[r][q];
  a[r][p] = a[p][r] = arp - s * (arq + tau * arp);
  a[r][q] = a[q][r] = arq + s * (arp - tau * arq);
  for (int k = 0; k < 3; k++) {
    double vp = V[3 * k + p], vq = V[3 * k + q];
    V[3 * k + p] = vp - s * (vq + tau * vp);
    V[3 * k + q] = vq + s * (vp - tau * vq);
  }
}

/* Sort w ascending, permuting the columns of V alike. */
static void sort_ascending(double w[3], double V[9]) {
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2 - i; j++)
      if (w[j + 1] < w[j]) {
        double t = w[j];
        w[j] = w[j + 1];
        w[j + 1] = t;
        for (int k = 0; k < 3; k++) {
          t = V[3 * k + j];
          V[3 * k + j] = V[3 * k + j + 1];
          V[3 * k + j + 1] = t;
        }
      }
}

bool pm_eigen_sym3(const double A[9], double w[3], double V[9]) {
  double a[3][3];
  bool finite = true;
  for (int i = 0; i < 3; i++)
    for (int j = i; j < 3; j++) {
      a[i][j] = a[j][i] = A[3 * i + j];
      finite = finite && isfinite(A[3 * i + j]);
    }
  for (int k = 0; k < 9; k++) V[k] = (k % 4 == 0);
  static const int pairs[3][3] = {{0, 1, 2}, {0, 2, 1}, {1, 2, 0}};
  bool done = !finite;
  for (int sweep = 0; sweep < 50 && !done; sweep++) {
    for (int k = 0; k < 3; k++) {
      int p = pairs[k][0], q = pairs[k][1], r = pairs[k][2];
      double g = 100 * fabs(a[p][q]);
      /* Negligible beside both diagonal entries: dropping it changes
       * neither eigenvalue in floating point.  Before the fourth sweep
       * rotate anyway, as the diagonal is not settled yet. */
      if (sweep > 3 && fabs(a[p][p]) + g == fabs(a[p][p]) &&
          fabs(a[q][q]) + g == fabs(a[q][q]))
        a[p][q] = a[q][p] = 0;
      else if (a[p][q] != 0)
        rotate(a, V, p, q, r);
    }
    done = a[0][1] == 0 && a[0][2] == 0 && a[1][2] == 0;
  }
  for (int i = 0; i < 3; i++) w[i] = a[i][i];
  sort_ascending(w, V);
  return finite && done;
}
