/* pm_riemann: exact solution of the Riemann problem for the 1D Euler
 * equations of an ideal (gamma-law) gas, the reference for shock tubes. */
#ifndef PM_RIEMANN_H
#define PM_RIEMANN_H

#include "pm_error.h"

/* A uniform gas state: density (kg/m^3), velocity (m/s), pressure (Pa). */
typedef struct {
  double rho, u, p;
} pm_riemann_state;

/* The solved wave pattern.  Left to right: the left wave (a shock or a
 * rarefaction fan), the star region left of the contact, the contact, the
 * star region right of it, the right wave.  The solution is self-similar:
 * it depends on xi = (x - x0) / t only. */
typedef struct {
  double gamma;
  pm_riemann_state left, right;
  double p_star, u_star; /* star region pressure and velocity */
  double rho_star_left, rho_star_right;
  int left_shock, right_shock; /* 1 shock, 0 rarefaction */
  /* Wave speeds (m/s): left wave head/tail (both the shock speed for a
   * shock), contact, right wave tail/head (both the shock speed for a
   * shock).  They are non-decreasing from left to right. */
  double s_left_head, s_left_tail, s_contact, s_right_tail, s_right_head;
  int iterations; /* pressure iterations used */
} pm_riemann;

/* Solve the Riemann problem of the states left (x < x0) and right (x > x0)
 * at t = 0 for the adiabatic exponent gamma, filling *out.  The star
 * pressure is found by a safeguarded Newton iteration to about 1e-14
 * relative.  Returns PM_ERR_ARG for a non-positive or non-finite density or
 * pressure, a non-finite velocity, gamma <= 1 or out == NULL;
 * PM_ERR_UNSTABLE when the states pull apart fast enough to generate a
 * vacuum (u_R - u_L >= 2 (c_L + c_R) / (gamma - 1)), which this solver does
 * not represent; PM_ERR_NOT_CONVERGED if the iteration fails.  On failure
 * the star fields of *out are NaN. */
pm_err pm_riemann_solve(double gamma, pm_riemann_state left,
                        pm_riemann_state right, pm_riemann *out);

/* The solution at the similarity coordinate xi = (x - x0) / t: density,
 * velocity and pressure into *rho, *u, *p (none may be NULL).  A point on
 * the contact (xi == s_contact) gets the left star state. */
void pm_riemann_sample(const pm_riemann *r, double xi, double *rho, double *u,
                       double *p);

/* Specific internal energy (J/kg) of an ideal gas, p / ((gamma - 1) rho). */
double pm_riemann_energy(double gamma, double rho, double p);

#endif
