#!/usr/bin/python3
"""Draw the accuracy/cost pictures of a benchmark written by `pointmech bench`.

Reads OUT/bench.csv: a row per method run (kind "method": case,
resolution, label, status, nrmse and what it is against, reaction_error_fe
or tip_error_fe, wall_seconds), among them the FE ladder the bench ran by
CalculiX (label "fe", a row per mesh, timed in the same bench), and the
referee's ladder as recorded when it was made (kind "fe-recorded").
Writes OUT/accuracy-cost.png (or --out FILE): one column per case, the
displacement NRMSE against wall time above and the reaction (a traction
case's tip) error against wall time below, a line per method through its
resolutions and FE's (black squares) through its meshes; the recorded
ladder (grey, dotted) only for a case whose FE the bench did not run.
Runs that did not reach a state (unstable, refused) and FE's reference
mesh (not measured against itself) are left out and named under the
picture.  Exits 3 when matplotlib is missing.
"""
import argparse
import csv
import math
import os
import sys


def fail(msg, status=1):
    print(f"plot-bench: {msg}", file=sys.stderr)
    sys.exit(status)


def num(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def error(r):
    """A row's error against the FE referee: the reaction's, or a traction
    case's tip displacement's."""
    e = num(r.get("reaction_error_fe"))
    return num(r.get("tip_error_fe")) if math.isnan(e) else e


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", help="the bench's output folder")
    ap.add_argument("--out", help="picture (default DIR/accuracy-cost.png)")
    a = ap.parse_args()
    path = os.path.join(a.dir, "bench.csv")
    if not os.path.exists(path):
        fail(f"no {path}")
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    cases = []
    for r in rows:
        if r["case"] not in cases:
            cases.append(r["case"])
    if not cases:
        fail(f"{path} has no rows: nothing to draw")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.ticker import NullFormatter
    except ImportError:
        fail("matplotlib is missing for this python", 3)

    ok = ("converged", "completed", "not-converged")  # "reference": left out
    left_out = []
    fig, axes = plt.subplots(2, len(cases), figsize=(4.2 * len(cases), 7),
                             squeeze=False)
    for j, case in enumerate(cases):
        top, bottom = axes[0][j], axes[1][j]
        labels = []
        for r in rows:
            if r["case"] == case and r["kind"] == "method" and \
                    r["label"] and r["label"] not in labels:
                labels.append(r["label"])
        against = ""
        tip = False
        for label in labels:
            runs = [r for r in rows if r["case"] == case and
                    r["kind"] == "method" and r["label"] == label]
            good = [r for r in runs if r["status"] in ok]
            left_out += [f"{case} {r['resolution']} {label} ({r['status']})"
                         for r in runs if r["status"] not in ok]
            good.sort(key=lambda r: num(r["wall_seconds"]))
            t = [num(r["wall_seconds"]) for r in good]
            e = [num(r["nrmse"]) for r in good]
            rx = [abs(error(r)) for r in good]
            tip = tip or any(not math.isnan(num(r.get("tip_error_fe")))
                             for r in good)
            style = "ks-" if label == "fe" else "o-"
            name = "FE (CalculiX, this bench)" if label == "fe" else label
            against = against or next((r["against"] for r in good
                                       if r["against"]), "")
            pts = [(x, y) for x, y in zip(t, e) if x > 0 and y > 0]
            if pts:
                top.plot(*zip(*pts), style, label=name)
            pts = [(x, y) for x, y in zip(t, rx) if x > 0 and y > 0]
            if pts:
                bottom.plot(*zip(*pts), style, label=name)
        if "fe" not in labels:
            fe = [r for r in rows if r["case"] == case and
                  r["kind"] in ("fe-recorded", "fe")]
            pts = [(num(r["wall_seconds"]), abs(error(r))) for r in fe]
            pts = [(x, y) for x, y in pts if x > 0 and y > 0]
            if pts:
                bottom.plot(*zip(*pts), "s:", color="0.5",
                            label="FE referee (recorded ladder)")
        top.set_title(case)
        top.set_ylabel(f"displacement NRMSE ({against or 'no reference'})")
        bottom.set_ylabel("|tip displacement error| against FE" if tip
                          else "|reaction error| against FE")
        for ax in (top, bottom):
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.xaxis.set_minor_formatter(NullFormatter())
            ax.set_xlabel("wall time (s)")
            ax.grid(True, which="both", alpha=0.3)
            if ax.get_lines():
                ax.legend(fontsize=7)
    if left_out:
        fig.text(0.01, 0.005, "left out: " + "; ".join(left_out)[:300],
                 fontsize=7)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    out = a.out or os.path.join(a.dir, "accuracy-cost.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
