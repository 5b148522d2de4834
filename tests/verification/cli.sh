#!/usr/bin/env bash
# The pointmech program end to end: bad scenes and overrides are refused with
# file:line:col and no output; a run that goes unstable stops with its
# diagnosis; plan, run, outputs and probe work on a coarse case F2.
#
# One OpenMP thread unless the caller sets OMP_NUM_THREADS: the runs are
# coarse (most have 229 points), where a step is mostly fork/join (on a
# loaded machine the undamped run below took 37 CPU seconds to t = 2 s on
# two threads, and 3.7 to t = 1 s on one).
set -u
bin=$1
src=$2
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
scene=$src/cases/fpm/f2-unconstrained-compression.yaml
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"

# A bad scene: exit 1, message "FILE:LINE:COL: ... KEY ...", no output dir.
bad_scene() { # name, sed expression, expected line, key word
  local name=$1 expr=$2 line=$3 word=$4 f="$work/$1.yaml"
  sed "$expr" "$scene" >"$f"
  "$bin" run "$f" --out "$work/out-$name" --quiet >/dev/null 2>"$work/err"
  local rc=$?
  check "$name: exit status 1 (got $rc)" test $rc -eq 1
  check "$name: names $f:$line:<col>" grep -Eq "$f:$line:[0-9]+" "$work/err"
  check "$name: names $word" grep -q -- "$word" "$work/err"
  check "$name: no output created" test ! -e "$work/out-$name"
}

# The four result files written whole, and no temporary file left.
outputs_complete() { # name, output folder
  for f in results.h5 results.xdmf history.csv summary.json; do
    check "$1: $f written" test -s "$2/$f"
  done
  check "$1: no temporary files" test -z "$(ls "$2" | grep tmp)"
}

line_of() { grep -n -- "$1" "$scene" | head -1 | cut -d: -f1; }

bad_scene unknown-key 's/fpm: {formulation: paper}/fpm: {formulation: paper, penalti: 3}/' \
  "$(line_of 'fpm: {formulation')" penalti
bad_scene wrong-type 's/mesh_size: 8.72e-3/mesh_size: fine/' \
  "$(line_of 'mesh_size:')" mesh_size
bad_scene negative-size 's/mesh_size: 8.72e-3/mesh_size: -0.01/' \
  "$(line_of 'mesh_size:')" mesh_size
bad_scene bad-poisson 's/poisson_ratio: 0.495/poisson_ratio: 0.5/' \
  "$(line_of 'poisson_ratio')" poisson_ratio

"$bin" run "$work/missing.yaml" --out "$work/out-missing" >/dev/null 2>"$work/err"
rc=$?
check "missing file: exit 1 (got $rc)" test $rc -eq 1
check "missing file: named" grep -q "missing.yaml" "$work/err"
check "missing file: no output" test ! -e "$work/out-missing"

"$bin" run "$scene" --set fpm.penalty=strong --out "$work/out-set" >/dev/null 2>"$work/err"
rc=$?
check "bad override: exit 1 (got $rc)" test $rc -eq 1
check "bad override: named" grep -q -- "fpm.penalty=strong" "$work/err"
check "bad override: no output" test ! -e "$work/out-set"

# Far above the stable step: stops with step, time, point and cause.
"$bin" run "$scene" --set time.dt=2e-3 --set time.max_steps=5000 \
  --out "$work/out-unstable" --quiet >/dev/null 2>"$work/err"
rc=$?
check "unstable: exit 2 (got $rc)" test $rc -eq 2
check "unstable: diagnosis" grep -Eq "step [0-9]+, t = .*point [0-9]+ at \(" "$work/err"
check "unstable: summary says so" grep -q '"status": "unstable"' "$work/out-unstable/summary.json"
check "unstable: results kept" test -f "$work/out-unstable/results.h5"
check "unstable: the step's advice (F2's supports at 0.15 of the shear wave speed)" \
  grep -q "reduce time.dt_safety or time.dt" "$work/err"

# Supports that outrun the body in a quasi-static run: F3 200% at 237
# points ramped over 0.05 s (the scene's smooth ramp moves the top face at
# 7.5 m/s, 7.5 times the shear wave speed sqrt(mu/rho) = 1.0 m/s) inverts a
# point during the ramp; the diagnosis puts it down to the ramp, with the
# ramp that moves them at 0.2 of it (1.87 s: 0.2 m at 1.875 / T of the
# quintic ramp), and plan says so before the run.
f3=(--set discretization.mesh_size=2e-2 --set discretization.refine.size_ratio=1
  --set time.ramp=0.05)
"$bin" run "$src/cases/fpm/f3-extension-200.yaml" "${f3[@]}" \
  --out "$work/out-ramp" --quiet >/dev/null 2>"$work/err"
rc=$?
check "fast ramp: exit 2 (got $rc)" test $rc -eq 2
check "fast ramp: diagnosis names the point and the ramp" grep -Eq \
  "point [0-9]+ at \(.*during the ramp \(it ends at t = 0.05 s\) the supports move at up to 7.5 m/s, 7.49 of the shear wave speed" \
  "$work/err"
check "fast ramp: the ramp that holds" grep -q "about 1.87 s moves them at 0.20" "$work/err"
check "fast ramp: summary's speeds" grep -Eq '"support_speed": 7.49' \
  "$work/out-ramp/summary.json"
"$bin" plan "$src/cases/fpm/f3-extension-200.yaml" "${f3[@]}" >"$work/plan-ramp" 2>&1
check "fast ramp: plan says so" grep -q \
  "above 0.25: the body may lag behind them (inertia, and the damping's drag on what moves), stretched near them; a" \
  "$work/plan-ramp"
check "fast ramp: plan's ramp that holds" grep -q "time.ramp of about 1.87 s moves them at 0.20" \
  "$work/plan-ramp"
"$bin" plan "$src/cases/fpm/f3-extension-200.yaml" "${f3[@]}" --set time.ramp=2 \
  >"$work/plan-ramp2" 2>&1
check "slow ramp: plan's speed without the warning" grep -q \
  "supports move at up to 0.187 m/s until t = 2 s, 0.19 of" "$work/plan-ramp2"
check "slow ramp: no warning" bash -c "! grep -q 'above 0.25' $work/plan-ramp2"
# A support given by an expression of t, sampled: z = 0.06 t under the
# 1 s smooth ramp moves at most d/dt (0.06 t r(t)) = 0.1067 m/s.
"$bin" plan "$src/cases/fpm/f3-extension-60.yaml" --set discretization.mesh_size=2e-2 \
  --set 'boundary.1.displacement.z=0.06*t' >"$work/plan-expr" 2>&1
check "expression of t: plan's speed" grep -q "supports move at up to 0.107 m/s" \
  "$work/plan-expr"

# Tension past the material's cavitation load.  A cube dilated on all six
# faces by u = e X holds the uniform hydrostatic tension K (J - 1), J = (1 +
# e)^3, at every point (FPM's gradient is exact on a linear field; the
# neo-Hookean's isochoric stress vanishes): with K = 1e5 Pa and e = 0.0093,
# 2816.03 Pa, 1.20609 times the gel's cavitation load 2334.848 Pa
# (tools/cavitation-load.py); the run says so, and at e = 0.006 (1810.8 Pa,
# 0.77556) it does not.
dilate() { # e, out-name
  local e=$1
  cat >"$work/dilate.yaml" <<YAML
name: dilate
method: fpm
dimension: 3
domain: {box: {min: [0, 0, 0], max: [0.1, 0.1, 0.1]}}
discretization: {mesh_size: 2e-2}
materials:
  - {name: gel, model: neo-hookean, density: 1000, youngs_modulus: 3000, poisson_ratio: 0.495}
bodies: [{material: gel, region: domain}]
boundary:
YAML
  for f in xmin xmax ymin ymax zmin zmax; do
    echo "  - {on: $f, displacement: {x: $e*x, y: $e*y, z: $e*z}}" >>"$work/dilate.yaml"
  done
  echo "time: {end: 1, quasi_static: {method: static}}" >>"$work/dilate.yaml"
  "$bin" run "$work/dilate.yaml" --out "$work/$2" >/dev/null 2>"$work/err"
  rc=$?
}
near() { # value, expected, relative tolerance
  awk -v v="$1" -v x="$2" -v r="$3" 'BEGIN { d = v - x; if (d < 0) d = -d;
    exit !(v != "" && d <= r * (x < 0 ? -x : x)) }'
}
json_of() { # summary.json, key
  grep -o "\"$2\": [-0-9.e+]*" "$1" | head -1 | awk '{ print $2 }'
}
dilate 0.0093 out-dilate
sj=$work/out-dilate/summary.json
check "cavitation: dilated cube converged (got $rc)" test $rc -eq 0
check "cavitation: tension K (J - 1) = 2816.03 Pa to 1e-6 (got $(json_of "$sj" \
  max_hydrostatic_tension))" near "$(json_of "$sj" max_hydrostatic_tension)" \
  2816.02744 1e-6
check "cavitation: the gel's load 2334.848 Pa to 1e-6" \
  near "$(json_of "$sj" cavitation_load)" 2334.84802 1e-6
check "cavitation: ratio 1.20609 to 1e-6 (got $(json_of "$sj" cavitation_ratio))" \
  near "$(json_of "$sj" cavitation_ratio)" 1.206086 1e-6
check "cavitation: the note" grep -q \
  "note: the hydrostatic tension reaches 2816 Pa at (.*), 1.21 times its material's cavitation load under hydrostatic tension (2335 Pa)" \
  "$work/err"
dilate 0.006 out-dilate-low
check "cavitation: below the load, ratio 0.77556 (got $(json_of \
  "$work/out-dilate-low/summary.json" cavitation_ratio))" near \
  "$(json_of "$work/out-dilate-low/summary.json" cavitation_ratio)" 0.775563 1e-6
check "cavitation: below the load, no note" bash -c "! grep -q 'cavitation load' $work/err"

# The stability bounds: J falling to stability.min_jacobian, and energy
# created by the non-symmetric flux in undamped dynamics, each stop the run
# with the step, time and cause.
coarse_run() { # out-name, --set ...: a coarse F2 run; sets rc
  local name=$1
  shift
  "$bin" run "$scene" --set discretization.mesh_size=0.02 "$@" \
    --out "$work/$name" --quiet >/dev/null 2>"$work/err"
  rc=$?
}
undamped=(--set time.quasi_static.method=none --set time.end=2)
coarse_run out-jmin --set stability.min_jacobian=0.999
check "min J bound: exit 2 (got $rc)" test $rc -eq 2
check "min J bound: diagnosis" grep -Eq \
  "step [0-9]+, t = .*point [0-9]+ at \(.*J <= stability.min_jacobian = 0.999" \
  "$work/err"
coarse_run out-energy "${undamped[@]}" --set fpm.flux=iipg
check "energy bound: exit 2 (got $rc)" test $rc -eq 2
check "energy bound: diagnosis" grep -Eq \
  "step [0-9]+, t = .*energy balance error .* exceeds stability.max_energy_error" \
  "$work/err"
# The same undamped run with the symmetric flux keeps its energy.
coarse_run out-sipg "${undamped[@]}" --set fpm.flux=sipg \
  --set fpm.penalty=100 --set stability.max_energy_error=0.01
check "symmetric flux, undamped: exit 0, energy within 1% (got $rc)" \
  test $rc -eq 0
"$bin" run "$scene" --set stability.min_jacobian=1.5 --out "$work/out-bad-j" \
  --quiet >/dev/null 2>"$work/err"
rc=$?
check "bad stability.min_jacobian: exit 1 (got $rc)" test $rc -eq 1
check "bad stability.min_jacobian: names the key" \
  grep -q "stability.min_jacobian.*\[0, 1)" "$work/err"
refused "unequal ladders" "same number" "$work/out-bad-ladder" \
  "$bin" convergence "$scene" --set-ladder discretization.mesh_size=0.02,0.015 \
  --set-ladder fpm.penalty=20 --out "$work/out-bad-ladder"

"$bin" plan "$scene" >"$work/plan" 2>"$work/err"
rc=$?
check "plan: exit 0 (got $rc)" test $rc -eq 0
check "plan: reports points, dt, steps, memory, estimate" \
  grep -q "estimate" "$work/plan"
for w in points pipeline dt steps memory; do
  check "plan: $w" grep -q "^$w" "$work/plan"
done

"$bin" --version >"$work/v" && check "version" grep -q "pointmech" "$work/v"
"$bin" --help >"$work/h" && check "help" grep -q "usage" "$work/h"

# A coarse F2 run, its outputs, and the probe at a few reference points.
out=$work/out-f2
"$bin" run "$scene" --set discretization.mesh_size=0.02 \
  --set time.quasi_static.tolerance=1e-8 --out "$out" --quiet 2>"$work/err"
rc=$?
check "coarse F2: exit 0 (got $rc)" test $rc -eq 0
outputs_complete "coarse F2" "$out"
check "coarse F2: converged" grep -q '"status": "converged"' "$out/summary.json"
printf 'x,y,z\n0.05,0.05,0.05\n0.02,0.07,0.09\n0.08,0.01,0.03\n' >"$work/pts.csv"
"$bin" probe "$out" --points "$work/pts.csv" >"$work/probe" 2>"$work/err"
rc=$?
check "probe: exit 0 (got $rc)" test $rc -eq 0
# u_z = -0.4 z exactly (linear field: MLS reproduces it)
check "probe: u_z = -0.4 z at every point" awk -F, '
  NR > 1 { n++; if ((($6 + 0.4 * $3) ^ 2) ^ 0.5 > 1e-6) bad++ }
  END { exit !(n == 3 && bad == 0) }' "$work/probe"
# probe --at points: every point's own values, no fit (u_z = -0.4 z holds
# at each point of the exact state); one point asked for by its
# coordinates (printed to 10 digits: found within 1e-9 m); a coordinate at
# no point refused with its file and line.
"$bin" probe "$out" --at points >"$work/own" 2>"$work/err"
rc=$?
check "probe --at points: exit 0 (got $rc)" test $rc -eq 0
check "probe --at points: header" grep -q '^point,x,y,z,displacement_x,displacement_y,displacement_z' "$work/own"
npts=$(grep -o '"points": [0-9]*' "$out/summary.json" | grep -o '[0-9]*$')
check "probe --at points: a row per point ($npts), u_z = -0.4 z" awk -F, -v n="$npts" '
  NR > 1 { k++; if ((($7 + 0.4 * $4) ^ 2) ^ 0.5 > 1e-6) bad++ }
  END { exit !(k == n && n > 0 && bad == 0) }' "$work/own"
awk -F, 'NR == 1 { print "x,y,z" } NR == 12 { print $2 "," $3 "," $4 }' "$work/own" >"$work/one.csv"
"$bin" probe "$out" --at points --points "$work/one.csv" >"$work/one" 2>"$work/err"
check "probe --at points --points: the point itself, at distance 0" awk -F, '
  NR == 1 { next } { n++; if ($4 > 1e-9 || $5 != 10) bad++ }
  END { exit !(n == 1 && bad == 0) }' "$work/one"
printf 'x,y,z\n0.05,0.05,0.05\n5,5,5\n' >"$work/far.csv"
"$bin" probe "$out" --at points --points "$work/far.csv" >"$work/far" 2>"$work/err"
rc=$?
check "probe --at points far away: exit 1 (got $rc)" test $rc -eq 1
check "probe --at points far away: names $work/far.csv:3" grep -q "far.csv:3: no point" "$work/err"
check "probe --at points far away: no partial table" test ! -s "$work/far"

# Convergence against the finite-element referee the scene names
# (reference.fe): the displacement at the FE lattice, the reaction and the
# mean strain energy density; F2's referee is the exact state.
small() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && (a < 0 ? -a : a) <= b) }'; }
out=$work/out-fe
"$bin" convergence "$scene" --set-ladder discretization.mesh_size=0.025,0.02 \
  --set time.quasi_static.tolerance=1e-8 --out "$out" --quiet \
  >"$work/conv" 2>"$work/err"
rc=$?
check "convergence, FE referee by default: exit 0 (got $rc)" test $rc -eq 0
check "convergence, FE referee: named under the table" \
  grep -q "finite-element lattice of .*f2-unconstrained-compression" \
  "$out/convergence.md"
for lv in 1 2; do
  e=$(col "$out/convergence.csv" $lv error)
  re=$(col "$out/convergence.csv" $lv reaction_error)
  se=$(col "$out/convergence.csv" $lv sed_error)
  check "convergence, FE referee: level $lv NRMSE $e <= 1e-5" small "$e" 1e-5
  check "convergence, FE referee: level $lv reaction error $re <= 1e-4" \
    small "$re" 1e-4
  check "convergence, FE referee: level $lv SED error $se <= 1e-4" \
    small "$se" 1e-4
done
# The same by static solves: PETSc (and MPI, which may start a helper
# process) starts before the outputs open, so no helper inherits the lock
# of a level's results.h5 and the comparison can read it.
out=$work/out-fe-static
"$bin" convergence "$scene" --set-ladder discretization.mesh_size=0.025,0.02 \
  --set time.quasi_static.method=static --out "$out" --quiet \
  >"$work/conv" 2>"$work/err"
rc=$?
check "convergence by static solves: exit 0 (got $rc)" test $rc -eq 0
for lv in 1 2; do
  e=$(col "$out/convergence.csv" $lv error)
  check "convergence by static solves: level $lv NRMSE $e <= 1e-5" \
    small "$e" 1e-5
done
refused "convergence, missing FE referee" "no-such-fe/ladder.csv" \
  "$work/out-fe-bad" "$bin" convergence "$scene" \
  --set-ladder discretization.mesh_size=0.025 \
  --reference fe:"$work/no-such-fe" --out "$work/out-fe-bad" --quiet

# SIGTERM during a run: the step ends, a last frame is written, the four
# files are complete with status "interrupted", and the exit status is 4.
# (A tolerance no run meets and a far end keep it running until then.)
out=$work/out-term
"$bin" run "$scene" --set discretization.mesh_size=0.02 \
  --set time.quasi_static.tolerance=1e-300 --set time.end=1e6 \
  --out "$out" --quiet 2>"$work/err" &
pid=$!
# Once the history holds the rows of steps 0 and 2000, the run is in its
# time loop.  (The wait was for a history.csv.tmp that exists only while
# a row is written: it ran out its 60 s instead.)
wait_rows $pid "$out" 3
kill -TERM $pid
wait $pid
rc=$?
check "SIGTERM: exit 4 (got $rc)" test $rc -eq 4
outputs_complete SIGTERM "$out"
check "SIGTERM: status interrupted" \
  grep -q '"status": "interrupted"' "$out/summary.json"
check "SIGTERM: the message names the signal and step" \
  grep -q 'interrupted by SIGTERM after step [0-9]*, t = ' "$work/err"
last=$(tail -1 "$out/history.csv" | cut -d, -f2)
check "SIGTERM: the last history row ($last) is the step named" \
  grep -q "after step $last," "$work/err"
rows=$(($(wc -l <"$out/history.csv") - 1))
frames=$(grep -c '<Time ' "$out/results.xdmf")
check "SIGTERM: results.xdmf indexes a frame per history row, the last step's too ($frames, $rows)" \
  test "$frames" -eq "$rows"

echo "$passes passed, $failures failed"
[ $failures -eq 0 ]
