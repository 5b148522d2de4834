#!/usr/bin/python3
"""Draw the user guide's tapered panel: the deformed points of an FPM run
and of an implicit MPM run side by side, coloured by u_y, over the
undeformed outline, with each run's tip u_y (a plane fitted through the
points within 0.3 m of the tip, evaluated at x = 10) and the CalculiX
referee's (cases/fe/panel-tapered, its Richardson limit).

    tools/plot-panel.py out/panel out/panel-mpm --out docs/img/panel.png

Reads the runs through python/pointmech (Debian's python3-numpy,
python3-h5py, python3-matplotlib).
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

OUTLINE = np.array([[0, 0], [10, 1], [10, 3], [0, 4], [0, 0]])


def tip_uy(x, u):
    """u_y at the tip's middle (10, 2) from a plane through the points
    within 0.3 m of the tip."""
    near = x[:, 0] > 10 - 0.3
    a = np.c_[np.ones(near.sum()), x[near, 0] - 10, x[near, 1] - 2]
    return np.linalg.lstsq(a, u[near, 1], rcond=None)[0][0]


def referee():
    """The referee's limit of the tip's mean u_y, or None."""
    path = os.path.join(ROOT, "cases", "fe", "panel-tapered", "ladder.csv")
    try:
        with open(path) as f:
            for line in f:
                if line.startswith("# richardson tip_uy:"):
                    return float(line.split()[3])
    except OSError:
        pass
    return None


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("runs", nargs="+", metavar="OUT")
    a.add_argument("--out", default="panel.png")
    o = a.parse_args()
    fe = referee()
    fig, axes = plt.subplots(1, len(o.runs), figsize=(5.5 * len(o.runs), 3.6),
                             squeeze=False)
    for ax, d in zip(axes[0], o.runs):
        r = pointmech.open(d)
        x = r.mesh["coordinates"]
        u = r.frames[-1]["displacement"]
        ax.plot(OUTLINE[:, 0], OUTLINE[:, 1], "--", color="0.6", lw=1)
        sc = ax.scatter(x[:, 0] + u[:, 0], x[:, 1] + u[:, 1], c=u[:, 1],
                        s=4, cmap="viridis")
        title = "%s (%s, %d points): tip u_y %.4f m" % (
            r.summary.get("name", d), r.summary.get("method", ""), len(x),
            tip_uy(x, u))
        if fe:
            title += "\nCalculiX %.4f m" % fe
        ax.set_title(title, fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        fig.colorbar(sc, ax=ax, label="u_y (m)", shrink=0.8)
    fig.tight_layout()
    fig.savefig(o.out, dpi=110)
    print(o.out)


if __name__ == "__main__":
    main()
