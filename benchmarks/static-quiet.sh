#!/bin/bash
# FPM's static solve against CalculiX on F3 60%, for a quiet machine:
# cases/bench/static-f3.yaml (the default static solve, the LU throughout,
# CalculiX N = 4, 6, 8; every run's wall and CPU seconds and error against
# the referee) REPEATS times in turn (default 3) on OMP_NUM_THREADS threads
# (default 2), the medians by run; then the peak memory of each FPM
# setting at 1851 points, of the quarter at 404 points and of ccx at N = 6
# (/usr/bin/time, one run each).
# usage: benchmarks/static-quiet.sh [BUILD_DIR]   (about 3 min)
bench_name=static-quiet
bench_env="REPEATS OMP_NUM_THREADS"
source "$(dirname "$0")/bench-lib.sh"
repeats=${REPEATS:-3}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2}
for ((r = 1; r <= repeats; r++)); do
  "$bin" bench cases/bench/static-f3.yaml --out "$out/r$r" --overwrite \
    --quiet >/dev/null
done
$py - "$out" "$repeats" <<'PY'
import csv, statistics, sys
out, repeats = sys.argv[1], int(sys.argv[2])
runs = {}
for r in range(1, repeats + 1):
    for row in csv.DictReader(open(f"{out}/r{r}/bench.csv")):
        if row["kind"] != "method" or row["status"] != "converged":
            continue
        at = f"N {row['fe_n']}" if row["label"] == "fe" else row["resolution"]
        runs.setdefault((row["label"], at), []).append(row)
# (a method's wall: its setup and its run; ccx's: its run)
print("| method | resolution | points / nodes | reaction error (%) | "
      "wall (s), median | of which setup (s) | CPU (s), median | "
      "CPU / wall | walls (s) |")
print("|---|---|---|---|---|---|---|---|---|")
for (m, at), rows in runs.items():
    w = [float(x["wall_seconds"]) for x in rows]
    c = [float(x["cpu_seconds"]) for x in rows]
    st = [float(x["setup_seconds"] or "nan") for x in rows]
    wm, cm = statistics.median(w), statistics.median(c)
    sm = statistics.median(st)
    print(f"| {m} | {at} | {rows[0]['points']} | "
          f"{100 * float(rows[0]['reaction_error_fe']):+.3f} | {wm:.3g} | "
          f"{'' if sm != sm else f'{sm:.3g}'} | {cm:.3g} | "
          f"{cm / wm:.2f} | {', '.join(f'{x:.3g}' for x in w)} |")
PY
# Peak memory, one run each.
f3=cases/fpm/f3-extension-60.yaml
for solver in default direct; do
  set_solver=()
  [ $solver = direct ] && set_solver=(--set time.quasi_static.linear_solver=direct)
  /usr/bin/time -f "%M" -o "$out/rss-$solver" "$bin" run "$f3" \
    --set discretization.mesh_size=8.72e-3 \
    --set time.quasi_static.method=static --set output.every=100000 \
    "${set_solver[@]}" --out "$out/mem-$solver" --overwrite --quiet
  echo "FPM static, 1851 points, $solver: peak $(($(cat "$out/rss-$solver") / 1024)) MiB" \
    "(summary.json, the process alone: $(($(json "$out/mem-$solver/summary.json" memory peak_rss_max) / 1048576)) MiB)"
done
# The quarter (two symmetry planes) where it reaches 1%: 1e-2, 404 points.
/usr/bin/time -f "%M" -o "$out/rss-quarter" "$bin" run "$f3" \
  --set discretization.mesh_size=1e-2 \
  --set time.quasi_static.method=static --set output.every=100000 \
  --set 'domain.box.min=[0.05, 0.05, 0]' \
  --set 'boundary.2={on: xmin, symmetry: true}' \
  --set 'boundary.3={on: ymin, symmetry: true}' \
  --out "$out/mem-quarter" --overwrite --quiet
echo "FPM static on the quarter, 404 points: peak $(($(cat "$out/rss-quarter") / 1024)) MiB" \
  "(summary.json, the process alone: $(($(json "$out/mem-quarter/summary.json" memory peak_rss_max) / 1048576)) MiB)"
if command -v ccx >/dev/null; then
  # (its exit status says the ladder holds no referee mesh: not a failure)
  $py tools/fe-referee.py f3-extension-60 --run --ladder 6 --keep \
    --work "$out/fe" --out "$out/fe-out" >/dev/null || true
  (cd "$out/fe/f3-extension-60-N6-C3D20R" &&
    /usr/bin/time -f "%M" -o ../rss ccx -i f3-extension-60-N6-C3D20R >/dev/null)
  echo "CalculiX N = 6: peak $(($(cat "$out/fe/rss") / 1024)) MiB"
fi
