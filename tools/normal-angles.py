#!/usr/bin/python3
"""How far a run's membrane normals are from the normals of its connectivity,
frame by frame.

usage: normal-angles.py [--failed] RUN_DIR

RUN_DIR is an MPM run with a membrane whose normals came by isosurface
least squares (or any method); its files are read through the project's
Python module (python/pointmech), which has the program vet each before
h5py opens it: a damaged one is refused with its name and the reason.  For each frame the normals
the run carried (the "normal" field) are compared with the normals the
membrane's connectivity gives on the frame's positions: in 3-D the mean of
the unit normals of each point's triangles (/mesh/surface), in 2-D the
perpendicular to the chord of a point's neighbours (the membrane's points
in order).  Signs are ignored (the angle is between lines).  Printed per
frame: time, points, mean, rms and largest angle in degrees, and the
number above 10 degrees; with --failed (runs with damage), the same over
the points within one triangle of a failed point, and over the others.
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
import pointmech  # noqa: E402


def fail(msg):
    sys.exit(f"normal-angles: {msg}")


def connectivity_normals(x, tri, members):
    n = np.zeros_like(x)
    if tri is not None:
        a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
        tn = np.cross(b - a, c - a)
        tn /= np.maximum(np.linalg.norm(tn, axis=1), 1e-300)[:, None]
        for k in range(3):
            np.add.at(n, tri[:, k], tn)
    else:  # 2-D: the membrane's points in order
        p = members
        xs = x[p]
        t = np.empty_like(xs)
        t[1:-1] = xs[2:] - xs[:-2]
        t[0] = xs[1] - xs[0]
        t[-1] = xs[-1] - xs[-2]
        n[p, 0], n[p, 1] = t[:, 1], -t[:, 0]
    n /= np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
    return n


def stats(ang):
    if len(ang) == 0:
        return "      -"
    return (f"{len(ang):7d} {ang.mean():7.3f} {np.sqrt((ang ** 2).mean()):7.3f} "
            f"{ang.max():7.2f} {(ang > 10).sum():6d}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run")
    ap.add_argument("--failed", action="store_true")
    a = ap.parse_args()
    try:
        report(a.run, a.failed)
    except (pointmech.Refused, OSError) as e:
        fail(e)


def report(run, with_failed):
    r = pointmech.open(run)
    r.check()  # the mesh and every frame, in one call of the program
    mesh = r.mesh
    x0 = np.asarray(mesh["coordinates"], dtype=float)
    tri = np.asarray(mesh["surface"], dtype=np.int64) \
        if "surface" in mesh else None
    frames = sorted(r.frames, key=lambda fr: fr.time)
    head = "time           points    mean     rms     max   >10deg"
    print(head + ("   | near failed ... | intact ..." if with_failed else ""))
    for fr in frames:
        if "normal" not in fr:
            fail(f"frame {fr.index:06d} ({fr.path}) has no normal field")
        x = x0 + np.asarray(fr["displacement"], dtype=float)
        nr = np.asarray(fr["normal"], dtype=float)
        mem = np.flatnonzero(np.linalg.norm(nr, axis=1) > 0.5)
        nc = connectivity_normals(x, tri, mem)
        c = np.abs(np.sum(nr[mem] * nc[mem], axis=1))
        ang = np.degrees(np.arccos(np.clip(c, 0, 1)))
        line = f"{fr.time:<12.5g} {stats(ang)}"
        if with_failed and "failed" in fr and tri is not None:
            failed = np.asarray(fr["failed"], dtype=float) > 0.5
            near = np.zeros(len(x0), bool)
            bad = failed[tri].any(axis=1)
            near[tri[bad].ravel()] = True
            sel = near[mem]
            line += f"   | {stats(ang[sel])} | {stats(ang[~sel])}"
        print(line)


if __name__ == "__main__":
    main()
