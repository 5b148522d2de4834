/* pm_models: the entries of the constitutive table and what several of them
 * share.  Private to src/common/physics: backends use pm_material.h. */
#ifndef PM_MODELS_H
#define PM_MODELS_H

#include <stddef.h>

#include "pm_material.h"

extern const pm_model pm_model_neo_hookean;
extern const pm_model pm_model_neo_hookean_log;
extern const pm_model pm_model_mooney_rivlin;
extern const pm_model pm_model_ogden;
extern const pm_model pm_model_holzapfel_gasser_ogden;
extern const pm_model pm_model_linear_elastic;
extern const pm_model pm_model_fluid;

/* Offset of constant slot k of pm_material, for key tables. */
#define PM_SLOT(k) (offsetof(pm_material, c) + (size_t)(k) * sizeof(double))
/* Offset of count slot k. */
#define PM_COUNT(k) (offsetof(pm_material, n) + (size_t)(k) * sizeof(int))

/* The isotropic elastic constants of the models that take Young's modulus
 * and Poisson's ratio, or the shear and bulk moduli, in slots:
 *   E, nu, mu, K (keyed, NaN when absent) and lambda (derived). */
enum { PM_EL_E = 0, PM_EL_NU, PM_EL_MU, PM_EL_K, PM_EL_LAMBDA, PM_EL_SLOTS };

/* The keys of that pair of forms (shared by neo-hookean, neo-hookean-log
 * and linear-elastic, whose parameters are the same). */
extern const pm_key pm_elastic_keys[];

#define PM_ELASTIC_KEY_SETS                                                    \
  "youngs_modulus and poisson_ratio, or shear_modulus and bulk_modulus"

/* Derive mu, K, lambda (and E, nu) from whichever pair was given and set
 * the reference figures (wave modulus lambda + 2 mu).  Fails naming the
 * missing or extra key. */
pm_err pm_elastic_init(pm_material *m, const char **key);

/* Reference figures from mu_0, K_0 and the P-wave modulus. */
void pm_material_reference(pm_material *m, double mu, double K,
                           double wave_modulus);

#endif
