#!/bin/bash
# Explicit MPM throughput: particle-steps per second (the step's stages,
# without output) on 1 thread and on every core, for
#   - a 3-D neo-Hookean block with quadratic B-splines, MUSL, 8 particles
#     per cell (cases/mpm/bench-block.yaml, 110592 particles), and
#   - the shock tube at the paper's size (cases/mpm/m2-shock-tube.yaml,
#     20000 gas particles, linear B-splines, iterative energy update),
#   - membranes with fluids: the gas-filled sphere
#     (cases/mpm/membrane-sphere-gas.yaml, 2562 membrane and 4224 gas
#     particles) and the reduced oocyte (cases/mpm/m4-oocyte-reduced.yaml:
#     a zona with elastodamage, two stiffened-gas fluids, two moving
#     bodies, absorbing faces; 8967 particles).
# usage: benchmarks/bench-mpm.sh [BUILD_DIR]   (STEPS: steps per run, 100)
bench_name=mpm bench_env=STEPS
source "$(dirname "$0")/bench-lib.sh"
steps=${STEPS:-100}
cores=$(nproc)
printf '%-28s %8s %7s %8s %14s %14s\n' case particles threads steps \
  "p-steps/s" "p-steps/s/core"
for scene in cases/mpm/bench-block.yaml cases/mpm/m2-shock-tube.yaml \
  cases/mpm/membrane-sphere-gas.yaml cases/mpm/m4-oocyte-reduced.yaml; do
  name=$(basename "$scene" .yaml)
  for threads in 1 "$cores"; do
    dir="$out/$name-t$threads"
    OMP_NUM_THREADS=$threads bench_run "$dir" "$scene" \
      --set time.max_steps="$steps" --set output.every=1000000
    s="$dir/summary.json"
    printf '%-28s %8s %7s %8s %14.3e %14.3e\n' "$name" "$(get particles "$s")" \
      "$threads" "$(get steps "$s")" "$(get point_steps_per_second "$s")" \
      "$(get point_steps_per_second_per_core "$s")"
  done
done
