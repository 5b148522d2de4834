/* pm_model_linear: small-strain linear elasticity, W = lambda/2 tr(e)^2 +
 * mu e:e with e = sym(F) - I, and its objective rate form (Jaumann) for
 * updated-Lagrangian backends. */
#include <math.h>

#include "pm_hyper.h"
#include "pm_models.h"

static bool stress(const pm_material *m, const double F[9], const double *st,
                   double P[9], double *W, double *Jout) {
  (void)st;
  const double mu = m->c[PM_EL_MU], lambda = m->c[PM_EL_LAMBDA];
  double e[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      e[3 * i + j] = 0.5 * (F[3 * i + j] + F[3 * j + i]) - (i == j);
  double tr = pm_t_trace(e);
  for (int k = 0; k < 9; k++) P[k] = 2 * mu * e[k];
  P[0] += lambda * tr;
  P[4] += lambda * tr;
  P[8] += lambda * tr;
  if (W) *W = 0.5 * lambda * tr * tr + mu * pm_t_ddot(e, e);
  if (Jout) *Jout = pm_t_det(F);
  return pm_hyper_finite(P);
}

static bool tangent(const pm_material *m, const double F[9], const double *st,
                    const double dF[9], double dP[9]) {
  (void)F;
  (void)st;
  const double mu = m->c[PM_EL_MU], lambda = m->c[PM_EL_LAMBDA];
  double tr = dF[0] + dF[4] + dF[8];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      dP[3 * i + j] =
          mu * (dF[3 * i + j] + dF[3 * j + i]) + (i == j ? lambda * tr : 0);
  return true;
}

/* sigma += dt (lambda tr D I + 2 mu D + W sigma - sigma W). */
static void rate(const pm_material *m, const double D[9], const double Wsp[9],
                 double dt, double sig[9]) {
  const double mu = m->c[PM_EL_MU], lambda = m->c[PM_EL_LAMBDA];
  double WS[9], SW[9];
  double trD = D[0] + D[4] + D[8];
  pm_t_mul(Wsp, sig, WS);
  pm_t_mul(sig, Wsp, SW);
  for (int i = 0; i < 9; i++) sig[i] += dt * (2 * mu * D[i] + WS[i] - SW[i]);
  sig[0] += dt * lambda * trD;
  sig[4] += dt * lambda * trD;
  sig[8] += dt * lambda * trD;
}

const pm_model pm_model_linear_elastic = {
    .name = "linear-elastic",
    .formula = "W = lambda/2 tr(e)^2 + mu e:e, e = sym(F) - I; updated-"
               "Lagrangian backends integrate its Jaumann rate",
    .kind = PM_MATERIAL_SOLID,
    .keys = pm_elastic_keys,
    .key_sets = PM_ELASTIC_KEY_SETS,
    .init = pm_elastic_init,
    .stress = stress,
    .tangent = tangent,
    .rate = rate,
};
