#!/usr/bin/env bash
# Write fuzz seeds with --set override lines into folder $1: a scene, a NUL
# byte, then KEY=VALUE lines (tests/fuzz/fuzz_scene.c reads them so).
set -euo pipefail
dir=$1
here=$(cd "$(dirname "$0")/../.." && pwd)
seed() { # NAME SCENE OVERRIDE...
  local name=$1 scene=$2
  shift 2
  {
    cat "$here/$scene"
    printf '\0'
    printf '%s\n' "$@"
  } >"$dir/$name"
}
seed set-f2 tests/data/scenes/f2-unconstrained-compression.yaml \
  discretization.mesh_size=8.02e-3 time.dt=1e-3 \
  boundary.3.displacement.z=-0.06 time.quasi_static.tolerance=1e-9 \
  "output.fields=[force, jacobian]" materials.0.poisson_ratio=0.3
seed set-grow tests/data/scenes/minimal-2d.yaml \
  time.quasi_static.method=damping "fpm.penalty=50" \
  'bodies=[{material: rubber, region: "x - 0.5"}]' "boundary=[]" \
  boundary.0.on=xmax "boundary.0.velocity.x=100*t" \
  "reference.displacement.x=0.1*x"
seed set-expr tests/data/scenes/f2-unconstrained-compression.yaml \
  "boundary.3.displacement.z=-0.02*sin(2*pi*t)*exp(-t)" \
  "reference.displacement.x=0.1*x^2-abs(y)" "boundary.4.traction.x=1/(t+1)"
seed set-mpm cases/mpm/m2-sod.yaml "mpm.flip=0.5" "time.end=1e-4" \
  "gravity=[0, 0, -9.81]"
