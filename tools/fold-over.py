#!/usr/bin/env python3
"""Points of a block that have folded over its clamped faces.

A scene that clamps the faces zmin and zmax of a box (F4's compression
scenes) models the grips as the faces' prescribed displacements alone:
nothing stops the free sides from wrapping round the clamped edges into
the space a grip would fill.  This counts, in a run's last frame
(or the frame given), the points over a clamped face's footprint (x and y
within the box's, the face's extent while it holds x and y) that lie past
its plane: above the top face, moved to z = zmax - travel * load, and
below the bottom face at z = zmin.

    tools/fold-over.py OUT --travel 0.06 [--load 1] [--frame K]
        [--box 0 0 0 0.1 0.1 0.1]

The run's files are read through python/pointmech, which has the program
vet them first: a damaged one is refused with its name.

Prints one line: the points past each face, and the farthest, in mm.
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
import pointmech  # noqa: E402


def fail(msg):
    sys.exit(f"fold-over: {msg}")


def load(out, frame):
    """Return (reference [n][3], deformed [n][3], frame name), vetted."""
    try:
        X, x, fr = pointmech.open(out).positions(frame)
    except (pointmech.Refused, OSError) as e:
        fail(e)
    return X, x, f"frame {fr.index}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", help="a run's output folder")
    ap.add_argument("--travel", type=float, required=True,
                    help="the top face's travel down at load 1 (m)")
    ap.add_argument("--load", type=float, default=1.0,
                    help="the load factor of the frame (default 1)")
    ap.add_argument("--frame", type=int, default=-1,
                    help="the frame's index among the run's (default -1: "
                    "the last)")
    ap.add_argument("--box", type=float, nargs=6,
                    default=[0, 0, 0, 0.1, 0.1, 0.1],
                    help="xmin ymin zmin xmax ymax zmax (m)")
    a = ap.parse_args()
    X, x, name = load(a.results, a.frame)
    lo, hi = np.array(a.box[:3]), np.array(a.box[3:])
    top = hi[2] - a.travel * a.load
    over = ((x[:, 0] >= lo[0]) & (x[:, 0] <= hi[0]) &
            (x[:, 1] >= lo[1]) & (x[:, 1] <= hi[1]))
    slack = 1e-9 * (hi[2] - lo[2])
    up = over & (x[:, 2] > top + slack)
    down = over & (x[:, 2] < lo[2] - slack)
    far_up = 1e3 * (x[up, 2] - top).max() if up.any() else 0.0
    far_down = 1e3 * (lo[2] - x[down, 2]).max() if down.any() else 0.0
    print(f"{name}: {len(X)} points; top face at z = {top:.4g}: "
          f"{up.sum()} past it over its footprint (farthest {far_up:.1f} "
          f"mm); bottom face at z = {lo[2]:.4g}: {down.sum()} past it "
          f"(farthest {far_down:.1f} mm)")


if __name__ == "__main__":
    main()
