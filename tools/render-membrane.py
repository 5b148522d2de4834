#!/usr/bin/python3
"""Render a run's membrane (the triangles of results/mesh.h5's /surface) at
chosen times, one panel per time, into one PNG.

OUT is a run directory (or its results.h5), read through the project's
Python module (python/pointmech): the program vets each HDF5 file before
h5py opens it, and a damaged one is refused with its name and the reason.
For each time of --times the frame nearest in time is drawn: its triangles
on the frame's "position" field (else the reference coordinates plus
"displacement", else the reference coordinates), each triangle coloured by
the mean of a scalar point field over its corners (--field; default
"failed" when the frames have it, else "von_mises"), and the membrane's
points with failed > 0.5 marked in red.  Every panel has the same axes and
colour scale; its title gives the frame's time in microseconds and how
many of the membrane's points have failed.

  render-membrane.py OUT --times 28e-6,52e-6,76e-6,100e-6 -o membrane.png
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import cm, colors  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
import pointmech  # noqa: E402


def fail(msg):
    sys.exit(f"render-membrane: {msg}")


def floats(text, what, count=None):
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        fail(f"{what} '{text}' is not a comma-separated list of numbers")
    if not values or (count and len(values) != count):
        fail(f"{what} '{text}': {count or 'at least one'} numbers expected")
    return values


def frame_table(r, path):
    """[(time, frame)] of every frame, in time order."""
    if len(r.frames) == 0:
        fail(f"{path}: no frame")
    table = []
    for fr in r.frames:
        if np.isnan(fr.time):
            fail(f"{fr.path}: frame {fr.index:06d} has no time attribute")
        table.append((fr.time, fr))
    return sorted(table, key=lambda tf: (tf[0], tf[1].index))


def nearest(table, t):
    k = int(np.argmin([abs(time - t) for time, _ in table]))
    return table[k]


def geometry(g, x0):
    if "position" in g:
        return np.asarray(g["position"], dtype=float)
    if "displacement" in g:
        return x0 + np.asarray(g["displacement"], dtype=float)
    return x0


def scalar(g, name, n):
    if name not in g:
        return None
    v = np.asarray(g[name], dtype=float)
    if v.shape != (n,):
        fail(f"{g.path}: field '{name}' is not a scalar field of {n} points "
             f"(shape {v.shape})")
    return v


def load(out, times, field):
    """Membrane triangles, the colour field's name and, per time asked,
    (frame time, positions, field values, failed flags or None)."""
    try:
        r = pointmech.open(out)
        path = r.folder
        r.check()  # the mesh and every frame, in one call of the program
        mesh = r.mesh
        if "surface" not in mesh:
            fail(f"{path}: no membrane (no /surface in results/mesh.h5: the "
                 "run has no surface triangles)")
        tri = np.asarray(mesh["surface"], dtype=np.int64)
        x0 = np.asarray(mesh["coordinates"], dtype=float)
        n = len(x0)
        if tri.ndim != 2 or tri.shape[1] != 3 or tri.min() < 0 or \
                tri.max() >= n:
            fail(f"{path}: the mesh's /surface is not triangles over {n} "
                 "points")
        table = frame_table(r, path)
        if field is None:
            field = "failed" if "failed" in table[0][1] else "von_mises"
        if times is None:  # four frames spread over the run
            times = list(np.linspace(table[0][0], table[-1][0], 4))
        frames = []
        for t in times:
            time, g = nearest(table, t)
            name = f"{g.index:06d}"
            values = scalar(g, field, n)
            if values is None:
                have = [k for k in g.keys() if g[k].shape == (n,)]
                fail(f"{g.path}: frame {name} has no scalar field "
                     f"'{field}' (it has: {', '.join(have) or 'none'})")
            frames.append((time, name, geometry(g, x0), values,
                           scalar(g, "failed", n)))
    except (pointmech.Refused, OSError) as e:
        fail(e)
    return tri, field, frames


def render(tri, field, frames, view, out_png):
    used = np.unique(tri)
    xs = np.concatenate([x[used] for _, _, x, _, _ in frames])
    lo, hi = xs.min(axis=0), xs.max(axis=0)
    span = np.maximum(hi - lo, 1e-12 * max(1.0, np.abs(xs).max()))
    vals = np.concatenate([v[used] for _, _, _, v, _ in frames])
    vmin, vmax = float(np.nanmin(vals)), float(np.nanmax(vals))
    if vmin == vmax:
        vmin, vmax = vmin - 0.5, vmax + 0.5
    norm = colors.Normalize(vmin=vmin, vmax=vmax)
    cmap = plt.get_cmap("viridis")
    ncols = min(len(frames), 4)
    nrows = (len(frames) + ncols - 1) // ncols
    fig = plt.figure(figsize=(4.2 * ncols + 1.0, 4.2 * nrows))
    size = max(2.0, 60.0 / np.sqrt(len(used)))
    for k, (time, name, x, v, failed) in enumerate(frames):
        ax = fig.add_subplot(nrows, ncols, k + 1, projection="3d")
        # The failed points are drawn over the triangles, not sorted into
        # them by depth (where the triangles would hide most of them).
        ax.computed_zorder = False
        faces = Poly3DCollection(x[tri], facecolors=cmap(norm(v[tri].mean(1))),
                                 edgecolors=(0, 0, 0, 0.15), linewidths=0.2,
                                 zorder=1)
        ax.add_collection3d(faces)
        n_failed = 0
        if failed is not None:
            down = used[failed[used] > 0.5]
            n_failed = len(down)
            if n_failed:
                ax.scatter(x[down, 0], x[down, 1], x[down, 2], c="red",
                           s=size, depthshade=False, zorder=2)
        ax.set_xlim(lo[0], lo[0] + span[0])
        ax.set_ylim(lo[1], lo[1] + span[1])
        ax.set_zlim(lo[2], lo[2] + span[2])
        ax.set_box_aspect(span / span.max())
        if view:
            ax.view_init(elev=view[0], azim=view[1])
        for axis in "xyz":
            getattr(ax, f"set_{axis}label")(f"{axis} (m)", fontsize=8)
        ax.locator_params(nbins=3)
        ax.tick_params(labelsize=7)
        failed_text = (f"{n_failed} failed" if failed is not None
                       else "no 'failed' field")
        ax.set_title(f"t = {time * 1e6:.3g} µs ({failed_text})", fontsize=10)
        print(f"t = {time:g} s: frame {name}, {n_failed} failed points")
    mappable = cm.ScalarMappable(norm=norm, cmap=cmap)
    mappable.set_array([])
    fig.colorbar(mappable, ax=fig.axes, shrink=0.6, label=field)
    fig.savefig(out_png, dpi=130, bbox_inches="tight")
    print(f"wrote {out_png}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", metavar="OUT",
                    help="run directory (or its results.h5)")
    ap.add_argument("--times", help="comma-separated times in s; the nearest "
                    "frame of each is drawn (default: four frames from the "
                    "first to the last)")
    ap.add_argument("--field", help="scalar point field colouring the "
                    "triangles (default: failed if present, else von_mises)")
    ap.add_argument("--view", help="elev,azim in degrees (default: "
                    "matplotlib's)")
    ap.add_argument("-o", "--output", default="membrane.png",
                    help="PNG to write (default: membrane.png)")
    a = ap.parse_args()
    times = floats(a.times, "--times") if a.times else None
    view = floats(a.view, "--view", 2) if a.view else None
    tri, field, frames = load(a.out, times, a.field)
    render(tri, field, frames, view, a.output)


if __name__ == "__main__":
    main()
