#!/usr/bin/env bash
# A condition whose expression stops being finite during a run (a square
# root of a negative number past t = 0.05) stops the run as a numerical
# failure, exit status 2, naming the step, time, point or node and its
# position, the scene key at file:line:col and the expression, for FPM
# (a prescribed displacement, a traction) and MPM (a prescribed
# displacement, a velocity); summary.json says "unstable" and the frames
# before are kept.  Tiny scenes: a second each.
set -u
bin=$1
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"

cat >"$work/fpm.yaml" <<'YAML'
name: not-finite-fpm
method: fpm
dimension: 3
domain: {box: {min: [0, 0, 0], max: [0.1, 0.1, 0.1]}}
discretization: {mesh_size: 0.05}
materials:
  - {name: gel, model: neo-hookean, density: 1000, youngs_modulus: 3000, poisson_ratio: 0.3}
bodies: [{material: gel, region: domain}]
boundary:
  - {on: zmin, displacement: {x: 0, y: 0, z: 0}}
  - {on: zmax, displacement: {z: "-0.001*sqrt(0.05 - t)"}, ramp: none}
time: {end: 0.1}
output: {every: 5}
YAML
cat >"$work/mpm.yaml" <<'YAML'
name: not-finite-mpm
method: mpm
dimension: 2
domain: {box: {min: [0, 0], max: [1, 0.5]}}
discretization: {mesh_size: 0.1}
materials:
  - {name: rubber, model: linear-elastic, density: 1100, youngs_modulus: 1.0e6, poisson_ratio: 0.3}
bodies: [{material: rubber, box: {min: [0, 0], max: [0.5, 0.5]}}]
boundary:
  - {on: xmin, displacement: {x: "0.001*sqrt(0.05 - t)"}, ramp: none}
time: {end: 0.1}
output: {every: 5}
YAML

not_in() { ! grep -qF -- "$1" "$2"; } # word, file

# A run stopped by a condition's value: exit 2, the message, the summary.
stopped() { # name, scene, message pattern (extended regex), --set ...
  local name=$1 scene=$2 pattern=$3 out=$work/out-$1
  shift 3
  "$bin" run "$scene" --out "$out" --quiet "$@" >/dev/null 2>"$work/err"
  local rc=$?
  check "$name: exit 2 (got $rc)" test $rc -eq 2
  check "$name: message" grep -Eq -- "$pattern" "$work/err"
  check "$name: no advice on dt" not_in "time.dt_safety" "$work/err"
  check "$name: summary says unstable" \
    grep -q '"status": "unstable"' "$out/summary.json"
  check "$name: summary names the key" \
    grep -q 'not a finite value' "$out/summary.json"
  check "$name: frames before kept" test -s "$out/results.h5"
}
num='-?[0-9.e+-]+'
xyz="\\($num, $num, $num\\)"

stopped fpm-displacement "$work/fpm.yaml" \
  "^pointmech: error: step [0-9]+, t = 0\\.05[0-9]* s: point [0-9]+ at $xyz: $work/fpm.yaml:11:34: boundary\\.1\\.displacement\\.z: \"-0\\.001\\*sqrt\\(0\\.05 - t\\)\" = nan, not a finite value$"
stopped fpm-traction "$work/fpm.yaml" \
  "^pointmech: error: step [0-9]+, t = 0\\.05[0-9]* s: facet of point [0-9]+ at $xyz: --set boundary\\.1\\.traction\\.y=100\\*sqrt\\(0\\.05-t\\): \"100\\*sqrt\\(0\\.05-t\\)\" = nan, not a finite value$" \
  --set "boundary.1.displacement={z: 0}" \
  --set "boundary.1.traction.y=100*sqrt(0.05-t)"
stopped mpm-displacement "$work/mpm.yaml" \
  "^pointmech: error: step [0-9]+, t = 0\\.05[0-9]* s: node [0-9]+ at $xyz: $work/mpm.yaml:10:34: boundary\\.0\\.displacement\\.x: \"0\\.001\\*sqrt\\(0\\.05 - t\\)\" = nan, not a finite value$"
stopped mpm-velocity "$work/mpm.yaml" \
  "^pointmech: error: step [0-9]+, t = 0\\.05[0-9]* s: node [0-9]+ at $xyz: --set boundary\\.0=\\{on: xmin, velocity: \\{y: 0\\.01\\*sqrt\\(0\\.05-t\\)\\}\\}: boundary\\.0\\.velocity\\.y: \"0\\.01\\*sqrt\\(0\\.05-t\\)\" = nan, not a finite value$" \
  --set "boundary.0={on: xmin, velocity: {y: 0.01*sqrt(0.05-t)}}"

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
