#!/usr/bin/python3
"""Plot a convergence table written by `pointmech convergence`.

Reads CSV (columns: level, one column per ladder key such as
discretization.mesh_size, then h, points, steps, status, error, rate,
wall_seconds, ...) and writes two PNGs:

  PREFIX-error-h.png     log-log error against h, with a least-squares line
                         and its slope q.  When every level has the same h
                         (a parameter ladder), error is plotted against the
                         first ladder key instead (linear x axis if a value
                         is <= 0; the fit is then log10(error) against x).
  PREFIX-error-time.png  log-log error against wall_seconds (accuracy/cost
                         front), each point labelled with its level.

and, for a table made against a finite-element referee (column
reaction_error), a third:

  PREFIX-reaction-time.png  log-log |reaction error| against wall_seconds;
                         with --fe DIR (the referee's cases/fe folder) the
                         referee's own meshes beside it: each mesh's
                         reaction against the finest's, at its wall time.

Given several CSVs (the same case by several formulations or solvers),
one picture of what accuracy costs instead:

  PREFIX-cost.png        the displacement error and (when the tables have
                         it) the |reaction error| against wall time, one
                         line per CSV (--labels names them), with the
                         referee's meshes (--fe) on the reaction panel.

The reference row (status "reference") and rows without a positive error
are left out.  PREFIX defaults to the CSV path without ".csv" (with
several CSVs: "accuracy-cost" in the current folder).
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

FIXED = ("level h points steps status error rate wall_seconds setup_seconds "
         "mean_strain_energy_density max_von_mises reaction min_jacobian "
         "energy_balance_error reaction_error reaction_rate sed_error "
         "error_interior").split()
REQUIRED = ("level", "h", "status", "error", "wall_seconds")


def fail(msg):
    sys.exit(f"plot-convergence: {msg}")


def num(text):
    """Float value of a cell; nan for an empty, "nan" or non-numeric cell."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def read_table(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
            header = rows[0].keys() if rows else None
    except OSError as e:
        fail(f"{path}: cannot read: {e.strerror}")
    except csv.Error as e:
        fail(f"{path}: malformed CSV: {e}")
    if not header:
        fail(f"{path}: no data rows")
    missing = [c for c in REQUIRED if c not in header]
    if missing:
        fail(f"{path}: missing column(s): {', '.join(missing)}")
    keys = [c for c in header if c and "." in c and c not in FIXED]
    rows = [r for r in rows if (r["status"] or "").strip() != "reference"]
    rows = [r for r in rows if num(r["error"]) > 0]
    if not rows:
        fail(f"{path}: no level with a positive error to plot")
    return keys, rows


def plot_error_h(rows, keys, title, out):
    err = np.array([num(r["error"]) for r in rows])
    h = np.array([num(r["h"]) for r in rows])
    xlabel, x = "h (m)", h
    if keys and np.nanmax(h) == np.nanmin(h):  # parameter ladder
        xlabel, x = keys[0], np.array([num(r[keys[0]]) for r in rows])
    ok = np.isfinite(x)
    if not ok.any():
        fail(f"column {xlabel!r} has no numeric value to plot against")
    x, err = x[ok], err[ok]
    logx = bool((x > 0).all())
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(x, err, "o", label="levels")
    if len(np.unique(x)) >= 2:
        fx = np.log10(x) if logx else x
        q, c = np.polyfit(fx, np.log10(err), 1)
        xs = np.linspace(fx.min(), fx.max(), 50)
        ax.plot(10 ** xs if logx else xs, 10 ** (c + q * xs), "--",
                label=f"fit q = {q:.2f}")
    ax.set_xscale("log" if logx else "linear")
    ax.set_yscale("log")
    ax.set(xlabel=xlabel, ylabel="error (NRMSE)", title=title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def plot_error_time(rows, title, out):
    pts = [(num(r["wall_seconds"]), num(r["error"]), r["level"]) for r in rows]
    dropped = [p[2] for p in pts if not p[0] > 0]
    if dropped:
        print(f"plot-convergence: level(s) {', '.join(dropped)} left out of "
              f"{out}: wall_seconds not positive", file=sys.stderr)
    pts = [p for p in pts if p[0] > 0]
    fig, ax = plt.subplots(figsize=(6, 4.5))
    if pts:
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-")
        for w, e, lv in pts:
            ax.annotate(lv, (w, e), textcoords="offset points", xytext=(5, 5))
        ax.set_xscale("log")
        ax.set_yscale("log")
    ax.set(xlabel="wall time (s)", ylabel="error (NRMSE)", title=title)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def fe_points(folder):
    """(wall seconds, |reaction change| against the finest, N) of the
    referee's meshes that reached the load, the finest left out."""
    path = os.path.join(folder, "ladder.csv")
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(ln for ln in f if not ln.startswith("#")))
    except OSError as e:
        fail(f"{path}: cannot read: {e.strerror}")
    rows = [r for r in rows if r.get("status", "converged") == "converged"]
    if len(rows) < 2:
        fail(f"{path}: fewer than two meshes reached the load")
    comps = ("reaction_x", "reaction_y", "reaction_z")
    fine = rows[-1]
    c = max(comps, key=lambda k: abs(num(fine[k])))
    ref = num(fine[c])
    return [(num(r["wall_seconds"]), abs(num(r[c]) - ref) / abs(ref),
             r["N"]) for r in rows[:-1]]


def plot_reaction_time(rows, fe, title, out):
    pts = [(num(r["wall_seconds"]), abs(num(r["reaction_error"])), r["level"])
           for r in rows]
    pts = [p for p in pts if p[0] > 0 and p[1] > 0]
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for data, style, label, tag in ((pts, "o-", "FPM levels", ""),
                                    (fe, "s--", "FE meshes", "N = ")):
        data = [p for p in data if p[0] > 0 and p[1] > 0]
        if not data:
            continue
        ax.plot([p[0] for p in data], [p[1] for p in data], style, label=label)
        for w, e, lv in data:
            ax.annotate(tag + lv, (w, e), textcoords="offset points",
                        xytext=(5, 5))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set(xlabel="wall time (s)", ylabel="relative reaction error",
           title=title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def plot_cost(tables, labels, fe, title, out):
    reaction = any(math.isfinite(num(r.get("reaction_error")))
                   for _, rows in tables for r in rows)
    fig, axes = plt.subplots(1, 2 if reaction else 1,
                             figsize=(11 if reaction else 6, 4.5),
                             squeeze=False)
    panels = [("error", "displacement error (NRMSE)")]
    if reaction:
        panels.append(("reaction_error", "relative reaction error"))
    for ax, (col, ylabel) in zip(axes[0], panels):
        for (_, rows), label in zip(tables, labels):
            pts = [(num(r["wall_seconds"]), abs(num(r.get(col))))
                   for r in rows]
            pts = [p for p in pts if p[0] > 0 and p[1] > 0]
            if pts:
                ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-",
                        label=label)
        if col == "reaction_error" and fe:
            data = [p for p in fe if p[0] > 0 and p[1] > 0]
            ax.plot([p[0] for p in data], [p[1] for p in data], "ks--",
                    label="FE meshes (against the finest)")
            for w, e, n in data:
                ax.annotate(f"N = {n}", (w, e), textcoords="offset points",
                            xytext=(5, 5), fontsize=8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set(xlabel="wall time (s)", ylabel=ylabel, title=title)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv", metavar="CSV", nargs="+",
                    help="convergence.csv to plot (several: one cost picture)")
    ap.add_argument("--out-prefix", metavar="PREFIX",
                    help="output prefix (default: CSV path without .csv)")
    ap.add_argument("--fe", metavar="DIR",
                    help="the finite-element referee's folder (cases/fe/CASE)"
                    " for its own points on the reaction plot")
    ap.add_argument("--labels", metavar="A,B,...",
                    help="names of the CSVs' lines on the cost picture "
                    "(default: their folders)")
    ap.add_argument("--title", help="title (default: the CSV's folder)")
    a = ap.parse_args()
    fe = fe_points(a.fe) if a.fe else []
    if len(a.csv) > 1:
        labels = (a.labels.split(",") if a.labels else
                  [os.path.basename(os.path.dirname(os.path.abspath(c)))
                   for c in a.csv])
        if len(labels) != len(a.csv):
            fail(f"--labels names {len(labels)} lines for {len(a.csv)} CSVs")
        tables = [read_table(c) for c in a.csv]
        out = f"{a.out_prefix or 'accuracy-cost'}-cost.png"
        try:
            plot_cost(tables, labels, fe, a.title or "accuracy and cost", out)
        except OSError as e:
            fail(f"{e.filename or out}: cannot write: {e.strerror or e}")
        print(out)
        return
    a.csv = a.csv[0]
    keys, rows = read_table(a.csv)
    prefix = a.out_prefix or (a.csv[:-4] if a.csv.endswith(".csv") else a.csv)
    title = a.title or os.path.basename(os.path.dirname(os.path.abspath(a.csv)))
    outs = [f"{prefix}-error-h.png", f"{prefix}-error-time.png"]
    reaction = any(math.isfinite(num(r.get("reaction_error"))) for r in rows)
    if reaction:
        outs.append(f"{prefix}-reaction-time.png")
    try:
        plot_error_h(rows, keys, title, outs[0])
        plot_error_time(rows, title, outs[1])
        if reaction:
            plot_reaction_time(rows, fe, title, outs[2])
    except OSError as e:
        fail(f"{e.filename or prefix}: cannot write: {e.strerror or e}")
    for o in outs:
        print(o)


if __name__ == "__main__":
    main()
