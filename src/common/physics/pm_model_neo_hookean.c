/* pm_model_neo_hookean: the neo-Hookean model of reduced invariants of the
 * FPM paper (eq. 27), W = mu/2 (J^-2/3 tr C - 3) + K/2 (J - 1)^2, written
 * to keep its relative accuracy as F -> I. */
#include <math.h>

#include "pm_hyper.h"
#include "pm_models.h"

/* P = mu J^-2/3 (F - I1/3 F^-T) + K (J - 1) J F^-T, with J F^-T = cof F.
 * J - 1 and J^-2/3 - 1 are formed from H = F - I so that the stress and
 * the energy keep their relative accuracy as F -> I. */
static bool stress(const pm_material *m, const double F[9], const double *st,
                   double P[9], double *W, double *Jout) {
  (void)st;
  const double mu = m->c[PM_EL_MU], kappa = m->c[PM_EL_K];
  double H[9], cof[9];
  for (int k = 0; k < 9; k++) H[k] = F[k];
  H[0] -= 1;
  H[4] -= 1;
  H[8] -= 1;
  double Jm1 = pm_t_det_minus_one(H);
  double J = 1 + Jm1;
  if (Jout) *Jout = J;
  if (!(J > 0)) return false;
  pm_t_cofactor(F, cof);
  double lnJ = log1p(Jm1);
  double Jm23 = exp(-2.0 / 3.0 * lnJ);
  double I1m3 = 2 * pm_t_trace(H) + pm_t_ddot(H, H); /* tr(F^T F) - 3 */
  double I1 = 3 + I1m3;
  /* F - I1/3 F^-T = F - I1/(3J) cof F */
  double a = mu * Jm23, b = -a * I1 / (3 * J) + kappa * Jm1;
  for (int k = 0; k < 9; k++) P[k] = a * F[k] + b * cof[k];
  /* J^-2/3 - 1 only for the energy: the stress alone skips the expm1. */
  if (W)
    *W = 0.5 * mu * (Jm23 * I1m3 + 3 * expm1(-2.0 / 3.0 * lnJ)) +
         0.5 * kappa * Jm1 * Jm1;
  return pm_hyper_finite(P);
}

/* d(a F + b cof F) with dJ = cof : dF, dI1 = 2 F : dF,
 * d cof = (dJ cof - cof dF^T cof) / J. */
static bool tangent(const pm_material *m, const double F[9], const double *st,
                    const double dF[9], double dP[9]) {
  (void)st;
  const double mu = m->c[PM_EL_MU], kappa = m->c[PM_EL_K];
  double cof[9], t1[9], t2[9], dFT[9];
  double J = pm_t_det(F);
  if (!(J > 0)) return false;
  pm_t_cofactor(F, cof);
  double a = mu * exp(-2.0 / 3.0 * log(J));
  double I1 = pm_t_ddot(F, F);
  double b = -a * I1 / (3 * J) + kappa * (J - 1);
  double dJ = pm_t_ddot(cof, dF), dI1 = 2 * pm_t_ddot(F, dF);
  double da = -2.0 / 3.0 * a * dJ / J;
  double db = -da * I1 / (3 * J) - a * dI1 / (3 * J) +
              a * I1 * dJ / (3 * J * J) + kappa * dJ;
  pm_t_transpose(dF, dFT);
  pm_t_mul(cof, dFT, t1);
  pm_t_mul(t1, cof, t2);
  for (int k = 0; k < 9; k++)
    dP[k] = da * F[k] + a * dF[k] + db * cof[k] + b * (dJ * cof[k] - t2[k]) / J;
  return true;
}

/* U(J) of the split W = W_iso + U(J). */
static void volumetric(const pm_material *m, double J, double U[3]) {
  pm_hyper_u_quadratic(m->c[PM_EL_K], J, U);
}

const pm_model pm_model_neo_hookean = {
    .name = "neo-hookean",
    .formula = "W = mu/2 (J^-2/3 tr C - 3) + K/2 (J - 1)^2 (FPM paper eq. 27)",
    .kind = PM_MATERIAL_SOLID,
    .keys = pm_elastic_keys,
    .key_sets = PM_ELASTIC_KEY_SETS,
    .init = pm_elastic_init,
    .stress = stress,
    .tangent = tangent,
    .volumetric = volumetric,
};
