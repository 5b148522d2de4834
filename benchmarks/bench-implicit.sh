#!/usr/bin/env bash
# Implicit MPM: what the linear solver and the operator cost, on case I2
# (64^2 and 128^2 cells, grid kept) and on F2 (the neo-Hookean cube, 40%
# compression, 8000 particles), one run at a time; and F2 by implicit
# against explicit MPM, error and time.
#   benchmarks/bench-implicit.sh [BUILD_DIR] [OUT_DIR]
bench_name=implicit bench_out=${2:-}
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
row() { # name, run dir
  $py - "$1" "$2" <<'PY'
import json, sys
d = json.load(open(sys.argv[2] + "/summary.json"))
nr = d.get("nrmse", {})
e = nr.get("vector", nr.get("u_z", "")) if isinstance(nr, dict) else ""
print("| %-44s | %-9s | %5s | %6s | %7s | %8.2f | %8.2f | %8.2f | %8.2f | %s |" % (
    sys.argv[1], d["status"], d.get("load_steps", d.get("steps")),
    d.get("newton_iterations", "-"), d.get("linear_iterations", "-"),
    d.get("tangent_seconds", 0), d.get("linear_seconds", 0),
    d.get("residual_seconds", 0), d["wall_seconds"],
    ("%.2e" % e) if isinstance(e, float) else "-"))
PY
}
echo "| run | status | steps | Newton | linear | tangent (s) | linear (s) | residual (s) | wall (s) | NRMSE |"
echo "|---|---|---|---|---|---|---|---|---|---|"
i2=cases/mpm/i2-vessel-slice.yaml
for cells in 64 128; do
  h=$(awk -v c="$cells" 'BEGIN { printf "%.10g", 537.6e-6 / c }')
  for ls in cg-gamg gmres-gamg cg-jacobi direct; do
    run="$out/i2-$cells-$ls"
    bench_run "$run" $i2 --set discretization.mesh_size="$h" \
      --set time.quasi_static.linear_solver=$ls --set output.every=100 || true
    row "I2 $cells^2 kept, $ls, assembled" "$run"
  done
  run="$out/i2-$cells-mf"
  bench_run "$run" $i2 --set discretization.mesh_size="$h" \
    --set mpm.implicit.operator=matrix-free --set output.every=100 || true
  row "I2 $cells^2 kept, cg-jacobi, matrix-free" "$run"
done
f2=cases/mpm/f2-unconstrained-compression.yaml
for ls in cg-gamg direct cg-jacobi; do
  run="$out/f2-implicit-$ls"
  bench_run "$run" $f2 --set method=mpm-implicit --set mpm.shape=linear \
    --set time.quasi_static.linear_solver=$ls \
    --set time.quasi_static.tolerance=1e-10 || true
  row "F2 implicit (linear), $ls" "$run"
done
run="$out/f2-implicit-mf"
bench_run "$run" $f2 --set method=mpm-implicit --set mpm.shape=linear \
  --set mpm.implicit.operator=matrix-free \
  --set time.quasi_static.tolerance=1e-10 || true
row "F2 implicit (linear), cg-jacobi, matrix-free" "$run"
run="$out/f2-explicit"
bench_run "$run" $f2 || true
row "F2 explicit (quadratic, MUSL, dyn. relaxation 1e-4)" "$run"
run="$out/f2-explicit-linear"
bench_run "$run" $f2 --set mpm.shape=linear || true
row "F2 explicit (linear, MUSL, dyn. relaxation 1e-4)" "$run"
