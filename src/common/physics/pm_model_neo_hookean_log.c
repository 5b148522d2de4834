/* pm_model_neo_hookean_log: the uncoupled neo-Hookean model of Simo and
 * Hughes with a logarithmic volumetric term (the implicit MPM paper on
 * multicellular constructs), W = mu/2 (Ibar1 - 3) + K/2 (ln J)^2. */
#include "pm_hyper.h"

/* P = mu/2 dIbar1/dF + K ln J F^-T. */
static bool stress(const pm_material *m, const double F[9], const double *st,
                   double P[9], double *W, double *Jout) {
  (void)st;
  const double mu = m->c[PM_EL_MU], K = m->c[PM_EL_K];
  pm_hyper_kin k;
  if (!pm_hyper_kinematics(F, &k, Jout)) return false;
  pm_hyper_vol v = pm_hyper_vol_log(&k, K);
  double I1m3;
  pm_hyper_ibar12(&k, &I1m3, NULL);
  pm_hyper_ibar1_stress(&k, P);
  for (int i = 0; i < 9; i++) P[i] *= 0.5 * mu;
  pm_hyper_vol_stress(&k, v, P);
  if (W) *W = 0.5 * mu * I1m3 + v.U;
  return pm_hyper_finite(P);
}

/* dP = mu/2 d(dIbar1/dF) + d(U' cof F). */
static bool tangent(const pm_material *m, const double F[9], const double *st,
                    const double dF[9], double dP[9]) {
  (void)st;
  const double mu = m->c[PM_EL_MU], K = m->c[PM_EL_K];
  pm_hyper_kin k;
  pm_hyper_dir d;
  if (!pm_hyper_kinematics(F, &k, NULL)) return false;
  pm_hyper_direction(&k, dF, &d);
  double D1[9];
  pm_hyper_ibar1_stress(&k, D1);
  pm_hyper_ibar1_tangent(&k, &d, D1, dP);
  for (int i = 0; i < 9; i++) dP[i] *= 0.5 * mu;
  pm_hyper_vol_tangent(&k, &d, pm_hyper_vol_log(&k, K), dP);
  return true;
}

/* U(J) of the split W = W_iso + U(J). */
static void volumetric(const pm_material *m, double J, double U[3]) {
  pm_hyper_u_log(m->c[PM_EL_K], J, U);
}

const pm_model pm_model_neo_hookean_log = {
    .name = "neo-hookean-log",
    .formula = "W = mu/2 (J^-2/3 tr C - 3) + K/2 (ln J)^2 (Simo-Hughes)",
    .kind = PM_MATERIAL_SOLID,
    .keys = pm_elastic_keys,
    .key_sets = PM_ELASTIC_KEY_SETS,
    .init = pm_elastic_init,
    .stress = stress,
    .tangent = tangent,
    .volumetric = volumetric,
};
