#!/bin/bash
# FPM's static solve of F3 60% at 13762 points (mesh_size 4.15e-3; with
# LARGE=1 also 32715 points, 2.98e-3), the default solver (multigrid),
# REPEATS times (default 3) on OMP_NUM_THREADS threads (default 2); with a
# second build (OLD_BUILD) the two in turn, round by round, for before and
# after side by side.  Each run: the process's wall, CPU and peak memory
# (/usr/bin/time), the static solve's seconds and counts (summary.json)
# and the top reaction (the last row of history.csv).
# usage: benchmarks/static-large.sh [BUILD_DIR [OLD_BUILD_DIR]]
#   (13762 points: about a minute a run; 32715: 4-9 minutes a run)
bench_name=static-large
bench_env="REPEATS OMP_NUM_THREADS LARGE"
source "$(dirname "$0")/bench-lib.sh"
repeats=${REPEATS:-3}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2}
builds=("$build")
[ -n "${2:-}" ] && builds+=("$2")
sizes=(4.15e-3)
[ "${LARGE:-0}" = 1 ] && sizes+=(2.98e-3)
f3=cases/fpm/f3-extension-60.yaml
rows=()
for h in "${sizes[@]}"; do
  for ((r = 1; r <= repeats; r++)); do
    for b in "${builds[@]}"; do
      tag=$(basename "$b")-$h-r$r
      /usr/bin/time -f "%e %U %S %M" -o "$out/$tag.time" "$b/pointmech" run \
        "$f3" --set discretization.mesh_size="$h" \
        --set time.quasi_static.method=static --set output.every=100000 \
        --out "$out/$tag" --overwrite --quiet >/dev/null || true
      rows+=("$b $h $r $out/$tag")
    done
  done
done
$py - "${rows[@]}" <<'PY'
import csv, json, sys
print("| build | points | round | wall (s) | CPU (s) | peak (MiB) | static solve (s) | "
      "linear (s) | set-ups (s) | load steps (cuts) | Newton | GMRES | top reaction (N) |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for row in sys.argv[1:]:
    b, h, r, d = row.split()
    wall, user, sys_, rss = open(d + ".time").read().split()[-4:]
    try:
        s = json.load(open(d + "/summary.json"))
        last = list(csv.DictReader(open(d + "/history.csv")))[-1]
    except (OSError, ValueError, IndexError):
        print(f"| {b} | {h} | {r} | {wall} | (no summary) |")
        continue
    print(f"| {b} | {s['points']} | {r} | {float(wall):.1f} | "
          f"{float(user) + float(sys_):.1f} | {int(rss) / 1024:.0f} | "
          f"{s['static_seconds']:.1f} | {s['static_linear_seconds']:.1f} | "
          f"{s['static_pc_setup_seconds']:.1f} | {s['static_load_steps']} "
          f"({s['static_cuts']}) | {s['static_newton_iterations']} | "
          f"{s['static_linear_iterations']} | {last['reaction_zmax_z']} |")
PY
