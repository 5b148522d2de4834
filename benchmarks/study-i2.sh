#!/usr/bin/env bash
# Case I2, the paper's 2-D slice (figs. 7 and 8): 64^2, 128^2 and 256^2
# cells, grid kept and grid reset, then the figure and the table.
#   benchmarks/study-i2.sh [BUILD_DIR] [OUT_DIR]
bench_name=i2 bench_out=${2:-out/i2}
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
scene=cases/mpm/i2-vessel-slice.yaml
for grid in kept reset; do
  for cells in 64 128 256; do
    h=$(awk -v c="$cells" 'BEGIN { printf "%.10g", 537.6e-6 / c }')
    run="$out/$grid-$cells"
    echo "== I2 $cells^2 cells, grid $grid"
    "$bin" run "$scene" --out "$run" --overwrite --quiet \
      --set discretization.mesh_size="$h" --set mpm.implicit.grid="$grid" ||
      echo "   (stopped: see $run/summary.json)"
    $py - "$run" <<'PY'
import json, sys
d = json.load(open(sys.argv[1] + "/summary.json"))
print("   status %s, load %.3g, %d load steps (%d cuts), %d Newton, %d linear "
      "iterations, wall %.1f s" % (d["status"], d.get("load_reached", 0),
      d.get("load_steps", 0), d.get("load_cuts", 0),
      d.get("newton_iterations", 0), d.get("linear_iterations", 0),
      d.get("wall_seconds", 0)))
PY
  done
done
labels="kept 64^2,kept 128^2,kept 256^2,reset 64^2,reset 128^2,reset 256^2"
$py tools/plot-vessel-stress.py "$out/fig7-fig8.png" \
  "$out"/kept-64 "$out"/kept-128 "$out"/kept-256 \
  "$out"/reset-64 "$out"/reset-128 "$out"/reset-256 --labels "$labels"
