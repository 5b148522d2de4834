#!/usr/bin/python3
"""Plot shock-tube profiles against the exact Riemann solution.

usage: plot-shock-tube.py [--exact EXACT.csv] --out FIG.png [--title TEXT]
                          LABEL=PROFILE.csv [LABEL=PROFILE.csv ...]

Every CSV has the header x,density,velocity,pressure,energy (energy: specific
internal energy).  Each LABEL=FILE is one profile (MPM particle data averaged
into bins), drawn as markers joined by thin lines; --exact is the exact
solution sampled finely, drawn as a solid line.  The figure is 2x2: density,
velocity, pressure and specific internal energy against x, with a legend.
"""
import argparse
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

COLUMNS = ("x", "density", "velocity", "pressure", "energy")
PANELS = (("density", "density (kg/m$^3$)"), ("velocity", "velocity (m/s)"),
          ("pressure", "pressure (Pa)"),
          ("energy", "specific internal energy (J/kg)"))
MARKERS = "os^vDx+*"


def fail(msg):
    sys.exit(f"plot-shock-tube: {msg}")


def read_profile(path):
    """Columns of a CSV as a dict of float arrays, sorted by x."""
    try:
        data = np.genfromtxt(path, delimiter=",", names=True, ndmin=1)
    except (OSError, ValueError) as e:
        fail(f"{path}: cannot read: {e}")
    missing = [c for c in COLUMNS if c not in (data.dtype.names or ())]
    if missing:
        fail(f"{path}: missing column(s) {', '.join(missing)} "
             f"(header must be {','.join(COLUMNS)})")
    if data.size == 0:
        fail(f"{path}: no data rows")
    order = np.argsort(data["x"], kind="stable")
    return {c: np.asarray(data[c], dtype=float)[order] for c in COLUMNS}


def main():
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("profiles", nargs="+", metavar="LABEL=FILE")
    ap.add_argument("--exact", metavar="FILE", help="exact solution CSV")
    ap.add_argument("--out", required=True, metavar="PNG")
    ap.add_argument("--title", default=None)
    args = ap.parse_args()

    profiles = []
    for arg in args.profiles:
        label, sep, path = arg.partition("=")
        if not sep or not label or not path:
            fail(f"profile {arg!r} must be LABEL=FILE")
        profiles.append((label, read_profile(path)))

    exact = read_profile(args.exact) if args.exact else None

    fig, axes = plt.subplots(2, 2, figsize=(10, 7), sharex=True)
    for ax, (col, ylabel) in zip(axes.flat, PANELS):
        if exact is not None:
            ax.plot(exact["x"], exact[col], "k-", lw=1.5, label="exact")
        for k, (label, prof) in enumerate(profiles):
            ax.plot(prof["x"], prof[col], lw=0.6, ms=3.5, mfc="none",
                    marker=MARKERS[k % len(MARKERS)], label=label)
        ax.set_ylabel(ylabel)
        ax.grid(True, lw=0.3, alpha=0.5)
    for ax in axes[1]:
        ax.set_xlabel("x (m)")
    axes[0, 0].legend(fontsize="small")
    if args.title:
        fig.suptitle(args.title)
    fig.tight_layout()
    try:
        fig.savefig(args.out, dpi=150)
    except OSError as e:
        fail(f"{args.out}: cannot write: {e.strerror}")


if __name__ == "__main__":
    main()
