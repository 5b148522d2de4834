#!/usr/bin/python3
"""Draw the difference fields of a comparison written by `pointmech compare`.

Reads OUT/midplane.csv: the lattice points of the middle plane (x, y, z;
in 3-D the x-z section through the lattice's middle y, in 2-D the whole
lattice) and, per method or reference NAME, columns NAME:u_x, NAME:u_y,
NAME:u_z (the analytic field only the components the scene gives; empty
or nan where a method has no fit).  The references are "analytic", "fe"
(the FE referee) and "reference" (a reference run); every other NAME is a
method.  Writes one PNG per comparison into OUT (or --out DIR):

  difference-A-B.png    |u_A - u_B| on the plane for every pair of methods
  difference-A-REF.png  |u_A - u_REF| for every method and reference
                        (for "analytic": over the components it gives)

each a colour map in metres with its largest value in the title.
"""
import argparse
import csv
import math
import os
import sys

REFERENCES = ("analytic", "fe", "reference")


def fail(msg, status=1):
    print(f"plot-compare: {msg}", file=sys.stderr)
    sys.exit(status)


def num(text):
    """Float value of a cell; nan for an empty or non-numeric cell."""
    try:
        return float(text)
    except ValueError:
        return math.nan


def read(path):
    """Coordinates [n][3] and {name: {component: [n]}} of midplane.csv."""
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except OSError as e:
        fail(f"cannot read {path}: {e.strerror}")
    if len(rows) < 2 or rows[0][:3] != ["x", "y", "z"]:
        fail(f"{path}: expected a header x,y,z,NAME:u_x,... and rows")
    head = rows[0]
    xyz = [[num(r[k]) for k in range(3)] for r in rows[1:]]
    fields = {}
    for col, name in enumerate(head[3:], start=3):
        who, _, comp = name.rpartition(":")
        if not who or comp not in ("u_x", "u_y", "u_z"):
            fail(f"{path}: column {col + 1} is '{name}', expected NAME:u_x, "
                 "NAME:u_y or NAME:u_z")
        fields.setdefault(who, {})[comp] = [num(r[col]) for r in rows[1:]]
    return xyz, fields


def plane_axes(xyz):
    """The two axes the points spread along (the plane's)."""
    spread = []
    for k in range(3):
        vals = [p[k] for p in xyz]
        spread.append(max(vals) - min(vals))
    axes = sorted(range(3), key=lambda k: -spread[k])[:2]
    return sorted(axes)


def difference(a, b):
    """|a - b| over the components both give, per point."""
    comps = [c for c in ("u_x", "u_y", "u_z") if c in a and c in b]
    n = len(next(iter(a.values())))
    return [math.sqrt(sum((a[c][i] - b[c][i]) ** 2 for c in comps))
            for i in range(n)], comps


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("dir", help="the comparison's folder (holding midplane.csv)")
    p.add_argument("--out", help="where the PNGs go (default: the folder)")
    args = p.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import matplotlib.tri as mtri
    except ImportError:
        fail("matplotlib is not available to this python "
             f"({sys.executable})", 3)
    xyz, fields = read(os.path.join(args.dir, "midplane.csv"))
    out = args.out or args.dir
    os.makedirs(out, exist_ok=True)
    ax0, ax1 = plane_axes(xyz)
    names = "xyz"
    off = [k for k in range(3) if k not in (ax0, ax1)][0]
    where = f"{names[off]} = {xyz[0][off]:.4g} m" if len(xyz) else ""
    px = [q[ax0] for q in xyz]
    py = [q[ax1] for q in xyz]
    tri = mtri.Triangulation(px, py)
    methods = [n for n in fields if n not in REFERENCES]
    refs = [n for n in REFERENCES if n in fields]
    pairs = [(a, b) for i, a in enumerate(methods) for b in methods[i + 1:]]
    pairs += [(a, r) for a in methods for r in refs]
    written = []
    for a, b in pairs:
        d, comps = difference(fields[a], fields[b])
        finite = [v for v in d if math.isfinite(v)]
        if not finite or len(finite) < 3:
            print(f"plot-compare: {a} against {b}: no points to draw",
                  file=sys.stderr)
            continue
        # Triangles with a point a method could not fit are left blank.
        bad = [not math.isfinite(v) for v in d]
        tri.set_mask([any(bad[k] for k in t) for t in tri.triangles])
        vals = [v if math.isfinite(v) else 0.0 for v in d]
        fig, ax = plt.subplots(figsize=(6.0, 5.0))
        pc = ax.tripcolor(tri, vals, shading="gouraud", cmap="viridis")
        ax.plot(px, py, ".", color="white", markersize=2)
        fig.colorbar(pc, ax=ax, label="|difference| (m)")
        over = "" if len(comps) == 3 else " (" + ", ".join(comps) + ")"
        ax.set_title(f"|u({a}) - u({b})|{over}, {where}\n"
                     f"largest {max(finite):.3g} m")
        ax.set_xlabel(f"{names[ax0]} (m)")
        ax.set_ylabel(f"{names[ax1]} (m)")
        ax.set_aspect("equal")
        fig.tight_layout()
        path = os.path.join(out, f"difference-{a}-{b}.png")
        fig.savefig(path, dpi=120)
        plt.close(fig)
        written.append(path)
    if not pairs:
        print("plot-compare: nothing to draw: one method and no reference")
    elif not written:
        fail("no comparison has points to draw", 2)
    else:
        print("pictures: " + ", ".join(written))


if __name__ == "__main__":
    main()
