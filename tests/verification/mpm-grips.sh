#!/usr/bin/env bash
# MPM conditions on regions of particles (grips) and tractions on faces,
# against the analytic 1-D bar (linear elastic, nu = 0, plane), at two
# cells: a grip's reaction and an end traction's displacement (explicit
# MPM; the traction by the implicit MPM too), and bad input refused with
# file:line:col.  The grips hold the particle layers
# themselves, so the bar between the held layers is the analytic gauge;
# the grid adds about half a cell of compliance at each grip (first order
# in h: -5.4% at h = 0.02 m, -2.7% at 0.01 m on this bar).
set -u
bin=$1
src=$2
scenes=$src/tests/data/scenes
grip=$scenes/mpm-grip-bar.yaml
trac=$scenes/mpm-traction-bar.yaml
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"

# |a / b - 1| <= tol
within() { awk -v a="$1" -v b="$2" -v t="$3" \
  'BEGIN { e = a / b - 1; if (e < 0) e = -e; exit !(e <= t) }'; }
# |a / ref - 1| <= f |b / ref - 1|: the error shrinks by f or more
shrinks() { awk -v a="$1" -v b="$2" -v r="$3" -v f="$4" \
  'BEGIN { ea = a / r - 1; eb = b / r - 1; if (ea < 0) ea = -ea;
           if (eb < 0) eb = -eb; exit !(ea <= f * eb) }'; }
# Last value of column NAME in a history.csv.
last() { awk -F, -v name="$2" \
  'NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i; next }
   { v = $c } END { print v }' "$1"; }
# Mean y displacement of the particles whose reference y is above Y, in
# the last frame of run OUT.
top_u() { /usr/bin/python3 - "$1" "$2" <<'PY'
import glob, sys
import h5py
f = h5py.File(sorted(glob.glob(sys.argv[1] + "/results/frame_*.h5"))[-1], "r")
x, u = f["position"][:], f["displacement"][:]
top = (x - u)[:, 1] > float(sys.argv[2])
print(u[top, 1].mean())
PY
}

# The grip: E A u / gauge, gauge the distance between the held layers.
"$bin" run "$grip" --out "$work/g2" --quiet 2>"$work/err"
check "grip bar h 0.02: completes" test $? -eq 0
r2=$(last "$work/g2/history.csv" reaction_boundary.1_y)
ref2=$(awk 'BEGIN { print 1e4 * 0.04 * 4e-4 / 0.39 }')
check "grip bar h 0.02: reaction $r2 within 6% of $ref2" within "$r2" "$ref2" 0.06
check "grip bar h 0.02: the grips' reactions balance" \
  within "$(last "$work/g2/history.csv" reaction_boundary.0_y)" "-$r2" 1e-3
"$bin" run "$grip" --out "$work/g1" --quiet \
  --set discretization.mesh_size=0.01 --set 'boundary.0.region=0.005 - y' \
  --set 'boundary.1.region=y - 0.395' 2>"$work/err"
check "grip bar h 0.01: completes" test $? -eq 0
r1=$(last "$work/g1/history.csv" reaction_boundary.1_y)
ref1=$(awk 'BEGIN { print 1e4 * 0.04 * 4e-4 / 0.395 }')
check "grip bar h 0.01: reaction $r1 within 3% of $ref1" within "$r1" "$ref1" 0.03
check "grip bar: first order (error at h 0.01 <= 0.6 x at 0.02)" \
  shrinks "$(awk -v r="$r1" -v f="$ref1" 'BEGIN { print r / f }')" \
  "$(awk -v r="$r2" -v f="$ref2" 'BEGIN { print r / f }')" 1 0.6

# Glued plates on the bar's end faces: they hold the grid nodes at and
# past the faces, so the gauge is the whole bar, E A u / 0.4 = 0.4 N
# (-0.05% measured at h 0.02, where the grips above are -5.4%).
glued=$scenes/mpm-glued-bar.yaml
"$bin" run "$glued" --out "$work/gl" --quiet 2>"$work/err"
check "glued bar h 0.02: completes" test $? -eq 0
rg=$(last "$work/gl/history.csv" reaction_top_y)
check "glued bar h 0.02: reaction $rg within 0.5% of 0.4" within "$rg" 0.4 0.005
check "glued bar h 0.02: the plates' reactions balance" \
  within "$(last "$work/gl/history.csv" reaction_bottom_y)" "-$rg" 1e-3

# The traction: u = (t / E) (y - y_held) at the top layer.
"$bin" run "$trac" --out "$work/t2" --quiet 2>"$work/err"
check "traction bar h 0.02: completes" test $? -eq 0
u2=$(top_u "$work/t2" 0.39)
check "traction bar h 0.02: u $u2 within 4% of 3.9e-4" within "$u2" 3.9e-4 0.04
"$bin" run "$trac" --out "$work/t1" --quiet \
  --set discretization.mesh_size=0.01 \
  --set 'boundary.0.region=0.005 - y' 2>"$work/err"
check "traction bar h 0.01: completes" test $? -eq 0
u1=$(top_u "$work/t1" 0.39) # layers at 0.3925 and 0.3975: mean 0.395
check "traction bar h 0.01: u $u1 within 2% of 3.925e-4" within "$u1" 3.925e-4 0.02

# The traction by the implicit MPM (a face holds the bottom, y = 0; linear
# B-splines hold the linear field exactly): u = (t / E) y at the top layer.
sed 's/method: mpm$/method: mpm-implicit/
     s/region: "0.01 - y", displacement: {y: 0}/on: ymin, displacement: {y: 0}/
     s/min: \[-0.02, -0.02\]/min: [-0.02, 0]/
     s/quasi_static: {.*}/quasi_static: {method: static, load_steps: 4}/' \
  "$trac" >"$work/implicit.yaml"
"$bin" run "$work/implicit.yaml" --out "$work/ti" --quiet 2>"$work/err"
check "implicit traction bar: completes" test $? -eq 0
ui=$(top_u "$work/ti" 0.39)
check "implicit traction bar: u $ui within 1e-6 of 3.95e-4" within "$ui" 3.95e-4 1e-6

# Bad input.
bad_scene grip-grips-nothing "$grip" 's/region: "y - 0.39"/region: "y - 0.5"/' \
  'y - 0.5' 'boundary.1.region: expected a region that holds particles'
bad_scene grip-on-absorbing "$grip" \
  's/region: "y - 0.39", displacement: {y: 4.0e-4}/region: "y - 0.39", absorbing: true/' \
  'absorbing: true' 'expected displacement or velocity on a region'
bad_scene traction-on-region "$trac" \
  's/on: ymax, traction/region: "y - 0.39", traction/' 'region: "y - 0.39"' \
  'boundary.1.traction: expected a traction on a face of domain.box or a named surface (method mpm;'
bad_scene traction-on-region-implicit "$trac" \
  's/method: mpm$/method: mpm-implicit/; s/on: ymax, traction/region: "y - 0.39", traction/' \
  'region: "y - 0.39"' \
  'boundary.1.traction: expected a traction on a face of domain.box or a named surface (method mpm-implicit;'
bad_scene grip-implicit "$grip" 's/method: mpm$/method: mpm-implicit/' \
  'region: "0.01 - y"' \
  'boundary.0.region: expected on: a face of domain.box or a named surface (displacement or traction) for method mpm-implicit'

bad_scene glued-grips-nothing "$glued" 's/point: \[0, 0.4\]/point: [0, 0.45]/' \
  'point: \[0, 0.45\]' 'boundary.1.plate: expected a glued plate on a body'
bad_scene glued-implicit "$glued" 's/method: mpm$/method: mpm-implicit/' \
  'plate: {point: \[0, 0\]' 'boundary.0.plate: contact needs method mpm or fpm'

echo "mpm-grips: $passes passed, $failures failed"
[ "$failures" -eq 0 ]
