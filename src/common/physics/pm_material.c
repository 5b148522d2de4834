/* pm_material: the neo-Hookean model of reduced invariants (FPM paper eq. 27)
 * and small-strain linear elasticity, written to stay accurate near F = I. */
#include "pm_material.h"

#include <string.h>

static const char *const model_names[PM_MODEL_COUNT] = {"neo-hookean",
                                                        "linear-elastic"};

const char *pm_model_name(pm_model model) {
  return (model >= 0 && model < PM_MODEL_COUNT) ? model_names[model] : "?";
}

pm_model pm_model_from_name(const char *name) {
  for (int k = 0; k < PM_MODEL_COUNT; k++)
    if (name && strcmp(name, model_names[k]) == 0) return (pm_model)k;
  return PM_MODEL_COUNT;
}

pm_err pm_material_init(pm_material *m, pm_model model, double density,
                        double youngs, double poisson) {
  PM_CHECK(model >= 0 && model < PM_MODEL_COUNT, PM_ERR_ARG,
           "unknown material model %d", (int)model);
  PM_CHECK(density > 0 && isfinite(density), PM_ERR_ARG,
           "density must be > 0 (got %g)", density);
  PM_CHECK(youngs > 0 && isfinite(youngs), PM_ERR_ARG,
           "youngs_modulus must be > 0 (got %g)", youngs);
  PM_CHECK(poisson > -1 && poisson < 0.5, PM_ERR_ARG,
           "poisson_ratio must be in (-1, 0.5) (got %g)", poisson);
  memset(m, 0, sizeof *m);
  m->model = model;
  m->density = density;
  m->youngs = youngs;
  m->poisson = poisson;
  m->mu = youngs / (2 * (1 + poisson));
  m->kappa = youngs / (3 * (1 - 2 * poisson));
  m->lambda = youngs * poisson / ((1 + poisson) * (1 - 2 * poisson));
  m->wave_speed = sqrt((m->lambda + 2 * m->mu) / density);
  return PM_SUCCESS;
}

/* Neo-Hookean: P = mu J^-2/3 (F - I1/3 F^-T) + K (J - 1) J F^-T, with
 * J F^-T = cof F.  J - 1 and J^-2/3 - 1 are formed from H = F - I so that
 * the stress and the energy keep their relative accuracy as F -> I. */
static bool neo_hookean(const pm_material *m, const double F[9], double P[9],
                        double *W, double *Jout) {
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
  double Jm23m1 = expm1(-2.0 / 3.0 * lnJ);
  double I1m3 = 2 * pm_t_trace(H) + pm_t_ddot(H, H); /* tr(F^T F) - 3 */
  double I1 = 3 + I1m3;
  /* F - I1/3 F^-T = F - I1/(3J) cof F */
  double a = m->mu * Jm23, b = -a * I1 / (3 * J) + m->kappa * Jm1;
  for (int k = 0; k < 9; k++) P[k] = a * F[k] + b * cof[k];
  if (W)
    *W = 0.5 * m->mu * (Jm23 * I1m3 + 3 * Jm23m1) + 0.5 * m->kappa * Jm1 * Jm1;
  for (int k = 0; k < 9; k++)
    if (!isfinite(P[k])) return false;
  return true;
}

static bool linear_elastic(const pm_material *m, const double F[9], double P[9],
                           double *W, double *Jout) {
  double e[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      e[3 * i + j] = 0.5 * (F[3 * i + j] + F[3 * j + i]) - (i == j);
  double tr = pm_t_trace(e);
  for (int k = 0; k < 9; k++) P[k] = 2 * m->mu * e[k];
  P[0] += m->lambda * tr;
  P[4] += m->lambda * tr;
  P[8] += m->lambda * tr;
  if (W) *W = 0.5 * m->lambda * tr * tr + m->mu * pm_t_ddot(e, e);
  if (Jout) *Jout = pm_t_det(F);
  for (int k = 0; k < 9; k++)
    if (!isfinite(P[k])) return false;
  return true;
}

bool pm_material_stress(const pm_material *m, const double F[9], double P[9],
                        double *W, double *J) {
  switch (m->model) {
  case PM_MODEL_NEO_HOOKEAN: return neo_hookean(m, F, P, W, J);
  case PM_MODEL_LINEAR_ELASTIC: return linear_elastic(m, F, P, W, J);
  default: return false;
  }
}

/* d(a F + b cof F) with dJ = cof : dF, dI1 = 2 F : dF,
 * d cof = (dJ cof - cof dF^T cof) / J. */
static bool neo_hookean_derivative(const pm_material *m, const double F[9],
                                   const double dF[9], double dP[9]) {
  double cof[9], t1[9], t2[9], dFT[9];
  double J = pm_t_det(F);
  if (!(J > 0)) return false;
  pm_t_cofactor(F, cof);
  double a = m->mu * exp(-2.0 / 3.0 * log(J));
  double I1 = pm_t_ddot(F, F);
  double b = -a * I1 / (3 * J) + m->kappa * (J - 1);
  double dJ = pm_t_ddot(cof, dF), dI1 = 2 * pm_t_ddot(F, dF);
  double da = -2.0 / 3.0 * a * dJ / J;
  double db = -da * I1 / (3 * J) - a * dI1 / (3 * J) +
              a * I1 * dJ / (3 * J * J) + m->kappa * dJ;
  pm_t_transpose(dF, dFT);
  pm_t_mul(cof, dFT, t1);
  pm_t_mul(t1, cof, t2);
  for (int k = 0; k < 9; k++)
    dP[k] = da * F[k] + a * dF[k] + db * cof[k] + b * (dJ * cof[k] - t2[k]) / J;
  return true;
}

bool pm_material_stress_derivative(const pm_material *m, const double F[9],
                                   const double dF[9], double dP[9]) {
  switch (m->model) {
  case PM_MODEL_NEO_HOOKEAN: return neo_hookean_derivative(m, F, dF, dP);
  case PM_MODEL_LINEAR_ELASTIC: {
    double tr = dF[0] + dF[4] + dF[8];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        dP[3 * i + j] = m->mu * (dF[3 * i + j] + dF[3 * j + i]) +
                        (i == j ? m->lambda * tr : 0);
    return true;
  }
  default: return false;
  }
}

bool pm_material_pk2(const pm_material *m, const double F[9], double S[9]) {
  double P[9], Finv[9];
  if (!pm_material_stress(m, F, P, NULL, NULL)) return false;
  if (!(pm_t_inverse(F, Finv) > 0)) return false;
  pm_t_mul(Finv, P, S);
  return true;
}

double pm_material_energy(const pm_material *m, const double F[9]) {
  double P[9], W;
  if (!pm_material_stress(m, F, P, &W, NULL)) return NAN;
  return W;
}

pm_err pm_material_uniaxial_lateral_stretch(const pm_material *m,
                                            double lambda_axial,
                                            double *lambda_lateral) {
  PM_CHECK(lambda_axial > 0, PM_ERR_ARG, "axial stretch must be > 0 (got %g)",
           lambda_axial);
  /* Solve P_xx(diag(s, s, lambda_axial)) = 0 for s by a safeguarded Newton
   * iteration with a central-difference slope. */
  double s = 1 / sqrt(lambda_axial); /* incompressible guess */
  for (int it = 0; it < 100; it++) {
    double F[9] = {s, 0, 0, 0, s, 0, 0, 0, lambda_axial}, P[9];
    if (!pm_material_stress(m, F, P, NULL, NULL)) break;
    double ds = 1e-7 * s, Pp[9], Pm[9];
    F[0] = F[4] = s + ds;
    pm_material_stress(m, F, Pp, NULL, NULL);
    F[0] = F[4] = s - ds;
    pm_material_stress(m, F, Pm, NULL, NULL);
    double slope = (Pp[0] - Pm[0]) / (2 * ds);
    if (!(slope > 0)) break;
    double step = -P[0] / slope;
    if (step < -0.5 * s) step = -0.5 * s;
    s += step;
    if (fabs(step) <= 1e-15 * s) {
      *lambda_lateral = s;
      return PM_SUCCESS;
    }
  }
  return PM_ERROR(PM_ERR_NOT_CONVERGED,
                  "no lateral stretch in uniaxial stress for axial stretch %g",
                  lambda_axial);
}
