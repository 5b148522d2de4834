/* pm_cavitation: the hydrostatic tension at which a void opens from a point
 * in an isotropic hyperelastic solid (Ball 1982).
 *
 * Under a hydrostatic tension t at infinity a solid is in equilibrium
 * homogeneously, and past a load a second, radially symmetric equilibrium
 * branches off: a cavity grown from a point, traction-free.  For an
 * incompressible neo-Hookean solid the branch opens at t = 5 mu / 2; for a
 * compressible one somewhat below (2.327 mu at K = 99.7 mu, the block
 * cases' material).  A body whose smooth solution carries more tension
 * than this anywhere admits the void there: refining its discretization
 * finds it, and no solver holds the smooth branch past it.
 *
 * The load is found by shooting: the radial deformation r(R) of a ball of
 * radius B around a cavity of current radius c (reference radius A << c
 * << B), integrated outward in s = ln R from the traction-free cavity as a
 * first-order system for r and q = R^2 dW/dlambda_r,
 *
 *   dr/ds = R lambda_r,   dq/ds = R^2 (dW/dlambda_2 + dW/dlambda_3),
 *
 * lambda_r from dW/dlambda_r(lambda_r, r / R) = q / R^2, by a fifth-order
 * Runge-Kutta pair with step control (Dormand and Prince).  The tension at
 * R = B is the radial Cauchy stress there.  The principal derivatives are
 * the model's first Piola-Kirchhoff stress of F = diag(lambda_r, lambda,
 * lambda), so every isotropic model of the table serves. */
#ifndef PM_CAVITATION_H
#define PM_CAVITATION_H

#include "pm_material.h"

/* The far-field tension (Pa) of the branch whose cavity has current
 * radius c grown from reference radius a, in a ball of radius 1.  NaN
 * where the integration fails (the model cannot be followed to such
 * stretches). */
double pm_cavitation_tension(const pm_material *m, double a, double c);

/* The cavitation load of material m (Pa): the tension that holds a
 * cavity of 1e-4 of the ball grown from a seed of 1e-9 of its radius,
 * where the branch has settled as the seed shrinks: for the neo-Hookean
 * solid to 1e-9 of the load.  A model whose hoop energy grows faster
 * (Mooney-Rivlin with c01 > 0) still rises slowly as the seed shrinks, and
 * more so toward incompressibility, where it has no finite load (Ball):
 * the figure is then the tension that opens a void from a seed that small.
 * NaN for a fluid, a model with per-point state (fibres: not isotropic) or
 * one the integration cannot follow. */
double pm_cavitation_load(const pm_material *m);

#endif
