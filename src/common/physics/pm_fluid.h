/* pm_fluid: compressible viscous fluids shared by every backend: the
 * equations of state (ideal gas, stiffened gas), the Newtonian viscous
 * stress and the artificial viscosity of shocks.  Equation numbers refer to
 * papers/mpm-fluid-membrane-zona-piezo-icsi.txt. */
#ifndef PM_FLUID_H
#define PM_FLUID_H

#include <math.h>

typedef enum {
  PM_EOS_NONE = 0,     /* not a fluid */
  PM_EOS_IDEAL_GAS,    /* P = (gamma - 1) rho e */
  PM_EOS_STIFFENED_GAS /* P = (gamma - 1) rho e - gamma P_inf (eq. 37 with
                          Gamma = gamma - 1) */
} pm_eos;

typedef struct {
  pm_eos eos;
  double gamma;          /* ratio of specific heats, > 1 */
  double p_inf;          /* stiffening pressure P_inf, Pa (0: ideal gas) */
  double density;        /* reference density, kg/m^3 */
  double viscosity;      /* shear viscosity mu, Pa s (eq. 23) */
  double bulk_viscosity; /* lambda of eq. 23, Pa s */
} pm_fluid;

/* Pressure from density and specific internal energy (eqs. 24, 37). */
static inline double pm_eos_pressure(const pm_fluid *f, double rho, double e) {
  return (f->gamma - 1.0) * rho * e - f->gamma * f->p_inf;
}

/* Specific internal energy from density and pressure (inverse of the
 * above). */
static inline double pm_eos_energy(const pm_fluid *f, double rho, double p) {
  return (p + f->gamma * f->p_inf) / ((f->gamma - 1.0) * rho);
}

/* Isentropic sound speed a = sqrt(gamma (P + P_inf) / rho); 0 where the
 * state has no real sound speed. */
static inline double pm_eos_sound_speed(const pm_fluid *f, double rho,
                                        double p) {
  double a2 = f->gamma * (p + f->p_inf) / rho;
  return a2 > 0 ? sqrt(a2) : 0.0;
}

/* Artificial viscosity of eq. 32: a pressure added in compression
 * (tr D < 0), q = rho Lc (c0 Lc (tr D)^2 - c1 a tr D), Lc the cell size
 * (eq. 33), a the sound speed. */
static inline double pm_artificial_viscosity(double c0, double c1, double rho,
                                             double Lc, double a, double trD) {
  if (trD >= 0) return 0.0;
  return rho * Lc * (c0 * Lc * trD * trD - c1 * a * trD);
}

/* Newtonian viscous stress of eq. 23 without the pressure:
 * tau = 2 mu D + lambda tr(D) I for the rate of deformation D (9,
 * row-major, symmetric). */
static inline void pm_fluid_viscous_stress(const pm_fluid *f, const double D[9],
                                           double tau[9]) {
  double tr = D[0] + D[4] + D[8];
  for (int k = 0; k < 9; k++) tau[k] = 2.0 * f->viscosity * D[k];
  tau[0] += f->bulk_viscosity * tr;
  tau[4] += f->bulk_viscosity * tr;
  tau[8] += f->bulk_viscosity * tr;
}

const char *pm_eos_name(pm_eos eos);

#endif
