#!/usr/bin/env bash
# Table 1 of the FPM paper reproduced: case F2 at the paper's four
# resolutions (or those given as arguments), each run from rest to its
# quasi-static state; prints points, NRMSE of u_z, steps, wall time, time
# per point-step and point-steps per second per core.
#   benchmarks/bench-f2.sh [BUILD_DIR] [h ...]
#   (h: average nodal spacings of the paper's ladder, 1.09e-2 8.02e-3
#   5.19e-3 3.73e-3, run as the scene with discretization.mesh_size set)
# BENCH_RULE=spectral uses the measured stable step instead of eqs. 24-26.
rule=${BENCH_RULE:-paper}
bench_name=f2-$rule bench_env=BENCH_RULE
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
shift || true
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(1.09e-2 8.02e-3 5.19e-3 3.73e-3)
scene=cases/fpm/f2-unconstrained-compression.yaml
nrmse_z() { sed -n 's/^    "u_z": \([^,]*\),\{0,1\}$/\1/p' "$1" | head -1; }

echo "case F2, dt rule: $rule"
printf '%-9s %10s %7s %8s %12s %7s %9s %10s %14s %8s\n' h mean_edge points \
  threads NRMSE_u_z steps wall_s setup_s "s/point-step" "Mps/s/c"
for h in "${sizes[@]}"; do
  dir=$out/h$h
  size=$(paper_mesh_size "$h") || continue
  bench_run "$dir" "$scene" --set discretization.mesh_size="$size" \
    --set time.dt_rule="$rule" || { echo "h=$h failed: see $dir.log"; continue; }
  s=$dir/summary.json
  printf '%-9s %10.4g %7s %8s %12s %7s %9.2f %10.2f %14.3e %8.2f\n' "$h" \
    "$(get mean_edge_length "$s")" "$(get points "$s")" "$(get threads "$s")" "$(nrmse_z "$s")" \
    "$(get steps "$s")" "$(get wall_seconds "$s")" "$(get setup_seconds "$s")" \
    "$(get seconds_per_point_step "$s")" \
    "$(awk -v v="$(get point_steps_per_second_per_core "$s")" 'BEGIN{print v/1e6}')"
done
