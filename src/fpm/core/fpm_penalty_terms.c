/* fpm_penalty_terms: the per-point passes of fpm.volume_penalty (phi =
 * (ln J)^2 and its increments), run before the flux pass reads them. */
#include "fpm_penalty_terms.h"

#include "pm_omp.h"

void fpm_volume_phi(long n, const double *J, double *phi) {
  PM_OMP(for schedule(static) nowait)
  for (long i = 0; i < n; i++) {
    const double l = log(J[i]);
    phi[i] = l * l;
  }
}

void fpm_volume_dphi(long n, const double *bH, const double *dH, double *phi,
                     double *dphi) {
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, bH, dH, phi, dphi))
  for (long i = 0; i < n; i++) {
    double F[9], C[9];
    fpm_deformation(bH + 9 * i, F);
    pm_t_cofactor(F, C); /* C = J F^-T */
    const double J = pm_t_det(F), l = log(J);
    if (phi) phi[i] = l * l;
    if (dphi) dphi[i] = 2 * l * pm_t_ddot(C, dH + 9 * i) / J;
  }
}
