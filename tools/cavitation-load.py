#!/usr/bin/env python3
"""The hydrostatic tension at which a void opens from a point in the
project's neo-Hookean solid.

The model (src/common/physics/pm_model_neo_hookean.c, the FPM paper's eq.
27) is W = mu/2 (J^-2/3 tr C - 3) + K/2 (J - 1)^2.  Under a hydrostatic
tension at infinity a solid body is in equilibrium homogeneously, and past
a load a second, radially symmetric equilibrium branches off it: a void
grown from a point (Ball 1982), which for an incompressible neo-Hookean
solid opens at a Cauchy tension of 5 mu / 2.  This computes the branch's
load for finite K: the radial deformation r(R) of a ball of radius B
around a cavity of radius c (reference radius A << c << B), traction-free
on the cavity, integrated outward as a first-order system in s = ln R for
r and q = R^2 dW/dlambda_r,

    dr/ds = R lambda_r,   dq/ds = R^2 dW/dlambda_theta   (both hoop
    stretches together), lambda_r from dW/dlambda_r = q / R^2,

and reports the radial Cauchy stress at R = B, the far field's tension,
which does not change as A / c and c / B go to 0 (it is printed for three
of each, so that a reader sees it settled).

usage: tools/cavitation-load.py [E POISSON]   (default: the block cases'
E = 3000 Pa, nu = 0.495)
"""
import sys
import warnings

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq


def dW_radial(l1, l, mu, K):
    """dW/dlambda_r at radial stretch l1 and hoop stretch l."""
    I, J = l1 * l1 + 2 * l * l, l1 * l * l
    return (mu / 2 * (-(2 / 3) * J ** (-5 / 3) * l * l * I
                      + 2 * l1 * J ** (-2 / 3)) + K * (J - 1) * l * l)


def dW_hoop(l1, l, mu, K):
    """dW/dlambda_theta, both hoop directions stretched by l."""
    I, J = l1 * l1 + 2 * l * l, l1 * l * l
    return (mu / 2 * (-(2 / 3) * J ** (-5 / 3) * 2 * l1 * l * I
                      + 4 * l * J ** (-2 / 3)) + K * (J - 1) * 2 * l1 * l)


def radial_stretch(t, l, mu, K):
    """lambda_r where dW/dlambda_r = t (it grows with lambda_r)."""
    f = lambda x: dW_radial(x, l, mu, K) - t
    lo, hi = 1e-12, 1.0
    while f(hi) < 0:
        hi *= 2
    while f(lo) > 0:
        lo /= 2
    return brentq(f, lo, hi, xtol=1e-15, rtol=1e-13)


def far_tension(mu, K, A, c, B=1.0):
    """The radial Cauchy stress at R = B of the branch with a cavity of
    radius c grown from reference radius A."""
    def rhs(s, y):
        R = np.exp(s)
        r, q = y
        l = r / R
        l1 = radial_stretch(q / (R * R), l, mu, K)
        return [R * l1, R * R * dW_hoop(l1, l, mu, K)]

    # (absolute tolerances far below the values near the cavity, where q
    # is of order mu A^2: looser ones moved the load by 5e-6 for mu = 1)
    sol = solve_ivp(rhs, [np.log(A), np.log(B)], [c, 0.0], method="DOP853",
                    rtol=1e-11, atol=[1e-18 * B, 1e-18 * mu])
    if not sol.success:
        raise RuntimeError(sol.message)
    r, q = sol.y[:, -1]
    l = r / B
    l1 = radial_stretch(q / (B * B), l, mu, K)
    return l1 * dW_radial(l1, l, mu, K) / (l1 * l * l)


def main():
    # Trial steps past the stretches the model can give overflow; the step
    # control rejects them.
    warnings.filterwarnings("ignore", category=RuntimeWarning)
    E, nu = (float(sys.argv[1]), float(sys.argv[2])) if len(sys.argv) == 3 \
        else (3000.0, 0.495)
    mu, K = E / (2 * (1 + nu)), E / (3 * (1 - 2 * nu))
    print(f"E = {E:g} Pa, nu = {nu:g}: mu = {mu:.6g} Pa, K = {K:.6g} Pa, "
          f"K / mu = {K / mu:.5g}")
    for c, ratio in [(1e-2, 1e-5), (1e-3, 1e-7), (1e-4, 1e-9)]:
        t = far_tension(mu, K, c * ratio, c)
        print(f"  cavity c / B = {c:.0e}, A / c = {ratio:.0e}: "
              f"tension {t:.6g} Pa = {t / mu:.5f} mu")
    print(f"  (incompressible limit: 5 mu / 2 = {2.5 * mu:.6g} Pa)")


if __name__ == "__main__":
    main()
