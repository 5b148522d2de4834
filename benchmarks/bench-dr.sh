#!/usr/bin/env bash
# Quasi-static efficiency: adaptive dynamic relaxation (damping from the
# lowest frequency estimated every step by the Rayleigh quotient of the
# step increment) against plain mass-proportional damping at fixed rates:
# steps and wall time to the same relative residual, same step, for F2
# and F3 60% at h = 1.09e-2.  The fixed rates bracket the critical damping
# 2 omega_1 that the adaptive run settles on.
#   benchmarks/bench-dr.sh [BUILD_DIR]      FLUX=iipg|sipg  PENALTY=p
bench_name=dr bench_env="FLUX PENALTY"
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
last_damping() { # the damping column of the last history row
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "damping") c = i; next }
           { d = $c } END { print d }' "$1"
}
printf '%-22s %-26s %8s %9s %10s %-14s\n' case method steps wall_s residual status
for c in f2-unconstrained-compression f3-extension-60; do
  scene=cases/fpm/$c.yaml
  sets=(--set discretization.mesh_size="$(paper_mesh_size 1.09e-2)"
    --set fpm.flux="$flux" --set fpm.penalty="$penalty"
    --set time.dt_rule=spectral --set time.dt_safety=0.5
    --set time.quasi_static.tolerance=1e-8 --set time.end=30
    --set output.every=200)
  run() { # label, extra --set ...
    local label=$1 dir=$out/$c-$1
    shift
    bench_run "$dir" "$scene" "${sets[@]}" "$@" || true
    printf '%-22s %-26s %8s %9.3f %10.3g %-14s\n' "$c" "$label" \
      "$(get steps "$dir/summary.json")" "$(get wall_seconds "$dir/summary.json")" \
      "$(get residual "$dir/summary.json")" "$(get status "$dir/summary.json")"
  }
  run adaptive-DR
  c1=$(last_damping "$out/$c-adaptive-DR/history.csv")
  for f in 0.5 1 2; do
    cf=$(awk -v c="$c1" -v f="$f" 'BEGIN { printf "%.4g", c * f }')
    run "damping-$cf" --set time.quasi_static.method=damping \
      --set time.quasi_static.damping="$cf"
  done
done
