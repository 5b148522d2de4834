/* pm_model_fluid: compressible viscous fluids as an entry of the material
 * table: the keys of the equation of state and the viscosities (the
 * physics itself is in pm_fluid.h). */
#include <math.h>
#include <stddef.h>

#include "pm_models.h"

static const pm_name eos_names[] = {
    {"ideal-gas", PM_EOS_IDEAL_GAS},
    {"stiffened-gas", PM_EOS_STIFFENED_GAS},
    {NULL, 0},
};

#define FLUID(field) (offsetof(pm_material, fluid) + offsetof(pm_fluid, field))

static const pm_key eos_keys[] = {
    {.name = "type",
     .type = PM_KEY_ENUM,
     .offset = offsetof(pm_fluid, eos),
     .flags = PM_KEY_REQUIRED,
     .names = eos_names,
     .doc = "ideal-gas: P = (gamma - 1) rho e; stiffened-gas: P = (gamma - "
            "1) rho e - gamma p_inf"},
    {.name = "gamma",
     .type = PM_KEY_NUMBER,
     .offset = offsetof(pm_fluid, gamma),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .lo = 1,
     .unit = "",
     .doc = "ratio of specific heats"},
    {.name = "p_inf",
     .type = PM_KEY_NUMBER,
     .offset = offsetof(pm_fluid, p_inf),
     .def = "nan",
     .range = PM_RANGE_GE,
     .lo = 0,
     .unit = "Pa",
     .doc = "stiffening pressure (stiffened-gas only)"},
    {0},
};

static const pm_key fluid_keys[] = {
    {.name = "viscosity",
     .type = PM_KEY_NUMBER,
     .offset = FLUID(viscosity),
     .def = "0",
     .range = PM_RANGE_GE,
     .lo = 0,
     .unit = "Pa s",
     .doc = "shear viscosity mu (eq. 23)"},
    {.name = "bulk_viscosity",
     .type = PM_KEY_NUMBER,
     .offset = FLUID(bulk_viscosity),
     .def = "0",
     .unit = "Pa s",
     .doc = "lambda of eq. 23, >= -2/3 viscosity (Stokes: = -2/3 viscosity)"},
    {.name = "eos",
     .type = PM_KEY_MAPPING,
     .offset = offsetof(pm_material, fluid),
     .flags = PM_KEY_REQUIRED,
     .keys = eos_keys,
     .doc = "equation of state: {type, gamma, p_inf}"},
    {0},
};

static pm_err init(pm_material *m, const char **key) {
  pm_fluid *f = &m->fluid;
  *key = NULL;
  f->density = m->density;
  if (f->eos == PM_EOS_IDEAL_GAS && !isnan(f->p_inf)) {
    *key = "eos.p_inf";
    return PM_ERROR(PM_ERR_ARG, "expected no p_inf for type ideal-gas (use "
                                "stiffened-gas), got p_inf");
  }
  if (isnan(f->p_inf)) f->p_inf = 0;
  /* lambda >= -2 mu / 3: a non-negative bulk viscosity lambda + 2 mu / 3
   * (Stokes' condition is lambda = -2 mu / 3). */
  if (!(f->bulk_viscosity >= -2.0 / 3.0 * f->viscosity * (1 + 1e-12))) {
    *key = "bulk_viscosity";
    return PM_ERROR(PM_ERR_ARG,
                    "expected a number >= -2/3 viscosity (Stokes: -2/3 "
                    "viscosity), got %g",
                    f->bulk_viscosity);
  }
  /* The response depends on the state (sound speed from the EOS): no
   * reference moduli. */
  m->shear_modulus = 0;
  m->bulk_modulus = 0;
  m->youngs_modulus = 0;
  m->poisson_ratio = 0.5;
  m->wave_modulus = 0;
  m->wave_speed = 0;
  return PM_SUCCESS;
}

const pm_model pm_model_fluid = {
    .name = "fluid",
    .formula = "sigma = 2 mu D + lambda tr(D) I - P(rho, e) I (eq. 23)",
    .kind = PM_MATERIAL_FLUID,
    .keys = fluid_keys,
    .init = init,
};
