#!/usr/bin/env bash
# Rigid plates in the explicit MPM's grid contact: F2 under a frictionless
# plate (cases/mpm/f2-plates.yaml) at a 0.02 m cell (1000 particles)
# against the exact homogeneous solution, the plate's reaction (-21.792 N,
# P_zz of uniaxial stress at stretch 0.6 times 0.01 m^2) and the energy
# balance; and bad input refused with file:line:col.
set -u
bin=$1
src=$2
scene=$src/cases/mpm/f2-plates.yaml
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"

# |a / b - 1| <= tol
within() { awk -v a="$1" -v b="$2" -v t="$3" \
  'BEGIN { e = a / b - 1; if (e < 0) e = -e; exit !(e <= t) }'; }
# a <= b (absolute values)
below() { awk -v a="$1" -v b="$2" \
  'BEGIN { if (a < 0) a = -a; exit !(a <= b) }'; }
last() { awk -F, -v name="$2" \
  'NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i; next }
   { v = $c } END { print v }' "$1"; }

"$bin" run "$scene" --set discretization.mesh_size=2e-2 --out "$work/f2" \
  --quiet 2>"$work/err"
check "F2 under a plate, cell 0.02: completes" test $? -eq 0
h=$work/f2/history.csv
grep -q '"status": *"converged"' "$work/f2/summary.json"
check "F2 under a plate: relaxation converged" test $? -eq 0
# Measured -21.876 N (+0.38%).
R=$(last "$h" reaction_top_z)
check "F2 under a plate: reaction $R within 1% of -21.792" within "$R" -21.792 0.01
# The rollers' sum balances the plate's (to the relaxation's tolerance).
check "F2 under a plate: zmin balances the plate" \
  within "$(last "$h" reaction_zmin_z)" "$(awk -v r="$R" 'BEGIN { print -r }')" 0.005
# Measured 1.5e-3 (the face condition's scene: 1.8e-3).
e=$(last "$h" nrmse_u_z)
check "F2 under a plate: NRMSE u_z $e <= 3e-3" below "$e" 3e-3
# Measured -1.35e-2.
b=$(last "$h" energy_error)
check "F2 under a plate: energy balance $b within 2e-2" below "$b" 2e-2

# Bad input.
bad_scene plate-inside "$scene" 's/point: \[0, 0, 0.1\]/point: [0, 0, 0.09]/' \
  'plate: {point' 'boundary.3.plate: expected a rigid body outside the bodies at t = 0, got particle'
bad_scene plate-penalty "$scene" 's/contact: frictionless/contact: frictionless\n    penalty: 100/' \
  'penalty: 100' 'boundary.3.penalty: expected no penalty for method mpm'
bad_scene plate-implicit "$scene" \
  's/method: mpm$/method: mpm-implicit/; s/quasi_static: {.*}/quasi_static: {method: static, load_steps: 4}/' \
  'plate: {point' 'contact needs method mpm or fpm for now'

echo "mpm-contact: $passes passed, $failures failed"
[ "$failures" -eq 0 ]
