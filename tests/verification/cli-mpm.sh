#!/usr/bin/env bash
# The pointmech program end to end on MPM scenes: bad scenes are refused with
# file:line:col, the key and the expected value, and no output; plan lists
# the MPM pipeline; a run writes its outputs; a run that goes unstable or
# loses a particle off the grid stops with its diagnosis; probe and
# convergence work on MPM outputs.
#
# The scenes here have 100 to 1600 particles: at that size a step is mostly
# OpenMP fork/join, and two threads that share their cores with anything
# else spin against each other and run tens of times slower.  So one thread
# unless the caller sets OMP_NUM_THREADS.
set -u
bin=$1
src=$2
mpm=$src/cases/mpm
tube=$mpm/m2-shock-tube-reduced.yaml
disks=$mpm/disks-collision.yaml
bar=$mpm/bar-first-mode.yaml
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"

not_in() { ! grep -qF -- "$1" "$2"; } # word, file
no_tmp() { ! compgen -G "$1/*.tmp.*" >/dev/null; } # dir: no FILE.tmp.PID

bad_scene fluid-without-eos "$tube" '/eos:/d' '- name: gas' \
  'materials.0.eos: missing required key'
bad_scene negative-cell "$tube" 's/mesh_size: 5.0e-3/mesh_size: -0.01/' \
  'mesh_size:' 'discretization.mesh_size: expected a number > 0, got -0.01'
bad_scene box-outside-grid "$tube" \
  's/max: \[1.0, 5.0e-3, 5.0e-3\]}, density: 0.125/max: [1.2, 5.0e-3, 5.0e-3]}, density: 0.125/' \
  'density: 0.125' 'bodies.1.box: expected a shape inside domain.box'
check "box-outside-grid: says 'outside the grid'" \
  grep -qF 'outside the grid' "$work/err"
bad_scene sphere-outside-grid "$disks" \
  's/center: \[0.8, 0.8\]/center: [0.9, 0.8]/' 'center: \[0.9, 0.8\]' \
  'bodies.1.sphere: expected a shape inside domain.box'
check "sphere-outside-grid: says 'outside the grid'" \
  grep -qF 'outside the grid' "$work/err"
bad_scene fluid-without-pressure "$tube" 's/, pressure: 0.001//' \
  'density: 0.125' 'bodies.1: missing required key pressure'
bad_scene traction-on-region-in-mpm "$tube" \
  's/{on: xmax, velocity: {x: 0}/{region: "x - 0.9", traction: {x: 0}/' \
  'region: "x - 0.9"' \
  'boundary.1.traction: expected a traction on a face of domain.box or a named surface (method mpm; a region holds particles by a displacement or velocity), got traction with region'
bad_scene flip-2 "$tube" 's/flip: 1.0/flip: 2/' 'flip:' \
  'mpm.flip: expected a number in [0, 1], got 2'
bad_scene unknown-mpm-key "$tube" 's/^  update: musl$/  update: musl\n  updat: usf/' \
  'updat: usf' 'mpm.updat: unknown key'

# The same through --set: the override is named, nothing is written.
"$bin" run "$disks" --set mpm.update=xyz --out "$work/out-set" --quiet \
  >/dev/null 2>"$work/err"
rc=$?
check "bad mpm override: exit 1 (got $rc)" test $rc -eq 1
check "bad mpm override: named with the choices" \
  grep -qF -- '--set mpm.update=xyz: expected one of usf, usl, musl' "$work/err"
check "bad mpm override: no output" test ! -e "$work/out-set"

# plan: the pipeline has the stages the scene needs and no others.
"$bin" plan "$disks" >"$work/plan" 2>"$work/err"
rc=$?
check "plan disks: exit 0 (got $rc)" test $rc -eq 0
for w in p2g 'grid update' g2p 'stress: solid' move 'bytes per particle'; do
  check "plan disks: lists '$w'" grep -qF "$w" "$work/plan"
done
for w in 'stress: fluid' absorbing gravity damping; do
  check "plan disks: does not list '$w'" not_in "$w" "$work/plan"
done
"$bin" plan "$tube" >"$work/plan" 2>"$work/err"
rc=$?
check "plan tube: exit 0 (got $rc)" test $rc -eq 0
for w in 'stress: fluid' iterative 'artificial viscosity' \
  'density energy pressure q'; do
  check "plan tube: lists '$w'" grep -qF "$w" "$work/plan"
done
check "plan tube: no gravity stage" not_in gravity "$work/plan"
"$bin" plan "$tube" --set 'gravity=[0,0,-9.81]' >"$work/plan" 2>"$work/err"
rc=$?
check "plan tube with gravity: exit 0 (got $rc)" test $rc -eq 0
check "plan tube with gravity: gravity stage" \
  grep -Eq '^ +[0-9]+\. gravity ' "$work/plan"

# The reduced shock tube: outputs, history columns, summary, last frame.
out=$work/out-tube
"$bin" run "$tube" --out "$out" --quiet >/dev/null 2>"$work/err"
rc=$?
check "shock tube: exit 0 (got $rc)" test $rc -eq 0
for f in results.h5 results.xdmf history.csv summary.json; do
  check "shock tube: $f written" test -s "$out/$f"
done
check "shock tube: no temporary files" no_tmp "$out"
for c in internal_energy energy_iterations; do
  check "shock tube: history column $c" \
    grep -Eq "(^|,)$c(,|$)" <(head -1 "$out/history.csv")
done
check "shock tube: history has rows" test "$(wc -l <"$out/history.csv")" -gt 2
for s in '"method": "mpm"' '"status": "completed"' '"particles": 800'; do
  check "shock tube: summary $s" grep -qF "$s" "$out/summary.json"
done
check "shock tube: last frame at t = 0.143 s has finite density, pressure, internal_energy" \
  /usr/bin/python3 - "$out/results.h5" <<'EOF'
import sys
import h5py
import numpy as np
with h5py.File(sys.argv[1], "r") as f:
    frames = f["frames"]
    last = frames[sorted(frames)[-1]]
    assert abs(last.attrs["time"] - 0.143) < 1e-12, last.attrs["time"]
    for name in ("density", "pressure", "internal_energy"):
        a = last[name][...]
        assert a.shape == (800,), (name, a.shape)
        assert np.isfinite(a).all() and (a > 0).all(), name
EOF

# Far above the stable step (0.019 s): J < 0 after a few steps.
"$bin" run "$disks" --set time.dt=0.5 --out "$work/out-unstable" --quiet \
  >/dev/null 2>"$work/err"
rc=$?
check "unstable: exit 2 (got $rc)" test $rc -eq 2
check "unstable: diagnosis names step, time, particle, position" \
  grep -Eq "step [0-9]+, t = .* particle [0-9]+ at \(" "$work/err"
check "unstable: cause" grep -Eq "volume ratio J = .* <= 0" "$work/err"
check "unstable: summary says so" \
  grep -q '"status": "unstable"' "$work/out-unstable/summary.json"
check "unstable: results kept" test -s "$work/out-unstable/results.h5"

# Disk 0 thrown at disk 1 at 5 m/s: disk 1 is pushed off the grid.
"$bin" run "$disks" --set 'bodies.0.velocity=[5,5]' --set time.end=0.3 \
  --out "$work/out-left" --quiet >/dev/null 2>"$work/err"
rc=$?
check "left the grid: exit 2 (got $rc)" test $rc -eq 2
check "left the grid: diagnosis" grep -Eq \
  "step [0-9]+, t = .* particle [0-9]+ at \(.*left the grid.*enlarge domain.box" \
  "$work/err"
check "left the grid: results kept" test -s "$work/out-left/results.h5"

# probe on an MPM output: the disks before contact translate rigidly,
# u = +-(0.05, 0.05) m at t = 0.5 s.
out=$work/out-disks
"$bin" run "$disks" --set time.end=0.5 --out "$out" --quiet >/dev/null \
  2>"$work/err"
rc=$?
check "disks to t = 0.5 s: exit 0 (got $rc)" test $rc -eq 0
printf 'x,y,z\n0.2,0.2,0\n0.15,0.25,0\n0.8,0.8,0\n0.85,0.7,0\n' >"$work/pts.csv"
"$bin" probe "$out" --points "$work/pts.csv" >"$work/probe" 2>"$work/err"
rc=$?
check "probe disks: exit 0 (got $rc)" test $rc -eq 0
check "probe disks: header" grep -qx 'x,y,z,u_x,u_y,u_z' "$work/probe"
check "probe disks: u = (0.05, 0.05) on disk 0, -(0.05, 0.05) on disk 1" \
  awk -F, '
  function num(s) { return s ~ /^-?[0-9]+(\.[0-9]*)?([eE][-+]?[0-9]+)?$/ }
  function abs(v) { return v < 0 ? -v : v }
  NR > 1 {
    n++
    for (i = 1; i <= 6; i++) if (!num($i)) bad++
    s = $1 < 0.5 ? 1 : -1
    if (abs($4 - 0.05 * s) > 1e-6 || abs($5 - 0.05 * s) > 1e-6 || $6 != 0) bad++
  }
  END { exit !(n == 4 && bad == 0) }' "$work/probe"
printf 'x,y,z\n0.1,0.0025,0.0025\n0.7,0.0025,0.0025\n' >"$work/pts-tube.csv"
"$bin" probe "$work/out-tube" --points "$work/pts-tube.csv" >"$work/probe" \
  2>"$work/err"
rc=$?
check "probe tube: exit 0 (got $rc)" test $rc -eq 0
check "probe tube: finite numbers, gas moved right past the diaphragm" \
  awk -F, '
  function num(s) { return s ~ /^-?[0-9]+(\.[0-9]*)?([eE][-+]?[0-9]+)?$/ }
  NR > 1 { n++; for (i = 1; i <= 6; i++) if (!num($i)) bad++ }
  NR == 3 && !($4 > 0) { bad++ }
  END { exit !(n == 2 && bad == 0) }' "$work/probe"

# convergence: the bar's quarter period on cells of 1, 0.5 and 0.25 m
# against the finest.
out=$work/out-conv
"$bin" convergence "$bar" --set-ladder discretization.mesh_size=1,0.5,0.25 \
  --reference last --set time.end=2.5 --out "$out" >/dev/null 2>"$work/err"
rc=$?
check "convergence bar: exit 0 (got $rc)" test $rc -eq 0
check "convergence bar: convergence.md" test -s "$out/convergence.md"
check "convergence bar: convergence.csv, one row per level and the reference" \
  test "$(wc -l <"$out/convergence.csv")" -eq 4
check "convergence bar: error falls with h" awk -F, '
  NR == 1 { for (i = 1; i <= NF; i++) if ($i == "error") c = i }
  NR == 2 { e1 = $c } NR == 3 { e2 = $c }
  END { exit !(c > 0 && e1 > 0 && e2 > 0 && e2 < e1) }' "$out/convergence.csv"
refused "convergence, no analytic field" "the scene has no reference field" \
  "$work/out-conv-analytic" "$bin" convergence "$bar" \
  --set-ladder discretization.mesh_size=1,0.5 --reference analytic \
  --out "$work/out-conv-analytic"

# The FPM F2 scene as MPM.  Its gmsh element size does not divide the box,
# so the loader lays the grid: the largest cell up to it that divides the
# box (0.1 / 12), and room beyond the free faces, which plan prints.  A
# cell that divides the box (1e-2) is taken as it is, and the body, which
# fills the scene's box, still gets room beyond its free faces: without it
# the particles left the grid once the load ramped up.  compare.sh runs
# this scene by both MPM methods to the exact state.
fpm_f2=$src/cases/fpm/f2-unconstrained-compression.yaml
for method in mpm mpm-implicit; do
  "$bin" plan "$fpm_f2" --set method=$method >"$work/plan" 2>"$work/err"
  rc=$?
  check "FPM F2 as $method: plan exit 0 (got $rc)" test $rc -eq 0
  check "FPM F2 as $method: plan prints the grid it chose" \
    grep -q "cell 0.00833333 m" "$work/plan"
  check "FPM F2 as $method: and the room (x 0/6 y 0/6 z 0/0)" \
    grep -q "cells below/above): x 0/6 y 0/6 z 0/0" "$work/plan"
done
"$bin" plan "$fpm_f2" --set method=mpm --set discretization.mesh_size=1e-2 \
  >"$work/plan" 2>"$work/err"
rc=$?
check "FPM F2 as MPM, dividing cell: plan exit 0 (got $rc)" test $rc -eq 0
check "FPM F2 as MPM, dividing cell: the cell as given" \
  grep -q "cell 0.01 m" "$work/plan"
check "FPM F2 as MPM, dividing cell: room beyond the free faces (x 0/5 y 0/5)" \
  grep -q "cells below/above): x 0/5 y 0/5 z 0/0" "$work/plan"
"$bin" run "$fpm_f2" --set method=mpm --set discretization.mesh_size=1e-2 \
  --set time.end=0.3 --out "$work/out-f2-as-mpm" --quiet >/dev/null 2>"$work/err"
rc=$?
check "FPM F2 as MPM, dividing cell: runs to t = 0.3 s, not yet quasi-static (exit 3, got $rc)" \
  test $rc -eq 3
check "FPM F2 as MPM, dividing cell: no particle leaves the grid" \
  sh -c "! grep -qF 'left the grid' '$work/err'"
"$bin" plan "$mpm/f2-unconstrained-compression.yaml" >"$work/plan" \
  2>"$work/err"
rc=$?
check "MPM F2: plan exit 0 (got $rc)" test $rc -eq 0
check "MPM F2: plan prints the grid" \
  grep -Eq '^grid +[0-9]+ x [0-9]+ x [0-9]+ nodes' "$work/plan"
check "MPM F2: plan prints the particle count" \
  grep -Eq '^particles +[0-9]+ ' "$work/plan"

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
