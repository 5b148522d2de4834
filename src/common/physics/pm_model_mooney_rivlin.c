/* pm_model_mooney_rivlin: the compressible Mooney-Rivlin model of reduced
 * invariants, W = c10 (Ibar1 - 3) + c01 (Ibar2 - 3) + K/2 (J - 1)^2,
 * Ibar2 = J^-4/3 I2; shear modulus 2 (c10 + c01) at F = I. */
#include "pm_hyper.h"

enum { MR_C10 = 0, MR_C01, MR_K };

static const pm_key keys[] = {
    {.name = "c10",
     .type = PM_KEY_NUMBER,
     .offset = PM_SLOT(MR_C10),
     .def = "nan",
     .flags = PM_KEY_REQUIRED,
     .unit = "Pa",
     .doc = "coefficient of Ibar1 - 3 (c10 + c01 > 0)"},
    {.name = "c01",
     .type = PM_KEY_NUMBER,
     .offset = PM_SLOT(MR_C01),
     .def = "nan",
     .flags = PM_KEY_REQUIRED,
     .unit = "Pa",
     .doc = "coefficient of Ibar2 - 3 (c10 + c01 > 0)"},
    PM_HYPER_BULK_KEY(MR_K),
    {0},
};

/* Checks the keys and c10 + c01 > 0 (no one key is at fault there). */
static pm_err init(pm_material *m, const char **key) {
  PM_CALL(pm_hyper_check_keys(m, key));
  const double c10 = m->c[MR_C10], c01 = m->c[MR_C01], K = m->c[MR_K];
  if (!(c10 + c01 > 0))
    return PM_ERROR(PM_ERR_ARG,
                    "expected c10 + c01 > 0 (the shear modulus is 2 (c10 + "
                    "c01)), got c10 = %g and c01 = %g",
                    c10, c01);
  const double mu = 2 * (c10 + c01);
  pm_material_reference(m, mu, K, K + 4.0 / 3.0 * mu);
  return PM_SUCCESS;
}

/* P = c10 dIbar1/dF + c01 dIbar2/dF + K (J - 1) cof F. */
static bool stress(const pm_material *m, const double F[9], const double *st,
                   double P[9], double *W, double *Jout) {
  (void)st;
  const double c10 = m->c[MR_C10], c01 = m->c[MR_C01];
  pm_hyper_kin k;
  if (!pm_hyper_kinematics(F, &k, Jout)) return false;
  pm_hyper_vol v = pm_hyper_vol_quadratic(&k, m->c[MR_K]);
  double I1m3, I2m3, D1[9], D2[9];
  pm_hyper_ibar12(&k, &I1m3, &I2m3);
  pm_hyper_ibar1_stress(&k, D1);
  pm_hyper_ibar2_stress(&k, D2);
  for (int i = 0; i < 9; i++) P[i] = c10 * D1[i] + c01 * D2[i];
  pm_hyper_vol_stress(&k, v, P);
  if (W) *W = c10 * I1m3 + c01 * I2m3 + v.U;
  return pm_hyper_finite(P);
}

/* W is linear in Ibar1 and Ibar2: dP = c10 dD1 + c01 dD2 + d(U' cof F). */
static bool tangent(const pm_material *m, const double F[9], const double *st,
                    const double dF[9], double dP[9]) {
  (void)st;
  const double c10 = m->c[MR_C10], c01 = m->c[MR_C01];
  pm_hyper_kin k;
  pm_hyper_dir d;
  if (!pm_hyper_kinematics(F, &k, NULL)) return false;
  pm_hyper_direction(&k, dF, &d);
  double D1[9], D2[9], dD1[9], dD2[9];
  pm_hyper_ibar1_stress(&k, D1);
  pm_hyper_ibar2_stress(&k, D2);
  pm_hyper_ibar1_tangent(&k, &d, D1, dD1);
  pm_hyper_ibar2_tangent(&k, &d, D2, dD2);
  for (int i = 0; i < 9; i++) dP[i] = c10 * dD1[i] + c01 * dD2[i];
  pm_hyper_vol_tangent(&k, &d, pm_hyper_vol_quadratic(&k, m->c[MR_K]), dP);
  return true;
}

/* U(J) of the split W = W_iso + U(J). */
static void volumetric(const pm_material *m, double J, double U[3]) {
  pm_hyper_u_quadratic(m->c[MR_K], J, U);
}

const pm_model pm_model_mooney_rivlin = {
    .name = "mooney-rivlin",
    .formula = "W = c10 (Ibar1 - 3) + c01 (Ibar2 - 3) + K/2 (J - 1)^2, "
               "Ibar1 = J^-2/3 I1, Ibar2 = J^-4/3 I2",
    .kind = PM_MATERIAL_SOLID,
    .keys = keys,
    .init = init,
    .stress = stress,
    .tangent = tangent,
    .volumetric = volumetric,
};
