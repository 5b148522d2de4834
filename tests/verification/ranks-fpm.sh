#!/usr/bin/env bash
# Explicit FPM across MPI ranks against the same runs on one process.
# Usage: ranks-fpm.sh POINTMECH SOURCE_DIR RANKS_FPM_SETUP
#
# A rank's force on its own points is one process's, the same operations in
# the same order (its ghosts carry what the force reads), so the fields are
# one process's bit for bit for as long as the step's sums do not feed back
# into it: until dynamic relaxation's damping starts (F2 here: step 800 of
# 1000), and with the quadratic jump.  From then on, the damping
# coefficient 2 sqrt((s3 - s1) / s2) takes the sums, summed over the ranks
# in another order than one process's, into the steps: measured 1e-11 (the
# fields, every history column) after 200 steps of relaxation, as between
# one and two OpenMP threads of one process (2e-11).  The coefficient itself
# is a difference of two sums that nearly cancel when the relaxation starts:
# its round-off on one process, 1 against 2 threads, is 7e-10, and so is
# that of the energy it dissipates; those two history columns are held to
# 1e-8, every other column and every field to 1e-10 of its largest
# magnitude, the bound of the MPM runs across ranks (verification.ranks).
# Each rank has one OpenMP thread (ranks-lib.sh).
set -u
bin=$1
src=$2
setup=$3
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/ranks-lib.sh"
bounds="damping=1e-8 dissipated=1e-8"
fpm=$src/cases/fpm
f2=$fpm/f2-unconstrained-compression.yaml
f4=$fpm/f4-compression-60.yaml

# F2 (3-D, 459 points, rollers and a moving face, dynamic relaxation from
# step 800) on 2 and 3 ranks; 1000 steps, not yet quasi-static (exit 3).
f2set="--set discretization.mesh_size=0.015 --set time.max_steps=1000
  --set output.every=100"
want=3 across f2 "$f2" 2 $f2set
want=3 across f2 "$f2" 3 $f2set
check "f2 on 3 ranks: the partition in summary.json" $py -c "
import json, sys
s = json.load(open('$work/f2-3/summary.json'))
r = s['ranks']
print('f2 on 3 ranks: points per rank %s, ghost points %s, %d pairs cut, '
      '%.0f bytes of ghost displacements a rank receives per step'
      % (r['points'], r['ghost_points'], r['edge_cut'],
         r['ghost_bytes_per_step']))
sys.exit(not (r['count'] == 3 and sum(r['points']) == s['points'] and
              min(r['ghost_points']) > 0 and r['edge_cut'] > 0))"

# Frames in pieces (output.ranks: pieces) without checkpoints: no rank
# keeps the whole model.  Each rank writes its own points of a frame
# (points alone, the frame's geometry its field "position"), rank 0 joins
# them, and the history rows (reactions, energies, the relaxation's
# figures, the ill-conditioned points, the errors against F2's reference
# field) and the end's figures are sums and extremes over the shares.  On
# 2 and 3 ranks: the frames, read in one-process order, the gathered run's
# bit for bit; history and summary one process's to round-off.
ln -s "$work/f2-1" "$work/f2-pieces-1" # (the same one-process run)
for n in 2 3; do
  want=3 across f2-pieces "$f2" $n $f2set --set output.ranks=pieces
  check "f2 in pieces on $n ranks: frames as gathered, bit for bit" \
    $same --frames "$work/f2-$n" "$work/f2-pieces-$n"
done
check "f2 in pieces on 3 ranks: the mesh, positions and summary" $py -c "
import h5py, json, sys
import numpy as np
sys.path.insert(0, '$src/python')
import pointmech
a, b = sys.argv[1:3]
fa, fb = h5py.File(a + '/results.h5', 'r'), h5py.File(b + '/results.h5', 'r')
x = fb['mesh/coordinates'][()]
assert np.array_equal(fa['mesh/coordinates'][()], x), 'mesh'
assert fb['mesh/cells'].attrs['nodes_per_cell'] == 1, 'a point cloud'
assert len(fb['frames']) == len(fa['frames']) == 11, 'frames'
for k in fb['frames']:
    g = fb['frames'][k]
    assert np.array_equal(pointmech.read_rows(g, 'position'),
                          x + pointmech.read_rows(g, 'displacement')), k
sa = json.load(open(a + '/summary.json'))
sb = json.load(open(b + '/summary.json'))
for k in ('points', 'steps', 'cells', 'interfaces', 'boundary_facets',
          'prescribed_dofs', 'ill_conditioned_points', 'dt_critical_point',
          'max_von_mises_at', 'end_min_jacobian_at'):
    assert sa[k] == sb[k], (k, sa[k], sb[k])
for k in ('kinetic_energy', 'strain_energy', 'external_work',
          'mean_strain_energy_density', 'max_von_mises', 'end_min_jacobian',
          'min_jacobian', 'nrmse_displacement', 'max_support_condition'):
    assert abs(sa[k] - sb[k]) <= 1e-10 * abs(sa[k]), (k, sa[k], sb[k])
g = json.load(open(a.replace('f2-1', 'f2-3') + '/summary.json'))
assert sb['ranks']['edge_cut'] == g['ranks']['edge_cut'], 'edge cut'
" "$work/f2-1" "$work/f2-pieces-3"
# In pieces without checkpoints a signal stops the run with its frames and
# says that it wrote no checkpoint; a static solve writes its frames
# gathered (refused in pieces, naming the key).
interrupt 2 "$work/pnone" "$f2" $f2set --set output.ranks=pieces
check "in pieces, no checkpoints, interrupted: no checkpoint, said" \
  grep -q 'no checkpoint: a run across ranks with frames in pieces' \
  "$work/pnone/summary.json"
refused "a static solve in pieces on 2 ranks" \
  "a static solve (time.quasi_static.method: static) across ranks writes" \
  "$work/static-pieces" ranks 2 "$bin" run "$f2" --set output.ranks=pieces \
  --set time.quasi_static.method=static --out "$work/static-pieces"

# Rank 0 alone meshes and builds the cells; where it keeps no whole model
# (as when every rank writes its frames) it lets them go once the parts
# are sent, and every share is still the one cut from the whole model, bit
# for bit (ranks_fpm_setup): F2 (linear jump), F4 60% (the quadratic jump,
# the averaged volume, stiffening) and the ring (2-D, follower pressure).
for args in "2 $f2 discretization.mesh_size=0.015" \
  "3 $f4 discretization.mesh_size=8.72e-3 fpm.volumetric=averaged" \
  "3 $fpm/ring/ring-pressure.yaml"; do
  set -- $args
  n=$1
  shift
  ranks "$n" "$setup" "$@" >"$work/setup" 2>&1
  rc=$?
  grep -E '^(ok|FAIL|rank)' "$work/setup" | sed "s/^/$(basename "$1"): /"
  check "setup on $n ranks without the whole model, $(basename "$1")" \
    test $rc -eq 0
done

# One rank under mpirun is one process.
ranks 1 "$bin" run "$f2" --out "$work/f2-np1" --quiet $f2set >/dev/null \
  2>"$work/err"
rc=$?
check "f2 on 1 rank: exit 3 (got $rc)" test $rc -eq 3
check "f2 on 1 rank: one process, bit for bit" \
  $same "$work/f2-1" "$work/f2-np1"

# Explicit FPM across ranks: Scotch partitions, the exchanges are MPI
# alone, and no rank opens PETSc (the loader's record of each rank's).
LD_DEBUG=files ranks 2 "$bin" run "$f2" --out "$work/f2-libs" --quiet \
  --set discretization.mesh_size=0.015 --set time.max_steps=5 >/dev/null \
  2>"$work/libs"
check "f2 on 2 ranks: Scotch opened" grep -q 'file=libscotch' "$work/libs"
check "f2 on 2 ranks: no rank opens PETSc" \
  sh -c "! grep -q 'file=libpetsc' '$work/libs'"

# The quadratic jump (F4 at 60%, coarsest h; its ghosts reach over the fits'
# two rings), 200 steps.
want=3 across f4-quadratic "$f4" 2 --set discretization.mesh_size=8.72e-3 \
  --set time.max_steps=200 --set output.every=50

# The averaged volume (fpm.volumetric: averaged): the ghosts' U'(Jbar)
# come from their owners inside the force, so its runs are one process's
# as the others: F2 (linear jump) to the same bounds through the
# relaxation, F4 60% (quadratic jump, 100 steps) bit for bit.
avg="--set fpm.volumetric=averaged"
want=3 across f2-averaged "$f2" 2 $f2set $avg
want=3 across f4-averaged "$f4" 2 --set discretization.mesh_size=8.72e-3 \
  --set time.max_steps=100 --set output.every=50 $avg
check "f4 averaged on 2 ranks: one process's, bit for bit" \
  $same "$work/f4-averaged-1" "$work/f4-averaged-2"

# plan on 2 ranks prints every rank's share; plan --ranks 2 on one
# process predicts the same.
ranks 2 "$bin" plan "$f2" >"$work/plan-2" 2>"$work/err"
check "plan on 2 ranks: exit 0" test $? -eq 0
"$bin" plan "$f2" --ranks 2 >"$work/plan-p" 2>"$work/err"
check "plan --ranks 2: exit 0" test $? -eq 0
sed -n '/^ranks /,/ghost points per rank/p' "$work/plan-2" >"$work/share-2"
sed -n '/^ranks /,/ghost points per rank/p' "$work/plan-p" >"$work/share-p"
check "plan on 2 ranks: a line per rank" \
  test "$(grep -cE '^ +[01] +[0-9]+ +[0-9]+ \(' "$work/share-2")" -eq 2
check "plan --ranks 2 predicts the shares of 2 ranks" \
  cmp -s "$work/share-2" "$work/share-p"

# A point turned inside out stops every rank with one process's message
# (the point by its index on one process).
fails_alike inverted 3 'step [0-9]*, .*(J = [^)]*)' "$f2" \
  --set time.dt=1e-3 --set output.every=5
# The same with the averaged volume, whose force is collective (the
# ghosts' U'(Jbar)): a rank whose own point inverted, or whose condition
# is not finite, still takes part in the other ranks' exchange.
fails_alike inverted-averaged 2 'step [0-9]*, .*(J = [^)]*)' "$f2" \
  --set time.dt=1e-3 --set output.every=5 $avg
fails_alike not-finite-averaged 2 'step [0-9]*, .* = nan' "$f2" $avg \
  --set discretization.mesh_size=0.015 --set output.every=5 \
  --set 'boundary.3.displacement.z=-0.04*sqrt(0.005 - 20*t*x)'

# The static solver (Newton on the shared layer) with every linear solve
# to 1e-10 (time.quasi_static.inexact false): F2 on 2 and 3 ranks by LU
# (the Newton iterates are one process's; measured 2e-12, the fields),
# with SIPG's exact tangent applied matrix-free on 2, and with the
# quadratic jump on 2 (1.6e-12).  The residual at convergence is a norm of
# round-off below Newton's tolerance: compared to no bound.  These hold
# the ranks' residual and tangent to round-off; the default, inexact
# Newton, is compared below to the bound its tolerances give.
static="--set time.quasi_static.method=static
  --set time.quasi_static.inexact=false"
coarse="--set discretization.mesh_size=0.015"
bounds="residual=inf" across f2-static "$f2" 2 $static $coarse
bounds="residual=inf" across f2-static "$f2" 3 $static $coarse
bounds="residual=inf" across f2-sipg "$f2" 2 $static $coarse \
  --set fpm.flux=sipg
bounds="residual=inf" across f2-quadratic "$f2" 2 $static $coarse \
  --set fpm.jump=quadratic --set fpm.penalty=1
# The averaged volume by Newton: its exact tangent applied matrix-free
# (the averages' coupling exchanged as in the force), GMRES preconditioned
# by LU of the tangent without the coupling.
bounds="residual=inf" across f2-static-averaged "$f2" 2 $static $coarse $avg
# The default, inexact Newton (Eisenstat-Walker): each linear solve stops
# at its forcing term (at most 1e-2), so a run ends wherever Newton's
# criterion |r| <= rtol |r0| is first met, and one process (which
# factorises the averages' coupling) and 2 ranks (which cannot) reach it
# by other iterates.  Both states meet the criterion, which fixes them to
# the tangent's condition number times rtol, not to round-off: held to
# 1e3 rtol (rtol = 1e-9, the scene's tolerance); measured 3.0e-8 (the
# fields) and 9.3e-8 (energy_error).
rtol=1e-9
tol=$($py -c "print(1e3 * $rtol)") bounds="residual=inf" across \
  f2-static-inexact "$f2" 2 --set time.quasi_static.method=static $coarse \
  $avg --set time.quasi_static.tolerance=$rtol

# Interrupted on 2 ranks and resumed: on 2 ranks bit for bit the run that
# was not interrupted (the partition is the same), on one process to
# round-off (a checkpoint is one process's).
interrupt 2 "$work/cut" "$f2" $f2set
want=3 resume_on "$work/cut" 1 2
check "interrupted on 2 ranks, resumed on 2: the run of 2 ranks, bit for bit" \
  $same "$work/f2-2" "$work/cut-2"
roundoff "interrupted on 2 ranks, resumed on 1" "$work/f2-1" "$work/cut-1"
# The same with the averaged volume (its state is u and v alone: Jbar and
# U'(Jbar) are made again by the force).
interrupt 2 "$work/acut" "$f2" $f2set $avg
want=3 resume_on "$work/acut" 1 2
check "averaged, interrupted on 2 ranks, resumed on 2: bit for bit" \
  $same "$work/f2-averaged-2" "$work/acut-2"
roundoff "averaged, interrupted on 2 ranks, resumed on 1" \
  "$work/f2-averaged-1" "$work/acut-1"

# A static run interrupted on 2 ranks after 3 of 10 load steps: resumed
# on 2 ranks bit for bit the run not interrupted (GMRES with ILU(0) in
# each rank's block repeats bit for bit; LU across ranks (MUMPS) analyses
# its matrix anew in a new run and repeats to round-off only), on one
# process and on 3 ranks to round-off the run not interrupted on as many
# (ILU(0) in 1, 2 or 3 blocks is another preconditioner each: the runs of
# different counts agree to GMRES's tolerance, 1e-10, not to round-off).
slow="$static $coarse --set time.quasi_static.load_steps=10
  --set time.quasi_static.linear_solver=gmres-ilu"
# (The one-process run, one thread, beside the runs on ranks.)
"$bin" run "$f2" --out "$work/s-1" --quiet $slow >/dev/null 2>&1 &
s1=$!
for n in 2 3; do
  ranks $n "$bin" run "$f2" --out "$work/s-$n" --quiet $slow >/dev/null 2>&1
done
interrupt 2 "$work/scut" "$f2" $slow
wait $s1
resume_on "$work/scut" 1 2 3
check "static, interrupted on 2 ranks, resumed on 2: bit for bit" \
  $same "$work/s-2" "$work/scut-2"
for n in 1 3; do
  bounds="residual=inf" roundoff \
    "static, interrupted on 2 ranks, resumed on $n" "$work/s-$n" "$work/scut-$n"
done
# Loads (2-D): the ring's follower pressure and the point forces (one on
# the nearest point, one shared by an edge's points, on a table curve)
# with gravity, by dynamic relaxation (300 steps, not yet quasi-static)
# and statically with every linear solve to 1e-10.
relax="--set time.quasi_static.method=dynamic-relaxation
  --set time.max_steps=300 --set output.every=100"
want=3 across ring "$fpm/ring/ring-pressure.yaml" 2 $relax
want=3 across point-forces "$fpm/point-forces.yaml" 2 $relax
bounds="residual=inf" across ring-static "$fpm/ring/ring-pressure.yaml" 2 \
  $static
bounds="residual=inf" across point-forces-static "$fpm/point-forces.yaml" \
  2 $static

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
