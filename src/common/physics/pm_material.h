/* pm_material: constitutive models shared by every backend, as pure inline
 * functions of the deformation gradient (first Piola-Kirchhoff stress P,
 * second Piola-Kirchhoff S, strain energy density W per reference volume). */
#ifndef PM_MATERIAL_H
#define PM_MATERIAL_H

#include <math.h>
#include <stdbool.h>

#include "pm_error.h"
#include "pm_tensor.h"

typedef enum {
  PM_MODEL_NEO_HOOKEAN = 0, /* W = mu/2 (J^-2/3 tr C - 3) + K/2 (J - 1)^2 */
  PM_MODEL_LINEAR_ELASTIC,  /* small strain: W = lambda/2 tr(e)^2 + mu e:e */
  PM_MODEL_COUNT
} pm_model;

/* Material constants, SI units.  Derived constants are filled by
 * pm_material_init and must not be set by hand. */
typedef struct {
  pm_model model;
  double density;           /* rho_0, kg/m^3 */
  double youngs;            /* E, Pa */
  double poisson;           /* nu, in (-1, 0.5) */
  double mu, kappa, lambda; /* shear, bulk and Lame moduli, Pa (derived) */
  double wave_speed;        /* dilatational wave speed sqrt((lambda+2mu)/rho) */
} pm_material;

/* "neo-hookean", "linear-elastic". */
const char *pm_model_name(pm_model model);
/* Parse a model name; returns PM_MODEL_COUNT when unknown. */
pm_model pm_model_from_name(const char *name);

/* Fill m from (model, rho, E, nu), checking ranges (rho > 0, E > 0,
 * -1 < nu < 0.5).  Fails with PM_ERR_ARG naming the bad value. */
pm_err pm_material_init(pm_material *m, pm_model model, double density,
                        double youngs, double poisson);

/* Stress and energy at F (row-major 3x3).  Writes P (9), and *W and *J when
 * those pointers are non-NULL.  Returns false when J <= 0 or the result is
 * not finite (P is then unspecified). */
bool pm_material_stress(const pm_material *m, const double F[9], double P[9],
                        double *W, double *J);
/* Directional derivative of P at F along dF: dP = A : dF with the
 * tangent modulus A = d2W/dF dF (which has major symmetry, so also
 * B : A = dP for B = dF).  False when J <= 0. */
bool pm_material_stress_derivative(const pm_material *m, const double F[9],
                                   const double dF[9], double dP[9]);
/* Second Piola-Kirchhoff stress S = F^-1 P (9); false when J <= 0. */
bool pm_material_pk2(const pm_material *m, const double F[9], double S[9]);
/* Strain energy density W(F) alone; NaN when J <= 0. */
double pm_material_energy(const pm_material *m, const double F[9]);

/* Lateral stretch of a bar in uniaxial stress with axial stretch
 * lambda_axial (zero traction on the lateral faces), by Newton's method.
 * Fails with PM_ERR_NOT_CONVERGED if no root is found. */
pm_err pm_material_uniaxial_lateral_stretch(const pm_material *m,
                                            double lambda_axial,
                                            double *lambda_lateral);

#endif
