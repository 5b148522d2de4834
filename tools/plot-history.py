#!/usr/bin/python3
"""Plot columns of one or more runs' history.csv against time.

usage: plot-history.py [--columns A,B,...] [--sum NAME=A+B+...]
                       [--relative] [--title T] --out PNG LABEL=RUN_DIR ...

Each RUN_DIR holds a history.csv written by `pointmech run`.  --columns
picks columns to draw (default: kinetic_energy,strain_energy); --sum adds a
derived column, e.g. --sum total=kinetic_energy+strain_energy.  With
--relative every curve is divided by its value at t = 0 (or by the first
non-zero value).  One line per run and column.
"""
import argparse
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot-history.py: {path}: no rows")
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", metavar="LABEL=RUN_DIR")
    ap.add_argument("--columns", default="kinetic_energy,strain_energy")
    ap.add_argument("--sum", action="append", default=[], metavar="NAME=A+B")
    ap.add_argument("--relative", action="store_true")
    ap.add_argument("--title", default="")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    cols = [c for c in a.columns.split(",") if c]
    sums = []
    for s in a.sum:
        name, _, expr = s.partition("=")
        if not name or not expr:
            sys.exit(f"plot-history.py: --sum expects NAME=A+B, got {s}")
        sums.append((name, expr.split("+")))
        cols.append(name)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for run in a.runs:
        label, _, d = run.partition("=")
        if not d:
            label, d = d or run, run
        h = read(f"{d}/history.csv")
        for name, parts in sums:
            missing = [p for p in parts if p not in h]
            if missing:
                sys.exit(f"plot-history.py: {d}: no column {missing[0]}")
            h[name] = [sum(v) for v in zip(*(h[p] for p in parts))]
        for c in cols:
            if c not in h:
                sys.exit(f"plot-history.py: {d}/history.csv: no column {c}")
            y = h[c]
            if a.relative:
                ref = next((v for v in y if v != 0), 1.0)
                y = [v / ref for v in y]
            ax.plot(h["time"], y, lw=1.2, label=f"{label}: {c}")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("relative to t = 0" if a.relative else "value")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if a.title:
        ax.set_title(a.title)
    fig.tight_layout()
    fig.savefig(a.out, dpi=150)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
