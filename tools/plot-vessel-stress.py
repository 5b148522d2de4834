#!/usr/bin/python3
"""Figures 7 and 8 of the implicit MPM paper from pointmech runs of case I2.

    plot-vessel-stress.py OUT.png RUN [RUN ...] [--labels A,B,...]
                          [--depth 1e-6] [--voxel 1.05e-6]

Each RUN is a run directory of cases/mpm/i2-vessel-slice.yaml (or the
study's), its HDF5 files read through the project's Python module
(python/pointmech): the program vets each before h5py opens it, and a
damaged one is refused with its name and the reason.  Writes OUT.png: on the left the reaction at the pulled end
against the applied strain for every run (fig. 7: per unit depth times
--depth, in nN); then, for every run, its von Mises stress at the last
frame drawn on the reference pixels (fig. 8), on one colour scale.

Prints, per run, the reaction at the last frame and the largest von Mises
stress: over all particles, and away from the grips (particles more than
one cell from the clamped and the pulled faces, where the clamped corners
are singular), with the 99.9th percentile.  The paper's figures for the
grid kept, 64^2, 128^2, 256^2 cells: 357, 384, 380 Pa.
"""
import argparse
import csv
import json
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
    sys.exit(f"plot-vessel-stress: {msg}")


def history(run):
    path = os.path.join(run, "history.csv")
    if not os.path.isfile(path):
        fail(f"{path}: no such file")
    rows = list(csv.DictReader(open(path)))
    lam = np.array([float(r["time"]) for r in rows])
    key = "reaction_ymax_y"
    if key not in rows[0]:
        fail(f"{path}: no column {key} (a condition on ymax)")
    react = np.array([float(r[key]) for r in rows])
    return lam / lam[-1] if lam[-1] > 0 else lam, react


def last_frame(run):
    try:
        r = pointmech.open(run)
        if len(r.frames) == 0:
            fail(f"{run}/results: no frame")
        fr = r.frames[-1]
        r.check([fr])  # the mesh and the last frame, in one call
        if "von_mises" not in fr:
            fail(f"{fr.path}: no von_mises field")
        x0 = np.array(r.mesh["coordinates"])
        vm = np.array(fr["von_mises"])
    except (pointmech.Refused, OSError) as e:
        fail(e)
    return x0, vm


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--labels", default=None)
    ap.add_argument("--depth", type=float, default=1e-6,
                    help="slice thickness, m (the reaction is per unit depth)")
    ap.add_argument("--voxel", type=float, default=1.05e-6)
    ap.add_argument("--strain", type=float, default=0.10,
                    help="the applied strain at full load")
    a = ap.parse_args()
    labels = a.labels.split(",") if a.labels else [os.path.basename(
        os.path.normpath(r)) for r in a.runs]
    if len(labels) != len(a.runs):
        fail("--labels: one per run")
    frames = [last_frame(r) for r in a.runs]
    vmax = max(np.percentile(vm, 99.9) for _, vm in frames)
    n = len(a.runs)
    rows = 2 if n > 3 else 1
    cols = 1 + (n + rows - 1) // rows
    fig, grid = plt.subplots(rows, cols, figsize=(4.2 * cols, 4.0 * rows),
                             squeeze=False)
    ax = grid[0][0]
    for r in range(1, rows):
        grid[r][0].axis("off")
    axes = [ax] + [grid[k // (cols - 1)][1 + k % (
        cols - 1)] for k in range(n)]
    for k in range(n, rows * (cols - 1)):
        grid[k // (cols - 1)][1 + k % (cols - 1)].axis("off")
    for run, lab in zip(a.runs, labels):
        lam, react = history(run)
        ax.plot(100 * a.strain * lam, react * a.depth * 1e9, "o-", ms=3,
                label=lab)
    ax.set_xlabel("axial strain (%)")
    ax.set_ylabel("reaction at the pulled end (nN)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    print(f"{'run':<28} {'reaction':>12} {'max vM':>9} {'max vM':>10} "
          f"{'99.9%':>8}")
    print(f"{'':<28} {'nN':>12} {'all':>9} {'off grips':>10} {'':>8}")
    for k, (run, lab) in enumerate(zip(a.runs, labels)):
        x0, vm = frames[k]
        lam, react = history(run)
        summ = os.path.join(run, "summary.json")
        h = json.load(open(summ)).get("cell_size", 0) if os.path.isfile(
            summ) else 0
        y = x0[:, 1]
        ymin, ymax = y.min(), y.max()
        inner = (y > ymin + h) & (y < ymax - h) if h > 0 else np.ones_like(
            y, bool)
        print(f"{lab:<28} {react[-1] * a.depth * 1e9:12.2f} {vm.max():9.1f} "
              f"{vm[inner].max():10.1f} {np.percentile(vm, 99.9):8.1f}")
        # the reference pixels as an image
        i = np.rint((x0[:, 0] - x0[:, 0].min()) / a.voxel).astype(int)
        j = np.rint((x0[:, 1] - x0[:, 1].min()) / a.voxel).astype(int)
        img = np.full((j.max() + 1, i.max() + 1), np.nan)
        img[j, i] = vm
        axk = axes[k + 1]
        im = axk.imshow(img, origin="lower", cmap="jet", vmin=0, vmax=vmax,
                        interpolation="nearest",
                        extent=[0, (i.max() + 1) * a.voxel * 1e6, 0,
                                (j.max() + 1) * a.voxel * 1e6])
        axk.set_title(f"{lab}: von Mises (Pa)", fontsize=8)
        axk.set_xlabel("x (um)")
        fig.colorbar(im, ax=axk, fraction=0.046)
    fig.tight_layout()
    fig.savefig(a.out, dpi=130)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
