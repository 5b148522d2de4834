#!/usr/bin/env bash
# MPM membranes end to end through the program: bad membrane scenes are
# refused with file:line:col and nothing written; plan shows the membrane's
# stage and arrays, and a scene without membranes has none of them; the
# reduced oocyte (case M4) runs to its end with no NaN, its energy
# accounted for, and its zona failing only near the injection pipette.
set -u
bin=$1
src=$2
mpm=$src/cases/mpm
oocyte=$mpm/m4-oocyte-reduced.yaml
tube=$mpm/m2-shock-tube-reduced.yaml
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2}
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"
py=/usr/bin/python3

bad_scene membrane-without-thickness "$oocyte" \
  's/membrane: {thickness: 8.0e-6, /membrane: {/' 'membrane: {sphere' \
  'bodies.0.membrane.thickness: missing required key'
bad_scene inside-open-surface "$oocyte" \
  's/sphere: {center: \[70.0e-6, 65.0e-6, 65.0e-6\], radius: 50.0e-6, refinement: 4}/rectangle: {origin: [20.0e-6, 20.0e-6, 65.0e-6], edge_u: [100.0e-6, 0, 0], edge_v: [0, 90.0e-6, 0], points: [11, 11]}/' \
  'outside: zona' 'bodies.1.outside: expected the name of a closed membrane'
# An open surface from a file: one square of two triangles.
cat >"$work/open.stl" <<'STL'
solid open
facet normal 0 0 1
outer loop
vertex 20e-6 20e-6 65e-6
vertex 120e-6 20e-6 65e-6
vertex 120e-6 110e-6 65e-6
endloop
endfacet
facet normal 0 0 1
outer loop
vertex 20e-6 20e-6 65e-6
vertex 120e-6 110e-6 65e-6
vertex 20e-6 110e-6 65e-6
endloop
endfacet
endsolid open
STL
bad_scene inside-open-file "$oocyte" \
  "s|sphere: {center: \[70.0e-6, 65.0e-6, 65.0e-6\], radius: 50.0e-6, refinement: 4}|file: $work/open.stl|" \
  'outside: zona' 'expected the name of a closed membrane'
check "inside-open-file: gives the reason" grep -qF 'hole' "$work/err"
bad_scene motion-does-not-parse "$oocyte" 's/cos(2 \* pi/cos(2 ** pi/' \
  'motion: {velocity: {y:' 'bodies.4.motion.velocity.y'
bad_scene motion-in-x-y-z "$oocyte" 's/cos(2 \* pi \* t/cos(2 * pi * x/' \
  'motion: {velocity: {y:' 'bodies.4.motion.velocity.y'
bad_scene membrane-neo-hookean "$oocyte" '0,/model: linear-elastic/s//model: neo-hookean/' \
  'model: neo-hookean' 'expected linear-elastic for material zona'
bad_scene damage-on-a-solid "$oocyte" \
  's/{name: holding, model: linear-elastic, density: 2300,/{name: holding, model: linear-elastic, density: 2300, damage: {c0: 1, c1: 1, elastic_limit: 0.1, failure_strain: 0.2},/' \
  'name: holding' 'expected damage only on a material of membranes'

# Membranes in 2D and as point clouds (cases M5).
circle=$mpm/m5-gas-circle.yaml
awk 'BEGIN { pi = atan2(0, -1); print "x,y,length";
  for (k = 0; k <= 90; k++) { a = pi / 2 * k / 90;
    printf "%.15g,%.15g,%.15g\n", 0.5 * cos(a), 0.5 * sin(a), (k == 0 || k == 90 ? 0.5 : 1) * pi / 4 / 90 } }' \
  >"$work/ring.csv"
cloud_expr="s|curve: {x: \"0.5\*cos(pi/2\*t)\", y: \"0.5\*sin(pi/2\*t)\", from: 0, to: 1, points: 91}|points: $work/ring.csv|"
bad_scene cloud-with-connectivity "$circle" \
  "$cloud_expr; s|normals: hybrid|normals: connectivity|" 'normals: connectivity' \
  'got connectivity'
check "cloud-with-connectivity: says why" grep -qF 'a point cloud has no connectivity' "$work/err"
awk 'NR == 12 { $0 = "0.49,abc,0.0087" } { print }' "$work/ring.csv" >"$work/ring-bad.csv"
bad_scene cloud-bad-line "$circle" \
  "$cloud_expr; s|ring.csv|ring-bad.csv|" 'ring-bad.csv' "ring-bad.csv:12:6: expected a number"
bad_scene curve-in-3d "$oocyte" \
  's/sphere: {center: \[70.0e-6, 65.0e-6, 65.0e-6\], radius: 50.0e-6, refinement: 4}/curve: {x: "1e-5*t", y: "1e-5*t", points: 10}/' \
  'curve: {x:' 'got curve'
bad_scene normals-unknown "$circle" 's/normals: hybrid/normals: isosurface/' \
  'normals: isosurface' 'expected one of connectivity'
# plan: the normal method changes the normal stage only.
"$bin" plan "$circle" >"$work/plan-iso" 2>"$work/err"
check "plan 2D: exit 0" test $? -eq 0
check "plan 2D: hybrid normal stage" grep -qF 'normals: membrane    skin: bodies.0: isosurface least squares, hybrid' "$work/plan-iso"
"$bin" plan "$circle" --set bodies.0.membrane.normals=connectivity \
  >"$work/plan-con" 2>"$work/err"
diff <(grep -E '^ +[0-9]+\. ' "$work/plan-iso") <(grep -E '^ +[0-9]+\. ' "$work/plan-con") \
  >"$work/plan-diff"
check "plan 2D: one stage differs" test "$(grep -c '^<' "$work/plan-diff")" -eq 1
check "plan 2D: it is the normal stage" grep -qF '< ' "$work/plan-diff"
check "plan 2D: connectivity normals" grep -qF "perpendicular to the neighbours' chord" "$work/plan-con"
# A point cloud runs (its gas seeded in a disk).
sed -e "$cloud_expr" -e 's|inside: membrane|region: "0.25 - x*x - y*y"|' \
  "$circle" >"$work/cloud.yaml"
"$bin" run "$work/cloud.yaml" --set time.end=0.02 --out "$work/cloud" --quiet \
  >/dev/null 2>"$work/err"
check "point cloud 2D: exit 0" test $? -eq 0
check "point cloud 2D: completed" grep -qF '"status": "completed"' "$work/cloud/summary.json"
check "point cloud 2D: plan says unconnected" bash -c \
  "'$bin' plan '$work/cloud.yaml' | grep -qF 'membrane of unconnected points'"

# plan: the membrane's stage and arrays; none in a scene without one.
"$bin" plan "$oocyte" >"$work/plan" 2>"$work/err"
check "plan: exit 0" test $? -eq 0
check "plan: membrane stage" grep -qF 'stress: membrane' "$work/plan"
check "plan: frame and strain arrays" grep -qF 'frame membrane_strain omega failed' "$work/plan"
check "plan: moving bodies" grep -qF 'moving as prescribed' "$work/plan"
"$bin" plan "$tube" >"$work/plan-tube" 2>"$work/err"
# (the scene line names the scene's path, which may hold any word)
check "plan without membranes: no membrane stage" \
  bash -c "! grep -v '^scene ' '$work/plan-tube' | grep -qiE 'membrane|motion'"

# The reduced oocyte to its end.
out=$work/oocyte
"$bin" run "$oocyte" --out "$out" --quiet >"$work/log" 2>"$work/err"
rc=$?
check "reduced M4: exit 0 (got $rc)" test $rc -eq 0
check "reduced M4: completed" grep -qF '"status": "completed"' "$out/summary.json"
"$py" - "$out" >"$work/m4.txt" 2>&1 <<'PY'
import json, sys
import h5py, numpy as np
out = sys.argv[1]
s = json.load(open(out + "/summary.json"))
f = h5py.File(out + "/results.h5", "r")
frames = sorted(f["frames"].keys())
last = f["frames"][frames[-1]]
x0 = f["mesh/coordinates"][:]
failed = last["failed"][:] > 0.5
ok = True
for k in ("position", "velocity", "stress"):
    if not np.all(np.isfinite(last[k][:])):
        print("FAIL: %s not finite" % k); ok = False
# The energy balance (E - E0 + D - W) / E0: E0 is the fluids' internal
# energy, mostly the stiffened gas's P_inf term; the work the pipette does
# and the kinetic energy are printed beside the imbalance.
err = abs(s["energy_balance_error"])
imb = (s["kinetic_energy"] + s["strain_energy"] + s["internal_energy"]
       - s["initial_energy"] + s["dissipated"] - s["external_work"])
print("energy balance error %.3e of E0; imbalance %.3e J, work %.3e J, "
      "kinetic %.3e J, dissipated %.3e J" % (err, imb, s["external_work"],
      s["kinetic_energy"], s["dissipated"]))
# The zona points that failed, where they started: within 60 um (0.6 of
# the oocyte's diameter) of the injection pipette's contact, none within
# 40 um of the holding pipette's.
contact = np.array([120e-6, 65e-6, 65e-6])
holding = np.array([20e-6, 65e-6, 65e-6])
d = np.linalg.norm(x0[failed] - contact, axis=1)
dh = np.linalg.norm(x0[failed] - holding, axis=1)
print("failed points %d: from the contact %.3g to %.3g um, nearest the "
      "holding pipette %.3g um" % (failed.sum(), 1e6 * d.min() if d.size else 0,
      1e6 * d.max() if d.size else 0, 1e6 * dh.min() if dh.size else 0))
if not failed.any(): print("FAIL: no point failed"); ok = False
if d.size and d.max() > 60e-6: print("FAIL: failures away from the contact"); ok = False
if dh.size and dh.min() < 40e-6: print("FAIL: failures at the holding pipette"); ok = False
if not err < 1e-6: print("FAIL: energy balance"); ok = False
print("OK" if ok else "NOT OK")
PY
cat "$work/m4.txt" | sed 's/^/  /'
check "reduced M4: finite, energy, failures near the contact" grep -qx OK "$work/m4.txt"

echo "membranes: $passes passed, $failures failed"
[ "$failures" -eq 0 ]
