/* pm_eigen: eigenvalues and eigenvectors of a symmetric 3x3 matrix by cyclic
 * Jacobi rotations: backward stable at any scale and exact in structure for
 * repeated eigenvalues (the eigenvectors stay orthonormal). */
#ifndef PM_EIGEN_H
#define PM_EIGEN_H

#include <stdbool.h>

/* A = V diag(w) V^T for a symmetric A (row-major; only its upper triangle
 * is read).  w ascending; V row-major with the eigenvectors as its
 * columns (V[3 * i + k] is component i of vector k), orthonormal.  Returns
 * false (w, V the last iterate) if the rotations have not zeroed the
 * off-diagonal after 50 sweeps, or A is not finite. */
bool pm_eigen_sym3(const double A[9], double w[3], double V[9]);

#endif
