#!/bin/bash
# Normals without connectivity (the membrane-normals paper; cases M5, M6),
# each membrane run by three methods: the paper's hybrid rule,
# hybrid-quadratic and connectivity:
#   OUT/tables.md           M6: the paper's static Tables I-III and figs.
#                           4-11 beside ours (pointmech normals)
#   OUT/m5-circle.png       the circle at t = 0 and at rest, normals drawn
#                           (the paper's fig. 12), OUT/m5-circle-p.png its
#                           gas pressure against time (fig. 13)
#   OUT/m5-dogbone.png,     likewise the dogbone (figs. 14, 15), and its
#   OUT/m5-dogbone-p.png    first steps (fig. 16: t = 4 and 7 steps)
#   OUT/normals.md          per run: wall time, the normal stage's time per
#                           membrane point per step, the end pressure, and
#                           the angle of the run's normals to the
#                           connectivity's (rms over frames, largest,
#                           point-frames above 10 degrees); the gas-filled
#                           sphere and the reduced oocyte in 3-D, the
#                           oocyte's angles split between points next to a
#                           failed one and the others
# usage: benchmarks/study-normals.sh [BUILD_DIR] [OUT]
bench_name=normals bench_out=${2:-out/normals}
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"

{
  bench_stamp
  echo
  "$bin" normals
} >"$out/tables.md"

run() { # scene, method, dir, extra --set...
  local scene=$1 method=$2 dir=$3
  shift 3
  "$bin" run --overwrite "cases/mpm/$scene.yaml" --quiet \
    --set bodies.0.membrane.normals="$method" "$@" --out "$dir"
}
for m in hybrid hybrid-quadratic connectivity; do
  run m5-gas-circle $m "$out/circle-$m" --set time.end=0.5
  run m5-gas-dogbone $m "$out/dogbone-$m" --set time.end=0.5
  run m5-gas-dogbone $m "$out/dogbone-early-$m" --set time.end=5e-4 \
    --set output.every=1
  run membrane-sphere-gas $m "$out/sphere-$m" --set time.end=0.3 \
    --set output.every=200
  run m4-oocyte-reduced $m "$out/oocyte-$m" --set output.every=200
done
$py tools/plot-membrane-2d.py --times 0,0.5 --scale 0.1 \
  --out "$out/m5-circle.png" "hybrid=$out/circle-hybrid" \
  "hybrid-quadratic=$out/circle-hybrid-quadratic" "connectivity=$out/circle-connectivity"
$py tools/plot-membrane-2d.py --times 0,0.5 --scale 0.2 \
  --out "$out/m5-dogbone.png" "hybrid=$out/dogbone-hybrid" \
  "hybrid-quadratic=$out/dogbone-hybrid-quadratic" "connectivity=$out/dogbone-connectivity"
dt=$($py -c "import csv; r = list(csv.DictReader(open('$out/dogbone-early-hybrid/history.csv'))); print(r[1]['dt'])")
$py tools/plot-membrane-2d.py --times "$($py -c "print(4 * $dt)"),$($py -c "print(7 * $dt)")" \
  --scale 0.2 --out "$out/m5-dogbone-early.png" \
  "hybrid=$out/dogbone-early-hybrid" \
  "hybrid-quadratic=$out/dogbone-early-hybrid-quadratic" \
  "connectivity=$out/dogbone-early-connectivity"
for c in circle dogbone; do
  $py tools/plot-history.py --columns gas_pressure \
    --title "M5 $c: gas pressure" --out "$out/m5-$c-p.png" \
    "hybrid=$out/$c-hybrid" "hybrid-quadratic=$out/$c-hybrid-quadratic" \
    "connectivity=$out/$c-connectivity"
done

$py - "$out" "$(bench_stamp)" <<'PY'
import csv, json, subprocess, sys
out = sys.argv[1]
rows = [sys.argv[2], "",
        "| run | method | steps | wall (s) | normal stage per point-step (us) "
        "| pressure at the end | angle rms (deg) | largest | point-frames > 10 deg |",
        "|---|---|---|---|---|---|---|---|---|"]
for case, npts in (("circle", 91), ("dogbone", 100), ("sphere", 2562),
                   ("oocyte", 2562)):
    for m in ("hybrid", "hybrid-quadratic", "connectivity"):
        d = f"{out}/{case}-{m}"
        s = json.load(open(f"{d}/summary.json"))
        h = list(csv.DictReader(open(f"{d}/history.csv")))
        p = next((h[-1][k] for k in h[-1] if k.endswith("_pressure")), "")
        us = 1e6 * s["stage_seconds"].get("normals: membrane", 0) / (
            s["steps"] * npts)
        a = subprocess.run(["/usr/bin/python3", "tools/normal-angles.py", d],
                           capture_output=True, text=True, check=True).stdout
        lines = [l.split() for l in a.splitlines()[1:]]
        rms = sum(float(l[3]) for l in lines) / len(lines)
        big = max(float(l[4]) for l in lines)
        n10 = sum(int(l[5]) for l in lines)
        rows.append(f"| {case} | {m} | {s['steps']} | {s['wall_seconds']:.1f} "
                    f"| {us:.3f} | {float(p):.6g} | {rms:.2f} | {big:.1f} | {n10} |"
                    if p else
                    f"| {case} | {m} | {s['steps']} | {s['wall_seconds']:.1f} "
                    f"| {us:.3f} | | {rms:.2f} | {big:.1f} | {n10} |")
rows.append("")
for m in ("hybrid", "hybrid-quadratic"):
    rows.append(f"The reduced oocyte by frame, {m} normals against the "
                "connectivity's (points next to a failed point | the others):")
    rows.append("```")
    rows.append(subprocess.run(["/usr/bin/python3", "tools/normal-angles.py",
                                "--failed", f"{out}/oocyte-{m}"],
                               capture_output=True, text=True,
                               check=True).stdout.rstrip())
    rows.append("```")
for m in ("hybrid", "hybrid-quadratic", "connectivity"):
    h = list(csv.DictReader(open(f"{out}/oocyte-{m}/history.csv")))
    rows.append(f"- oocyte, {m}: failed points at the end {h[-1]['failed_points']}, "
                f"zona inside mass of cytoplasm {h[-1].get('mass_inside_zona_cytoplasm', '')}")
open(f"{out}/normals.md", "w").write("\n".join(rows) + "\n")
print("\n".join(rows))
PY
echo "study-normals: wrote $out/tables.md, $out/normals.md and the PNGs"
