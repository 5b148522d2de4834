"""The fold at the clamped edges of F4, measured on a kept run (--keep, then
--fold): how far the free faces rise past the clamp's plane, how far the
elements there are squeezed or inverted, and where the reaction sits."""

import glob
import os

import numpy as np
from numpy.polynomial.legendre import leggauss

from .cases import moduli
from .ccx import last_block, read_dat
from .deck import job_name
from .mesh import make_mesh, serendipity, serendipity_gradient

# The strain energy is split at this distance (m) from the loaded face's
# edges with the free faces: the band along them against the rest.
BAND = 0.005


def displacement(spec, n, reduced, work):
    """The mesh of ladder value n and the nodal displacement ([nodes][3])
    of its kept run under work at the last load reached, with that load
    fraction; SystemExit when the run is not there."""
    mesh = make_mesh(spec, n)
    rundir = os.path.join(work, job_name(spec["name"], spec, n, reduced))
    dat = glob.glob(os.path.join(rundir, "*.dat"))
    if not dat:
        raise SystemExit("--fold: no kept run in %s (run it with --keep)"
                         % rundir)
    block = last_block(read_dat(dat[0]), "displacements", "NALL")
    u = np.zeros((mesh.n_nodes, 3))
    for r in block[3]:
        if int(r[0]) <= mesh.n_nodes:  # the plates' nodes follow the body's
            u[int(r[0]) - 1] = r[1:4]
    return mesh, u, block[2]


def piola(F, mu, kappa):
    """First Piola-Kirchhoff stress of CalculiX's neo-Hookean solid at the
    deformation gradients F ([k][3][3]); |J| stands in J^(-2/3) where an
    element is inverted, so that the figure stays finite."""
    J = np.linalg.det(F)
    FiT = np.transpose(np.linalg.inv(F), (0, 2, 1))
    I1 = np.einsum("eij,eij->e", F, F)
    return (mu * np.abs(J)[:, None, None] ** (-2.0 / 3.0)
            * (F - (I1 / 3.0)[:, None, None] * FiT)
            + (kappa * (J - 1.0) * J)[:, None, None] * FiT)


def gradients(mesh, u, xi, elements):
    """Deformation gradients of elements at natural point xi and the shape
    functions' reference gradients there ([e][node][axis])."""
    g = np.array([serendipity_gradient(o, xi) for o in mesh.local])
    dN = np.einsum("ak,ek->eak", g, 2.0 / mesh.size[elements])
    F = np.eye(3) + np.einsum("eai,eaj->eij", u[mesh.conn[elements] - 1], dN)
    return F, dN


def fold(spec, n, reduced, work):
    """The fold's measures of the kept run of mesh n (3-D, the top face
    loaded along z): a dict of the load fraction, the clamp plane's height,
    the highest free-face node above it (mm) with its depth below the edge
    and its distance outside the block (mm), the number of free-face nodes
    above the plane, the smallest J at the 27 Gauss points and at 6 x 6
    points of the loaded face, the face points with J <= 0, the loaded
    face's nodal force (whole block, N; the plates' share not in it) and
    the mean strain energy density (J/m^3 of the part) within BAND of the
    loaded face's edges with the free faces and elsewhere."""
    mesh, u, reached = displacement(spec, n, reduced, work)
    X, x = mesh.x, mesh.x + u
    hi = mesh.hi
    uz = spec["faces"]["zmax"][2] * reached
    plane = hi[2] + uz
    free = (np.abs(X[:, 0] - hi[0]) < 1e-12) | (np.abs(X[:, 1] - hi[1]) < 1e-12)
    rise = np.where(free, x[:, 2] - plane, -np.inf)
    top = int(np.argmax(rise))
    out = dict(N=n, reached=reached, plane=plane, rise=rise[top] * 1e3,
               depth=(hi[2] - X[top, 2]) * 1e3,
               outside=max(x[top, 0] - hi[0], x[top, 1] - hi[1]) * 1e3,
               above=int(np.sum(rise > 1e-9)), free=int(np.sum(free)))
    mu, kappa = moduli(spec["nu"])
    scale = 4.0 if len(spec["mirrors"]) >= 2 else 1.0
    all_e = np.arange(len(mesh.conn))
    gx, gw = leggauss(3)
    force = np.zeros((mesh.n_nodes, 3))
    jmin, band, rest = np.inf, 0.0, 0.0
    vol = np.prod(mesh.size / 2.0, axis=1)
    corners = X[mesh.conn - 1]
    for i, a in enumerate(gx):
        for j, b in enumerate(gx):
            for k, c in enumerate(gx):
                F, dN = gradients(mesh, u, (a, b, c), all_e)
                J = np.linalg.det(F)
                jmin = min(jmin, float(np.min(J)))
                w = gw[i] * gw[j] * gw[k] * vol
                shape = np.array([serendipity(o, (a, b, c))
                                  for o in mesh.local])
                at = np.einsum("a,eak->ek", shape, corners)
                near = np.hypot(hi[2] - at[:, 2], np.minimum(
                    hi[0] - at[:, 0], hi[1] - at[:, 1])) < BAND
                I1 = np.einsum("eij,eij->e", F, F)
                W = (0.5 * mu * (np.abs(J) ** (-2.0 / 3.0) * I1 - 3.0)
                     + 0.5 * kappa * (J - 1.0) ** 2) * w
                band += float(np.sum(W[near]))
                rest += float(np.sum(W[~near]))
                fe = np.einsum("eij,eaj->eai", piola(F, mu, kappa), dN)
                np.add.at(force, mesh.conn - 1, fe * w[:, None, None])
    loaded = np.abs(X[:, 2] - hi[2]) < 1e-12
    out["jmin_gauss"] = jmin
    out["reaction"] = scale * float(np.sum(force[loaded, 2]))
    # The loaded face's points: J.
    px = leggauss(6)[0]
    face_e = np.where(np.abs(corners[:, :, 2].max(axis=1) - hi[2])
                      < 1e-12)[0]
    jface, bad = np.inf, 0
    for a in px:
        for b in px:
            J = np.linalg.det(gradients(mesh, u, (a, b, 1.0), face_e)[0])
            jface = min(jface, float(np.min(J)))
            bad += int(np.sum(J <= 0.0))
    part = np.prod(np.array(hi) - np.array(mesh.lo))
    out.update(jmin_face=jface, inverted_face=bad, sed_band=band / part,
               sed_rest=rest / part)
    return out


def fold_table(name, spec, ladder, reduced, work):
    """The markdown table of fold() over the kept runs of ladder."""
    spec = dict(spec, name=name)
    lines = ["| N | load reached | rise above the clamp's plane (mm) | at "
             "(mm below the edge, outside) | free-face nodes above | min J, "
             "Gauss points | min J, loaded face | face points J <= 0 | "
             "loaded face's force (N) | mean SED within %g mm of the loaded "
             "face's free edges (J/m^3) | elsewhere (J/m^3) |"
             % (BAND * 1e3), "|" + "---|" * 11]
    for n in ladder:
        f = fold(spec, n, reduced, work)
        lines.append("| %d | %.3f | %.2f | %.1f, %.1f | %d of %d | %.3f | "
                     "%.3f | %d | %.4f | %.3f | %.3f |" % (
                         n, f["reached"], f["rise"], f["depth"], f["outside"],
                         f["above"], f["free"], f["jmin_gauss"],
                         f["jmin_face"], f["inverted_face"], f["reaction"],
                         f["sed_band"], f["sed_rest"]))
    return "\n".join(lines)
