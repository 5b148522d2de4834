#!/usr/bin/env python3
"""The reference of a thick ring (plane strain) under internal pressure,
for the follower pressure of cases/fpm/ring/ring-pressure.yaml.

The ring (radii A, B) of the standard compressible neo-Hookean solid of
pointmech, W = mu/2 (J^-2/3 I1 - 3) + K/2 (J - 1)^2, deforms radially:
r(R), stretches lr = r', lt = r/R, lz = 1.  Equilibrium of the nominal
stress, d(R P_r)/dR = P_t, with P_r(A) = -p lt(A) (the Cauchy stress -p on
the deformed inner face) and P_r(B) = 0, is a two-point boundary-value
problem solved here to 1e-10 (scipy's solve_bvp, derivatives by complex
steps); at small p it is Lame's solution.  Given a run folder, the points'
radial displacement is compared with it.

    tools/ring-pressure.py --p 300                 # the reference alone
    tools/ring-pressure.py --p 300 out/ring        # and a run against it

Needs numpy and scipy (/usr/bin/python3); a run folder needs h5py.
"""

import argparse
import os
import sys

import numpy as np
from scipy.integrate import solve_bvp


def stresses(lr, lt, mu, kappa):
    """Nominal radial and hoop stresses at stretches lr, lt (lz = 1)."""
    J = lr * lt
    I1 = lr * lr + lt * lt + 1
    Jm23 = J ** (-2.0 / 3.0)
    common = -mu / 3.0 * Jm23 * I1 / J + kappa * (J - 1)
    return mu * Jm23 * lr + common * lt, mu * Jm23 * lt + common * lr


def solve(p, A, B, mu, kappa):
    """r(R) on [A, B] as a callable, and its mesh's residual."""
    h = 1e-30

    def rhs(R, y):
        r, rp = y
        lt = r / R
        Pr, Pt = stresses(rp, lt, mu, kappa)
        # dPr/dlr, dPr/dlt by complex steps (exact to round-off)
        dlr = stresses(rp + 1j * h, lt, mu, kappa)[0].imag / h
        dlt = stresses(rp, lt + 1j * h, mu, kappa)[0].imag / h
        # Pr + R (dlr r'' + dlt (r'/R - r/R^2)) = Pt
        rpp = ((Pt - Pr) / R - dlt * (rp / R - r / (R * R))) / dlr
        return np.vstack([rp, rpp])

    def bc(ya, yb):
        Pa = stresses(ya[1], ya[0] / A, mu, kappa)[0]
        Pb = stresses(yb[1], yb[0] / B, mu, kappa)[0]
        return np.array([Pa + p * ya[0] / A, Pb])

    R = np.linspace(A, B, 201)
    sol = solve_bvp(rhs, bc, R, np.vstack([R, np.ones_like(R)]), tol=1e-10,
                    max_nodes=100000)
    if not sol.success:
        sys.exit("ring-pressure: the boundary-value problem failed: "
                 + sol.message)
    return sol


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", nargs="?", help="a run folder to compare")
    ap.add_argument("--p", type=float, default=300, help="pressure, Pa")
    ap.add_argument("--radii", default="1,2", help="A,B in m")
    ap.add_argument("--E", type=float, default=3000)
    ap.add_argument("--nu", type=float, default=0.3)
    a = ap.parse_args()
    A, B = (float(v) for v in a.radii.split(","))
    mu = a.E / (2 * (1 + a.nu))
    kappa = a.E / (3 * (1 - 2 * a.nu))
    sol = solve(a.p, A, B, mu, kappa)
    ua, ub = sol.sol(A)[0] - A, sol.sol(B)[0] - B
    print(f"p = {a.p:g} Pa: u_r(A) = {ua:.6g} m, u_r(B) = {ub:.6g} m "
          f"(hoop stretch at A {1 + ua / A:.5f})")
    if not a.run:
        return 0
    sys.path.insert(0, os.path.join(os.path.dirname(
        os.path.abspath(__file__)), "..", "python"))
    import pointmech
    run = pointmech.open(a.run)
    x = run.mesh["coordinates"]
    u = run.frames[-1]["displacement"]
    R = np.hypot(x[:, 0], x[:, 1])
    ur = (u[:, 0] * x[:, 0] + u[:, 1] * x[:, 1]) / R
    ex = sol.sol(np.clip(R, A, B))[0] - R
    inner = np.abs(R - A) < 1e-6 * A
    rms = np.sqrt(np.mean((ur - ex) ** 2)) / abs(ua)
    print(f"{a.run}: {len(R)} points, inner u_r {ur[inner].mean():.6g} m "
          f"(error {(ur[inner].mean() - ua) / ua:+.3e}), RMS error of u_r "
          f"over u_r(A) {rms:.3e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
