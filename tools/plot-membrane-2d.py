#!/usr/bin/python3
"""Draw 2-D membranes with their normals at chosen times: one column per
run, one row per time (as figs. 12 and 14 of the membrane-normals paper).

usage: plot-membrane-2d.py --times T1,T2 [--scale S] --out PNG LABEL=RUN_DIR ...

Each RUN_DIR is a 2-D MPM run with a membrane, read through the project's
Python module (python/pointmech): the program vets each HDF5 file before
h5py opens it, and a damaged one is refused with its name and the reason.
For each time the frame nearest in time is drawn: the other particles as
grey dots, the membrane's points (those whose "normal" field is a unit vector) in
black with their normals as arrows of length S (default 0.1, in the
results' length unit).
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
import pointmech  # noqa: E402


def fail(msg):
    sys.exit(f"plot-membrane-2d: {msg}")


def load(path, t):
    try:
        r = pointmech.open(path)
        r.check()  # the mesh and every frame, in one call of the program
        if len(r.frames) == 0:
            fail(f"{path}: no frame")
        g = min(r.frames, key=lambda fr: abs(fr.time - t))
        x0 = np.asarray(r.mesh["coordinates"], dtype=float)
        x = x0 + np.asarray(g["displacement"], dtype=float) \
            if "displacement" in g else x0
        if "normal" not in g:
            fail(f"{path}: frame {g.index:06d} has no normal field "
                 "(no membrane?)")
        n = np.asarray(g["normal"], dtype=float)
        return g.time, x, n
    except (pointmech.Refused, OSError) as e:
        fail(e)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", metavar="LABEL=RUN_DIR")
    ap.add_argument("--times", required=True)
    ap.add_argument("--scale", type=float, default=0.1)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    try:
        times = [float(v) for v in a.times.split(",") if v]
    except ValueError:
        fail(f"--times '{a.times}' is not a list of numbers")
    runs = [r.partition("=") for r in a.runs]
    fig, axes = plt.subplots(len(times), len(runs), squeeze=False,
                             figsize=(4.2 * len(runs), 4.2 * len(times)))
    for j, (label, _, d) in enumerate(runs):
        for i, t in enumerate(times):
            time, x, n = load(d, t)
            ax = axes[i][j]
            mem = np.linalg.norm(n, axis=1) > 0.5
            ax.plot(x[~mem, 0], x[~mem, 1], ".", ms=1.5, color="0.7")
            ax.plot(x[mem, 0], x[mem, 1], "k.", ms=3)
            ax.quiver(x[mem, 0], x[mem, 1], n[mem, 0], n[mem, 1],
                      angles="xy", scale_units="xy", scale=1 / a.scale,
                      width=0.004, color="tab:red")
            ax.set_aspect("equal")
            ax.set_title(f"{label}, t = {time:.4g}")
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(f"plot-membrane-2d: wrote {a.out}")


if __name__ == "__main__":
    main()
