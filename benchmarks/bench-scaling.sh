#!/bin/bash
# Strong scaling on this machine (2 cores) of four cases across ranks:
# the shock tube at the paper's size (explicit MPM, 20 000
# particles), the reduced oocyte (explicit MPM: membrane with damage, two
# fluids, pipettes moving as prescribed), case I2 at 64^2 cells (implicit
# MPM, 262 144 particles, GMRES + GAMG) and F3 60% by FPM (dynamic
# relaxation at h = 5.19e-3), each as 1 rank x 1 thread, 1 rank x 2
# threads and 2 ranks x 1 thread (not bound: BIND=core binds each rank to
# a core, which on this machine slowed FPM's 2 ranks by 40%, 21.7 ms a
# step against 15.6, in waiting at the step's sums); the shock
# tube also weak (twice the particles on 2 ranks).  The configurations of
# a case take turns, REPEAT times (3): single runs vary by 10-40% here.
# Prints per configuration the seconds of the step's stages per step (a
# load step for I2; the median, and the range), the speed-up and the
# efficiency per core against 1 x 1 (of the medians and of the fastest
# runs), and what a rank sends per step (node sums, particles, membrane
# ghosts, FPM's ghost displacements).
# usage: benchmarks/bench-scaling.sh [BUILD_DIR]   (STEPS: 200, the explicit
#        runs' steps: F3 STEPS, the shock tube 2 STEPS, the oocyte 10 STEPS;
#        TABLE_ONLY=1 tabulates an earlier call's runs again; CASES="f3-fpm
#        i2" runs those cases only, of shock-tube oocyte i2 f3-fpm)
bench_name=scaling bench_env="STEPS BIND REPEAT TABLE_ONLY CASES"
source "$(dirname "$0")/bench-lib.sh"
steps=${STEPS:-200}
bind=${BIND:-none}
repeat=${REPEAT:-3}

# fig SUMMARY: points, steps, s/step, bytes a rank sends per step
fig() {
  $py - "$1" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
r = s.get('ranks') or {}
n = max(s['steps'], 1)
sent = sum(r.get(k, 0) for k in ('node_bytes_per_step',
                                 'particle_bytes_per_step',
                                 'ghost_bytes_per_step'))
print(s['points'], s['steps'], s['step_seconds'] / n, sent)
EOF
}

printf '%-20s %7s %10s %21s %6s %6s %9s %10s\n' "case config" points \
  s/step "(range)" speed eff "eff(fast)" "B/step/rank"
# case, scene, weak scaling's particles per cell (or -), overrides
ranks_specs "shock-tube cases/mpm/m2-shock-tube.yaml 50,1,1 time.max_steps=$((2 * steps))" \
  "oocyte cases/mpm/m4-oocyte-reduced.yaml - time.max_steps=$((10 * steps))" \
  "i2 cases/mpm/i2-vessel-slice.yaml - time.end=1" \
  "f3-fpm cases/fpm/f3-extension-60.yaml - discretization.mesh_size=$(paper_mesh_size 5.19e-3) time.max_steps=$steps"
