#!/bin/bash
# Explicit MPM across MPI ranks on this machine, one run at a time:
#   strong scaling: the same scene on 1 rank x 1 thread, 1 rank x 2
#     threads, 2 ranks x 1 thread (each rank bound to a core);
#   weak scaling: twice the particles (particles_per_cell doubled along x)
#     on 2 ranks x 1 thread against the scene on 1 x 1;
# for the 3-D block (cases/mpm/bench-block.yaml, 110592 particles,
# quadratic), the shock tube at the paper's size (cases/mpm/m2-shock-tube,
# 20000 particles, linear) and the disks refined 8 times (2-D, 26624
# particles).  Prints seconds per step of the step's stages (rank 0's,
# which wait for the others in the exchanges), the speed-up and efficiency
# against 1 x 1 (per core used), and what a rank sends per step: node sums
# (bytes), particles (bytes), and the exchanges' seconds over the run.
# usage: scripts/bench-ranks.sh [BUILD_DIR]   (STEPS: steps per run, 200)
bench_name=ranks
source "$(dirname "$0")/bench-lib.sh"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
steps=${STEPS:-200}
py=/usr/bin/python3

# fig SUMMARY: "particles steps s/step node-bytes particle-bytes halo-s mig-s"
fig() {
  $py - "$1" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
r = s.get('ranks', {})
print(s['points'], s['steps'], s['step_seconds'] / max(s['steps'], 1),
      r.get('node_bytes_per_step', 0), r.get('particle_bytes_per_step', 0),
      r.get('node_exchange_seconds', 0), r.get('migration_seconds', 0))
EOF
}

# run NAME RANKS THREADS SCENE [--set ...]: the run's figures
run() {
  local name=$1 ranks=$2 threads=$3 scene=$4
  shift 4
  local dir="$out/$name-r$ranks-t$threads"
  if [ "$ranks" -eq 1 ]; then
    OMP_NUM_THREADS=$threads "$bin" run --overwrite "$scene" --out "$dir" \
      --quiet --set time.max_steps="$steps" --set output.every=1000000 "$@" \
      2>/dev/null || true
  else
    OMP_NUM_THREADS=$threads mpirun -np "$ranks" --bind-to core "$bin" run \
      --overwrite "$scene" --out "$dir" --quiet \
      --set time.max_steps="$steps" --set output.every=1000000 "$@" \
      2>/dev/null || true
  fi
  fig "$dir/summary.json"
}

printf '%-14s %-8s %-9s %6s %10s %8s %10s %12s %14s %8s %8s\n' case kind \
  "ranks x t" points s/step speed-up efficiency "node B/step" \
  "particle B/step" halo-s migr-s
row() { # case kind config cores base figures...
  local c=$1 k=$2 cfg=$3 cores=$4 base=$5
  shift 5
  local n=$1 per=$3 nb=$4 pb=$5 hs=$6 ms=$7
  $py -c "
b, p, c = $base, $per, $cores
print('%-14s %-8s %-9s %6s %10.3e %8.2f %10.2f %12.0f %14.0f %8.2f %8.2f' % (
  '$c', '$k', '$cfg', $n, p, b / p, b / p / c, $nb, $pb, $hs, $ms))"
}

# case, scene, particles per cell doubled along x, an override
for spec in "block cases/mpm/bench-block.yaml 4,2,2" \
  "shock-tube cases/mpm/m2-shock-tube.yaml 50,1,1" \
  "disks cases/mpm/disks-collision.yaml 4,2 discretization.mesh_size=6.25e-3"; do
  read -r name scene ppc2 extra <<<"$spec"
  sets=()
  [ -n "${extra:-}" ] && sets=(--set "$extra")
  one=$(run "$name" 1 1 "$scene" "${sets[@]}")
  base=$(echo "$one" | cut -d' ' -f3)
  row "$name" strong 1x1 1 "$base" $one
  row "$name" strong 1x2 2 "$base" $(run "$name" 1 2 "$scene" "${sets[@]}")
  row "$name" strong 2x1 2 "$base" $(run "$name" 2 1 "$scene" "${sets[@]}")
  # weak: twice the particles on twice the ranks, the same time per step
  # at perfect efficiency
  w=$(run "$name-weak" 2 1 "$scene" "${sets[@]}" \
    --set "mpm.particles_per_cell=[$ppc2]")
  row "$name" weak 2x1 1 "$base" $w
done
