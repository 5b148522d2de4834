#!/usr/bin/python3
"""Draw the deformed points of one or more pointmech runs side by side.

Each OUT is a run directory (or its results.h5), read through the
project's Python module (python/pointmech): the program vets each HDF5
file before h5py opens it, and a damaged one is refused with its name and
the reason.  One subplot per run, all with the same axis limits and equal
aspect.  2-D runs (all z == 0, or triangle cells): the deformed triangulation
drawn faintly, the deformed points as dots and the undeformed box outline
dashed grey.  3-D runs: the x-z projection of the deformed points.  The
last frame is drawn unless --frame N picks another (index into the frames
in time order; negative counts from the end).

--subdomains (2-D only) draws, instead of the triangle edges, each point's
median-dual subdomain deformed by that point's own linear field
u_i + G_i (X - X_i), G_i the weighted least-squares (generalized finite
difference) gradient over the mesh-edge neighbours, w = 1/|X_k - X_i|^2.
Gaps and overlaps between the pieces show the inter-subdomain jumps that
the interior penalty of the Fragile Points Method controls; the largest
jump at shared corners is printed per run.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
import pointmech  # noqa: E402


def fail(msg):
    sys.exit(f"plot-points: {msg}")


def load(out, frame):
    """Return (deformed [n][3], reference [n][3], cells, frame name)."""
    try:
        r = pointmech.open(out)
        x, deformed, fr = r.positions(frame)
        if "cells" not in r.mesh:
            fail(f"{r.folder}/results/mesh.h5: missing /cells")
        cells = np.asarray(r.mesh["cells"])
    except (pointmech.Refused, OSError) as e:
        fail(e)
    if cells.ndim != 2 or (cells.size and
                           (cells.min() < 0 or cells.max() >= len(x))):
        fail(f"{r.folder}: /mesh/cells must be [m][k] point indices < "
             f"{len(x)}")
    return deformed, x, cells, f"{fr.index:06d}"


def gradients(x, u, cells):
    """Per-point 2x2 least-squares displacement gradients G [n][2][2]."""
    e = np.vstack([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]])
    e = np.unique(np.sort(e, axis=1), axis=0)
    i, k = np.vstack([e, e[:, ::-1]]).T  # directed mesh edges i -> k
    dx, du = x[k] - x[i], u[k] - u[i]
    r2 = (dx ** 2).sum(axis=1)
    if not r2.all():
        fail("--subdomains: the mesh has a zero-length edge")
    w = (1.0 / r2)[:, None, None]
    A, B = np.zeros((len(x), 2, 2)), np.zeros((len(x), 2, 2))
    np.add.at(A, i, w * dx[:, :, None] * dx[:, None, :])
    np.add.at(B, i, w * du[:, :, None] * dx[:, None, :])
    bad = np.flatnonzero(np.linalg.det(A) <= 1e-12 * np.trace(A, axis1=1, axis2=2) ** 2)
    if len(bad):
        fail(f"--subdomains: the neighbours of point {bad[0]} at "
             f"{x[bad[0]].tolist()} do not span the plane; no gradient")
    return B @ np.linalg.inv(A), e  # normal equations: G A = B


def subdomains(x, u, cells, magnify):
    """Deformed median-dual quadrilaterals [3m][4][2], and the jumps between
    neighbouring points' linear fields at edge midpoints and centroids."""
    x, u = x[:, :2], u[:, :2]
    G, edges = gradients(x, u, cells)

    def field(i, p):  # point i's linear field at positions p
        return u[i] + np.einsum("...ab,...b->...a", G[i], p - x[i])

    tri = cells[:, [0, 1, 2, 1, 2, 0, 2, 0, 1]].reshape(-1, 3)  # (i, j, k)
    i, j, k = tri.T
    quad = lambda v: np.stack([v[i], (v[i] + v[j]) / 2, v[tri].mean(axis=1),
                               (v[i] + v[k]) / 2], axis=1)
    corners, ulin = quad(x), quad(u)  # ulin: the P1 interpolant there
    poly = corners + ulin + magnify * (field(i[:, None], corners) - ulin)
    m, c = x[edges].mean(axis=1), x[cells].mean(axis=1)
    fc = [field(cells[:, v], c) for v in range(3)]
    jumps = [field(edges[:, 0], m) - field(edges[:, 1], m),
             fc[0] - fc[1], fc[1] - fc[2], fc[2] - fc[0]]
    return poly, np.linalg.norm(np.vstack(jumps), axis=1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("outs", nargs="+", metavar="OUT", help="run directory (or its results.h5)")
    ap.add_argument("--labels", metavar="L1,L2,...", help="comma-separated subplot titles "
                    "(default: the directory names)")
    ap.add_argument("--out", default="points.png", metavar="FILE.png",
                    help="PNG to write (default: points.png)")
    ap.add_argument("--frame", type=int, default=-1, metavar="N",
                    help="frame index in time order (default: -1, the last)")
    ap.add_argument("--subdomains", action="store_true",
                    help="2-D only: draw each point's median-dual subdomain "
                    "deformed by its own linear field instead of the "
                    "triangles; gaps and overlaps show the jumps between "
                    "neighbouring subdomains")
    ap.add_argument("--magnify", type=float, default=1.0, metavar="F",
                    help="with --subdomains: scale each piece's deviation from "
                    "the piecewise-linear (P1) interpolation of the nodal "
                    "displacements on its triangle by F, i.e. draw corners at "
                    "X + u_P1 + F (u_i + G_i (X - X_i) - u_P1); F = 1 (default) "
                    "is the true picture, F = 0 the P1 mesh, F > 1 "
                    "exaggerates gaps and overlaps (not the overall motion)")
    a = ap.parse_args()
    if a.magnify != 1.0 and not a.subdomains:
        fail("--magnify needs --subdomains")
    if not np.isfinite(a.magnify):
        fail(f"--magnify {a.magnify}: must be finite")
    labels = a.labels.split(",") if a.labels is not None else [
        os.path.basename(os.path.dirname(o) if os.path.isfile(o) else o)
        for o in map(os.path.abspath, a.outs)]
    if len(labels) != len(a.outs):
        fail(f"--labels gives {len(labels)} label(s) for {len(a.outs)} run(s)")

    runs, frames = [], set()
    for out in a.outs:
        y, x, cells, frame = load(out, a.frame)
        flat = cells.shape[1] == 3 or not x[:, 2].any()
        k = 1 if flat else 2  # second plotted coordinate: y in 2-D, z in 3-D
        poly, ext = None, y
        if a.subdomains:
            if not flat or cells.shape[1] != 3 or not len(cells):
                fail(f"{out}: --subdomains needs a 2-D run with triangle "
                     f"cells (this one has cells {cells.shape}, "
                     f"{'all' if flat else 'not all'} z == 0)")
            poly, jump = subdomains(x, y - x, cells, a.magnify)
            ext = np.vstack([y, np.pad(poly.reshape(-1, 2), ((0, 0), (0, 1)))])
            print(f"{out}: jump between neighbouring linear fields at shared "
                  f"corners: max {jump.max():.4g} m, rms {np.sqrt((jump ** 2).mean()):.4g}"
                  f" m (max |u| {np.linalg.norm(y - x, axis=1).max():.4g} m)")
        runs.append((y, x, cells, flat, k, poly, ext))
        frames.add(frame)
    allpts = np.vstack([np.vstack([r[6][:, [0, r[4]]], r[1][:, [0, r[4]]]])
                        for r in runs])
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    pad = 0.05 * max((hi - lo).max(), 1e-12)
    w, h = hi - lo + 2 * pad  # panel data extent: the figure follows it
    pw = 5.0 if w >= h else max(1.5, 5.0 * w / h)
    ph = min(max(pw * h / w, 1.0), 6.0)

    n = len(runs)
    fig, axes = plt.subplots(1, n, figsize=(n * (pw + 0.9), ph + 1.3),
                             squeeze=False)
    for ax, label, (y, x, cells, flat, k, poly, _) in zip(axes[0], labels, runs):
        size = max(0.5, min(12.0, 3000.0 / len(y)))
        if poly is not None:
            ax.add_collection(PolyCollection(
                poly, facecolors="C0", edgecolors="navy", linewidths=0.3,
                alpha=0.35))
            size = min(size, 4.0)
        if flat:
            if poly is None and cells.shape[1] == 3 and len(cells):
                ax.triplot(y[:, 0], y[:, 1], cells, color="C0", lw=0.3,
                           alpha=0.3)
            (x0, y0), (x1, y1) = x[:, :2].min(axis=0), x[:, :2].max(axis=0)
            ax.plot([x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0], "--",
                    color="grey", lw=1)
        ax.scatter(y[:, 0], y[:, k], s=size, color="C1", zorder=3)
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal", adjustable="box")
        ax.set(title=label, xlabel="x (m)", ylabel="y (m)" if flat else "z (m)")
    fig.suptitle((f"frame {frames.pop()}" if len(frames) == 1
                  else "last frame" if a.frame == -1
                  else f"frame index {a.frame}")
                 + ("" if not a.subdomains else ", deformed subdomains"
                    + ("" if a.magnify == 1 else f", jumps x {a.magnify:g}")))
    fig.tight_layout()
    try:
        fig.savefig(a.out, dpi=120)
    except OSError as e:
        fail(f"{a.out}: cannot write: {e.strerror or e}")
    print(a.out)


if __name__ == "__main__":
    main()
