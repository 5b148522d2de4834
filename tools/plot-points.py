#!/usr/bin/python3
"""Draw the deformed points of one or more pointmech runs side by side.

Each OUT is a run directory holding results.h5 (or the results.h5 file
itself).  One subplot per run, all with the same axis limits and equal
aspect.  2-D runs (all z == 0, or triangle cells): the deformed triangulation
drawn faintly, the deformed points as dots and the undeformed box outline
dashed grey.  3-D runs: the x-z projection of the deformed points.  The
last frame is drawn unless --frame N picks another (index into the frames
in time order; negative counts from the end).
"""
import argparse
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def fail(msg):
    sys.exit(f"plot-points: {msg}")


def load(out, frame):
    """Return (deformed [n][3], reference [n][3], cells, frame name)."""
    path = out if os.path.isfile(out) else os.path.join(out, "results.h5")
    if not os.path.isfile(path):
        fail(f"{path}: no such file")
    try:
        with h5py.File(path, "r") as f:
            for name in ("mesh/coordinates", "mesh/cells", "frames"):
                if name not in f:
                    fail(f"{path}: missing /{name}")
            x = np.asarray(f["mesh/coordinates"][()], dtype=float)
            cells = np.asarray(f["mesh/cells"][()])
            frames = sorted(f["frames"].keys())
            if not frames:
                fail(f"{path}: /frames holds no frame")
            if not -len(frames) <= frame < len(frames):
                fail(f"{path}: --frame {frame} out of range "
                     f"({len(frames)} frames)")
            name = frames[frame]
            if "displacement" not in f["frames"][name]:
                fail(f"{path}: missing /frames/{name}/displacement")
            u = np.asarray(f["frames"][name]["displacement"][()], dtype=float)
    except OSError as e:
        fail(f"{path}: cannot read as HDF5: {e}")
    if x.ndim != 2 or x.shape[1] != 3 or u.shape != x.shape:
        fail(f"{path}: coordinates {x.shape} and displacement {u.shape} "
             "must both be [n][3]")
    if cells.ndim != 2 or (cells.size and
                           (cells.min() < 0 or cells.max() >= len(x))):
        fail(f"{path}: /mesh/cells must be [m][k] point indices < {len(x)}")
    return x + u, x, cells, name


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("outs", nargs="+", metavar="OUT", help="run directory (or its results.h5)")
    ap.add_argument("--labels", metavar="L1,L2,...", help="comma-separated subplot titles "
                    "(default: the directory names)")
    ap.add_argument("--out", default="points.png", metavar="FILE.png",
                    help="PNG to write (default: points.png)")
    ap.add_argument("--frame", type=int, default=-1, metavar="N",
                    help="frame index in time order (default: -1, the last)")
    a = ap.parse_args()
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
        runs.append((y, x, cells, flat, k))
        frames.add(frame)
    allpts = np.vstack([np.vstack([r[0][:, [0, r[4]]], r[1][:, [0, r[4]]]])
                        for r in runs])
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    pad = 0.05 * max((hi - lo).max(), 1e-12)

    n = len(runs)
    fig, axes = plt.subplots(1, n, figsize=(4.5 * n, 4.5), squeeze=False)
    for ax, label, (y, x, cells, flat, k) in zip(axes[0], labels, runs):
        size = max(0.5, min(12.0, 3000.0 / len(y)))
        if flat:
            if cells.shape[1] == 3 and len(cells):
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
    fig.suptitle(f"frame {frames.pop()}" if len(frames) == 1
                 else "last frame" if a.frame == -1
                 else f"frame index {a.frame}")
    fig.tight_layout()
    try:
        fig.savefig(a.out, dpi=120)
    except OSError as e:
        fail(f"{a.out}: cannot write: {e.strerror or e}")
    print(a.out)


if __name__ == "__main__":
    main()
