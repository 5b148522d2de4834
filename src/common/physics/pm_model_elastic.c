/* pm_model_elastic: the isotropic elastic constants shared by the models
 * that take (youngs_modulus, poisson_ratio) or (shear_modulus,
 * bulk_modulus), and the reference figures every model derives. */
#include <math.h>

#include "pm_models.h"

const pm_key pm_elastic_keys[] = {
    {.name = "youngs_modulus",
     .type = PM_KEY_NUMBER,
     .offset = PM_SLOT(PM_EL_E),
     .def = "nan",
     .range = PM_RANGE_GT,
     .lo = 0,
     .unit = "Pa",
     .doc = "Young's modulus E (with poisson_ratio)"},
    {.name = "poisson_ratio",
     .type = PM_KEY_NUMBER,
     .offset = PM_SLOT(PM_EL_NU),
     .def = "nan",
     .range = PM_RANGE_GT | PM_RANGE_LT,
     .lo = -1,
     .hi = 0.5,
     .unit = "",
     .doc = "Poisson's ratio nu (with youngs_modulus)"},
    {.name = "shear_modulus",
     .type = PM_KEY_NUMBER,
     .offset = PM_SLOT(PM_EL_MU),
     .def = "nan",
     .range = PM_RANGE_GT,
     .lo = 0,
     .unit = "Pa",
     .doc = "shear modulus mu (with bulk_modulus)"},
    {.name = "bulk_modulus",
     .type = PM_KEY_NUMBER,
     .offset = PM_SLOT(PM_EL_K),
     .def = "nan",
     .range = PM_RANGE_GT,
     .lo = 0,
     .unit = "Pa",
     .doc = "bulk modulus K (with shear_modulus)"},
    {0},
};

void pm_material_reference(pm_material *m, double mu, double K,
                           double wave_modulus) {
  m->shear_modulus = mu;
  m->bulk_modulus = K;
  m->youngs_modulus = 9 * K * mu / (3 * K + mu);
  m->poisson_ratio = (3 * K - 2 * mu) / (2 * (3 * K + mu));
  m->wave_modulus = wave_modulus;
  m->wave_speed = sqrt(wave_modulus / m->density);
}

pm_err pm_elastic_init(pm_material *m, const char **key) {
  double *c = m->c;
  bool has_e = !isnan(c[PM_EL_E]), has_nu = !isnan(c[PM_EL_NU]);
  bool has_mu = !isnan(c[PM_EL_MU]), has_k = !isnan(c[PM_EL_K]);
  *key = NULL;
  if ((has_e || has_nu) && (has_mu || has_k)) {
    *key = has_mu ? "shear_modulus" : "bulk_modulus";
    return PM_ERROR(PM_ERR_ARG,
                    "expected either youngs_modulus and poisson_ratio or "
                    "shear_modulus and bulk_modulus, got %s with %s",
                    has_e ? "youngs_modulus" : "poisson_ratio", *key);
  }
  if (has_e || has_nu) {
    if (!(has_e && has_nu))
      return PM_ERROR(PM_ERR_ARG, "missing required key %s (given with %s)",
                      has_e ? "poisson_ratio" : "youngs_modulus",
                      has_e ? "youngs_modulus" : "poisson_ratio");
    double E = c[PM_EL_E], nu = c[PM_EL_NU];
    c[PM_EL_MU] = E / (2 * (1 + nu));
    c[PM_EL_K] = E / (3 * (1 - 2 * nu));
    c[PM_EL_LAMBDA] = E * nu / ((1 + nu) * (1 - 2 * nu));
  } else if (has_mu || has_k) {
    if (!(has_mu && has_k))
      return PM_ERROR(PM_ERR_ARG, "missing required key %s (given with %s)",
                      has_mu ? "bulk_modulus" : "shear_modulus",
                      has_mu ? "shear_modulus" : "bulk_modulus");
    double mu = c[PM_EL_MU], K = c[PM_EL_K];
    c[PM_EL_E] = 9 * K * mu / (3 * K + mu);
    c[PM_EL_NU] = (3 * K - 2 * mu) / (2 * (3 * K + mu));
    c[PM_EL_LAMBDA] = K - 2.0 / 3.0 * mu;
  } else {
    return PM_ERROR(PM_ERR_ARG, "missing required keys: expected %s",
                    PM_ELASTIC_KEY_SETS);
  }
  pm_material_reference(m, c[PM_EL_MU], c[PM_EL_K],
                        c[PM_EL_LAMBDA] + 2 * c[PM_EL_MU]);
  /* The given pair exactly (the figures above are formed from mu, K). */
  m->youngs_modulus = c[PM_EL_E];
  m->poisson_ratio = c[PM_EL_NU];
  return PM_SUCCESS;
}
