#!/usr/bin/env bash
# Membranes and bodies moving as prescribed across MPI ranks against the
# same runs on one process (as ranks.sh: 1e-10 of each field's largest
# magnitude, each rank one thread).
# Usage: ranks-membranes.sh POINTMECH SOURCE_DIR RANKS_MIGRATE
#
# A membrane point's normal reads its neighbours, which may be on another
# rank (ghosts, mpm_par_ghosts.h): the normals are one process's bit for
# bit, and what differs is the node sums' order, as in ranks.sh.  The
# gas-filled sphere is given a speed of 12 m/s along x, the axis the cut
# crosses, so that its points move between the ranks (and the links are
# made anew) within the steps the test runs.
set -u
bin=$1
src=$2
migrate=$3
. "$(dirname "$0")/lib.sh"
# shellcheck source=ranks-lib.sh
. "$(dirname "$0")/ranks-lib.sh"

sphere=$mpm/membrane-sphere-gas.yaml
moving="--set bodies.0.velocity=[12,0,0] --set bodies.1.velocity=[12,0,0]"

# The sphere's triangles span the cut, and its points move across it: every
# rank's ghosts are the points linked to its own, after every migration.
ranks 2 "$migrate" "$sphere" 100 "bodies.0.velocity=[12,0,0]" \
  "bodies.1.velocity=[12,0,0]" >"$work/mig" 2>&1
rc=$?
grep -v '^ *$' "$work/mig" | tail -2
check "sphere, migration on 2 ranks: exit 0 (got $rc)" test $rc -eq 0
check "sphere on 2 ranks: membrane points moved, triangles span the ranks" \
  grep -qE 'membrane points moved between ranks [1-9][0-9]*, links spanning .* [1-9][0-9]* \(' \
  "$work/mig"

# The gas-filled sphere (3-D, triangles) on 2 and 3 ranks.
# shellcheck disable=SC2086
across sphere "$sphere" 2 --set time.max_steps=200 --set output.every=50 $moving
# shellcheck disable=SC2086
across sphere "$sphere" 3 --set time.max_steps=200 --set output.every=50 $moving
# On 2 ranks the moving sphere crowds one box and the boxes are cut anew
# (mpm.rebalance): the membrane's points relinked where they are, the run
# still one process's to round-off (above).
check "sphere on 2 ranks: the boxes cut anew as it moves" $py -c "
import json, sys
sys.exit(json.load(open('$work/sphere-2/summary.json'))['ranks']['recuts'] < 1)"

# One rank under mpirun is one process.
# shellcheck disable=SC2086
ranks 1 "$bin" run "$sphere" --out "$work/sphere-np1" --quiet \
  --set time.max_steps=200 --set output.every=50 $moving >/dev/null 2>"$work/err"
check "sphere on 1 rank: one process, bit for bit" \
  $same "$work/sphere-1" "$work/sphere-np1"

# The gas-filled circle (2-D, a curve's neighbours) on 2 ranks.
circle=$mpm/m5-gas-circle.yaml
links="bodies.0.membrane.normals=connectivity"
ranks 2 "$migrate" "$circle" 100 "$links" >"$work/mig" 2>&1
rc=$?
grep -v '^ *$' "$work/mig" | tail -2
check "circle, migration on 2 ranks: exit 0 (got $rc)" test $rc -eq 0
check "circle on 2 ranks: the curve spans the ranks" \
  grep -qE 'links spanning .* [1-9][0-9]* \(' "$work/mig"
across circle "$circle" 2 --set "$links" --set time.max_steps=400 \
  --set output.every=100
# Its normals fitted per cell (the scene's hybrid rule, as the paper ran
# it): each rank fits its own cells with the points of the blocks of cells
# around them, other ranks' included.  The fits amplify round-off (which
# points are degenerate, which cells merge): between one and two threads
# on one process, which sum the nodes in other orders too, 1.1e-11 at 100
# steps, 1.3e-11 at 200 and 1.6e-10 at 400; hence 100 steps.
# normals_max_condition, the largest cond(T) of a step's fits (up to
# 6e19), is left out: it differs by 1.3e-8 between those two runs.
bounds="normals_max_condition=inf" across circle-fitted "$circle" 2 \
  --set time.max_steps=100 --set output.every=25

# The dogbone (M5): its curve crosses the cut with many points on either
# side (the circle's cut, 5 cells from the symmetry planes, leaves one
# rank a single particle), its normals fitted per cell, 200 steps.
bounds="normals_max_condition=inf" across dogbone-fitted "$mpm/m5-gas-dogbone.yaml" 2 \
  --set time.max_steps=200 --set output.every=50

# The sphere's normals fitted per cell in 3-D (hybrid-quadratic: blocks of
# up to 8 cells a side, reaching 7 cells beyond a rank's box): the first
# step's normals, from the positions every run starts from, are one
# process's bit for bit (later steps differ as two threads do: a fit's
# degenerate points and merged cells change with the positions' round-off
# on one process as well); ranks_migrate checks every rank's nearby points.
fitted="bodies.0.membrane.normals=hybrid-quadratic"
"$bin" run "$sphere" --out "$work/fitted-1" --quiet --set "$fitted" \
  --set time.max_steps=1 --set output.every=1 >/dev/null 2>"$work/err"
for n in 2 3; do
  ranks $n "$bin" run "$sphere" --out "$work/fitted-$n" --quiet \
    --set "$fitted" --set time.max_steps=1 --set output.every=1 \
    >/dev/null 2>"$work/err"
  check "sphere, normals fitted per cell on $n ranks: one process's, bit for bit" \
    $py -c "
import h5py, numpy as np, sys
a, b = (h5py.File('$work/fitted-%s/results.h5' % r, 'r')['frames']['000001']
        ['normal'][()] for r in (1, $n))
sys.exit(not np.array_equal(a, b))"
done
ranks 3 "$migrate" "$sphere" 60 "$fitted" "bodies.0.velocity=[12,0,0]" \
  "bodies.1.velocity=[12,0,0]" >"$work/mig" 2>&1
rc=$?
grep -v '^ *$' "$work/mig" | tail -1
check "sphere, normals fitted per cell, migration on 3 ranks: exit 0 (got $rc)" \
  test $rc -eq 0

# The reduced oocyte (case M4: a membrane with damage, two fluids, two
# pipettes moving as prescribed, absorbing faces), 300 steps.
oocyte=$mpm/m4-oocyte-reduced.yaml
ranks 2 "$bin" plan "$oocyte" >"$work/plan" 2>"$work/err"
check "oocyte, plan on 2 ranks: exit 0" test $? -eq 0
grep -E '^ranks|particles per rank' "$work/plan"
check "oocyte, plan on 2 ranks: particles shared within 5%" $py -c "
import re, sys
m = re.search(r'imbalance ([0-9.]+)', open('$work/plan').read())
sys.exit(not (m and float(m.group(1)) < 1.05))"
across oocyte "$oocyte" 2 --set time.max_steps=300 --set output.every=100

# A failure stops every rank with one process's message: the injection
# pipette's prescribed velocity is not finite before t = 1 us.  Its
# particles are all on rank 1; rank 0, which has none, must not report one
# of its own.
nan="bodies.4.motion.velocity.y=sqrt(t - 1.0e-6)"
"$bin" run "$oocyte" --out "$work/nan-1" --quiet --set "$nan" >/dev/null \
  2>"$work/err1"
ranks 2 "$bin" run "$oocyte" --out "$work/nan-2" --quiet --set "$nan" \
  >/dev/null 2>"$work/err"
rc=$?
check "oocyte, a velocity not finite on 2 ranks: exit 2 (got $rc)" \
  test $rc -eq 2
check "oocyte, a velocity not finite on 2 ranks: one process's message" \
  grep -qF "$(grep -o 'step 1, .*is not finite at t = [^ ]* s' "$work/err1")" \
  "$work/err"

# A tear across the cut: a pin moving as prescribed pushes into the top of
# the sphere, where the cut (x = 0) passes, until its points fail.
cat >"$work/tear.yaml" <<'YAML'
name: membrane-sphere-tear
method: mpm
dimension: 3
domain: {box: {min: [-0.7, -0.7, -0.7], max: [0.7, 0.7, 0.7]}}
discretization: {mesh_size: 0.1}
materials:
  - name: skin
    model: linear-elastic
    density: 0.5
    youngs_modulus: 1.0e6
    poisson_ratio: 0.3
    damage: {c0: 1, c1: 10, elastic_limit: 0.015, failure_strain: 0.02}
  - {name: gas, model: fluid, density: 1.0, eos: {type: ideal-gas, gamma: 1.4}, viscosity: 0.2}
  - {name: pin, model: linear-elastic, density: 1000, youngs_modulus: 1.0e6, poisson_ratio: 0.3}
bodies:
  - name: membrane
    material: skin
    membrane: {thickness: 0.1, sphere: {center: [0, 0, 0], radius: 0.5, refinement: 4}}
  - {name: gas, material: gas, inside: membrane, density: 1.0, pressure: 1000}
  - {name: pin, material: pin, box: {min: [-0.05, -0.05, 0.52], max: [0.05, 0.05, 0.62]}, particles_per_cell: [4], motion: {velocity: {z: -10}}}
mpm: {shape: quadratic, update: musl, flip: 0.95, particles_per_cell: [2]}
time: {end: 0.6, max_steps: 200}
output: {every: 50, fields: [displacement, velocity, stress]}
YAML
across tear "$work/tear.yaml" 2
check "tear on 2 ranks: failed points on both sides of the cut" $py -c "
import h5py, sys
f = h5py.File('$work/tear-2/results.h5', 'r')
g = f['frames'][sorted(f['frames'])[-1]]
failed, x = g['failed'][()].ravel() > 0, g['position'][()]
left, right = int((x[failed, 0] < 0).sum()), int((x[failed, 0] >= 0).sum())
print('tear on 2 ranks: failed points %d (x < 0: %d, x >= 0: %d)' %
      (left + right, left, right))
sys.exit(not (left > 0 and right > 0))"

# Interrupted on 2 ranks and resumed, the sphere moving across the cut:
# the membrane's arrays in one-process order in the checkpoint, its links
# made again on resuming.
long="--set time.max_steps=600 --set output.every=50 $moving"
# shellcheck disable=SC2086
"$bin" run "$sphere" --out "$work/sphere-long-1" --quiet $long >/dev/null 2>&1
# shellcheck disable=SC2086
ranks 2 "$bin" run "$sphere" --out "$work/sphere-long-2" --quiet $long \
  >/dev/null 2>&1
# shellcheck disable=SC2086
interrupt 2 "$work/sphere-cut" "$sphere" $long
resume_on "$work/sphere-cut" 1 2
check "sphere interrupted on 2 ranks, resumed on 2: the run of 2 ranks, bit for bit" \
  $same "$work/sphere-long-2" "$work/sphere-cut-2"
roundoff "sphere interrupted on 2 ranks, resumed on 1" "$work/sphere-long-1" \
  "$work/sphere-cut-1"

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
