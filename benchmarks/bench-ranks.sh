#!/bin/bash
# Explicit MPM across MPI ranks on this machine, one run at a time:
#   strong scaling: the same scene on 1 rank x 1 thread, 1 rank x 2
#     threads, 2 ranks x 1 thread (each rank bound to a core);
#   weak scaling: twice the particles (particles_per_cell doubled along x)
#     on 2 ranks x 1 thread against the scene on 1 x 1;
# for the 3-D block (cases/mpm/bench-block.yaml, 110592 particles,
# quadratic), the shock tube at the paper's size (cases/mpm/m2-shock-tube,
# 20000 particles, linear) and the disks refined 8 times (2-D, 25784
# particles).  Prints seconds per step of the step's stages (rank 0's,
# which wait for the others in the exchanges), the speed-up and efficiency
# against 1 x 1 (per core used), what a rank sends per step (node sums and
# particles, bytes), the exchanges' seconds over the run, and the ranks'
# own work (their stages less the exchanges): the busiest rank's over the
# mean (imbalance) and the share of the step that is not the mean rank's
# own work (exchanges and waiting).
# The configurations of a case run in turn, REPEAT times (5): single runs
# on this machine vary by 10-30%, and taking turns spreads its slow spells
# over all of them.  Each line gives the median seconds per step (the
# fastest and slowest beside it) and the other figures of the median run,
# and the efficiency of the fastest runs (against the fastest 1 x 1): on a
# noisy machine the fastest run is the closest to the work itself.
# usage: benchmarks/bench-ranks.sh [BUILD_DIR]   (STEPS: steps per run, 200;
#        TABLE_ONLY=1 tabulates the runs of an earlier call again; CASES="block
#        disks" runs those cases only, of block shock-tube disks)
bench_name=ranks bench_env="STEPS REPEAT TABLE_ONLY CASES"
source "$(dirname "$0")/bench-lib.sh"
bind=core
steps=${STEPS:-200}
repeat=${REPEAT:-5}

# fig SUMMARY: particles, steps, s/step, node bytes, particle bytes (per
# step), node-sum and migration seconds, imbalance, exchange share
fig() {
  $py - "$1" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
r = s.get('ranks', {})
n = max(s['steps'], 1)
own = r.get('own_work_seconds_mean', s['step_seconds'])
print(s['points'], s['steps'], s['step_seconds'] / n,
      r.get('node_bytes_per_step', 0), r.get('particle_bytes_per_step', 0),
      r.get('node_exchange_seconds', 0), r.get('migration_seconds', 0),
      r.get('own_work_seconds_max', own) / own if own > 0 else 1,
      1 - own / s['step_seconds'] if s['step_seconds'] > 0 else 0)
EOF
}

printf '%-20s %7s %10s %21s %6s %6s %9s %10s %10s %10s %10s %10s %10s\n' \
  "case config" points s/step "(range)" speed eff "eff(fast)" \
  "node B/st" "part. B/st" halo-s migr-s imbal. comm
# case, scene, particles per cell doubled along x, overrides
ranks_specs "block cases/mpm/bench-block.yaml 4,2,2 time.max_steps=$steps" \
  "shock-tube cases/mpm/m2-shock-tube.yaml 50,1,1 time.max_steps=$steps" \
  "disks cases/mpm/disks-collision.yaml 4,2 time.max_steps=$steps discretization.mesh_size=6.25e-3"
