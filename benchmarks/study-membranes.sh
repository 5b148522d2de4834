#!/bin/bash
# Cases M1 and M3 of the fluid-membrane paper at the paper's three cell
# sizes each, their curves as PNG from history.csv, and a table of the
# figures with the wall time of each run:
#   OUT/m1/cuboid-uz.png    z-displacement of the cuboid's centre, cells
#                           0.05, 0.025, 0.02 m
#   OUT/m3/cube-uz.png      z-displacement of the cube's centroid, cells
#                           0.04, 0.02, 0.01 m
#   OUT/membranes.md        per run: particles, steps, wall time, the
#                           displacement at the paper's times, and its change
#                           from the next coarser cell
#   OUT/leak.md             does gas leak through a membrane one point thick?
#                           The gas-filled sphere (cell 0.1 m) with 42 to 2562
#                           membrane points: the gas mass inside the
#                           membrane's current surface at the end (0.3 s)
#                           against the start, by cell size over point
#                           spacing
# usage: benchmarks/study-membranes.sh [BUILD_DIR] [OUT] [m1|m3|leak|all]
bench_name=membranes bench_out=${2:-out/membranes}
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
which=${3:-all}
stamp=$(bench_stamp)

run() { # case, cell, dir
  "$bin" run --overwrite "cases/mpm/$1.yaml" --quiet \
    --set discretization.mesh_size="$2" --set output.every=20 --out "$3"
}

# One case at its three cells and the PNG of one history column.
study() { # name, scene, column, png, title, cells...
  local name=$1 scene=$2 col=$3 png=$4 title=$5 args=()
  shift 5
  for h in "$@"; do
    run "$scene" "$h" "$out/$name/h$h"
    args+=("cell $h m=$out/$name/h$h")
  done
  $py tools/plot-history.py --columns "$col" --title "$title" \
    --out "$out/$name/$png" "${args[@]}"
}

if [ "$which" = all ] || [ "$which" = m1 ]; then
  study m1 m1-cuboid-net cuboid_uz cuboid-uz.png \
    "M1: z-displacement of the cuboid's centre (m)" 0.05 0.025 0.02
fi
if [ "$which" = all ] || [ "$which" = m3 ]; then
  study m3 m3-gas-box-membrane cube_uz cube-uz.png \
    "M3: z-displacement of the cube's centroid (m)" 0.04 0.02 0.01
fi
if [ "$which" = all ] || [ "$which" = leak ]; then
  for r in 1 2 3 4; do
    "$bin" run --overwrite cases/mpm/membrane-sphere-gas.yaml \
      --quiet --set time.end=0.3 --set output.every=100 \
      --set bodies.0.membrane.sphere.refinement=$r --out "$out/leak/r$r" ||
      echo "refinement $r: the run stopped (see $out/leak/r$r/summary.json)"
  done
  $py - "$out" "$stamp" <<'PY'
import csv, math, os, sys
out = sys.argv[1]
lines = [sys.argv[2], "", "# Gas inside a closed membrane (sphere R = 0.5 m, cell 0.1 m, 0.3 s)", "",
         "| refinement | membrane points | edge (m) | cell / edge | gas mass inside at 0 | at the end | end (s) | lost |",
         "|---|---|---|---|---|---|---|---|"]
for r in (1, 2, 3, 4):
    d = os.path.join(out, "leak", "r%d" % r)
    rows = list(csv.DictReader(open(os.path.join(d, "history.csv"))))
    col = "mass_inside_membrane_gas"
    m0, m1 = float(rows[0][col]), float(rows[-1][col])
    end = float(rows[-1]["time"])
    n = 10 * 4 ** r + 2
    edge = math.sqrt(4 * 4 * math.pi * 0.25 / (math.sqrt(3) * 20 * 4 ** r))
    lines.append("| %d | %d | %.3f | %.2f | %.4f | %.4f | %.3g | %.2f%% |" % (
        r, n, edge, 0.1 / edge, m0, m1, end, 100 * (m0 - m1) / m0))
open(os.path.join(out, "leak.md"), "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
fi
$py - "$out" "$stamp" <<'PY'
import csv, json, os, sys
out = sys.argv[1]
cases = [("m1", "cuboid_uz", [0.05, 0.1, 0.15, 0.2], ["0.05", "0.025", "0.02"]),
         ("m3", "cube_uz", [0.01, 0.02, 0.03], ["0.04", "0.02", "0.01"])]
lines = [sys.argv[2], "", "# M1 and M3 at three cell sizes", ""]
for name, col, times, cells in cases:
    runs = [os.path.join(out, name, "h" + h) for h in cells]
    if not all(os.path.exists(os.path.join(r, "history.csv")) for r in runs):
        continue
    lines += ["## %s: %s (m) at t (s)" % (name.upper(), col), "",
              "| cell (m) | particles | steps | wall (s) | " +
              " | ".join("t = %g" % t for t in times) + " | change from coarser |",
              "|---|---|---|---|" + "---|" * len(times) + "---|"]
    prev = None
    for h, r in zip(cells, runs):
        rows = list(csv.DictReader(open(os.path.join(r, "history.csv"))))
        s = json.load(open(os.path.join(r, "summary.json")))
        vals = []
        for t in times:
            best = min(rows, key=lambda q: abs(float(q["time"]) - t))
            vals.append(float(best[col]))
        change = "" if prev is None else "%.3g" % max(abs(a - b) for a, b in zip(vals, prev))
        lines.append("| %s | %d | %d | %.1f | %s | %s |" % (
            h, s["points"], s["steps"], s["wall_seconds"],
            " | ".join("%.4g" % v for v in vals), change))
        prev = vals
    lines.append("")
open(os.path.join(out, "membranes.md"), "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
