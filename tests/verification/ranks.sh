#!/usr/bin/env bash
# Explicit MPM across MPI ranks against the same runs on one process.
# Usage: ranks.sh POINTMECH SOURCE_DIR RANKS_MIGRATE
#
# A run across ranks sums each node's contributions in another order (each
# rank's share, then the ranks'), so its values differ from one process's
# by round-off, which the steps carry on: measured 6e-14 (shock tube, 296
# steps), 2e-14 to 2e-13 (disks, 157 steps, 2 to 4 ranks), 4e-12 (F2, 100
# steps) and 4e-12 to 7e-12 (the shock tube to t = 2 s, some 4000 steps,
# interrupted on 2 ranks and resumed on 3 or on one process).  The bound, 1e-10 of each field's largest magnitude, leaves room
# for other machines and catches any real error (a contribution lost or
# counted twice is of order 1).  One rank under mpirun is one process, bit
# for bit.  Each run has one OpenMP thread per rank, and ranks waiting in a
# collective yield their core (mpi_yield_when_idle): more ranks than cores
# otherwise spin against each other, 20 times slower.
set -u
bin=$1
src=$2
migrate=$3
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/ranks-lib.sh"

# The shock tube (3-D, pressure ratio 1000, cut along x between its
# walls), the disks (2-D: 2, 3 and 4 boxes, each disk's particles shared
# among them) and F2 (3-D, dynamic relaxation with moving and fixed walls:
# z holds the moving wall and is not cut).
across shock-tube $mpm/m2-shock-tube-reduced.yaml 2
across disks $mpm/disks-collision.yaml 2
across disks $mpm/disks-collision.yaml 3
across disks $mpm/disks-collision.yaml 4
# (100 steps: not yet quasi-static, exit 3)
want=3 across f2 $mpm/f2-unconstrained-compression.yaml 2 \
  --set time.max_steps=100 --set output.every=25

check "shock tube: the decomposition in summary.json" $py -c "
import json, sys
r = json.load(open('$work/shock-tube-2/summary.json'))['ranks']
sys.exit(not (r['count'] == 2 and r['cuts'] == [1, 0, 0] and
              r['particles_at_start'] == [400, 400] and
              r['particles_migrated'] > 0 and r['node_bytes_per_step'] > 0))"
check "disks on 4 ranks: the particles shared alike" $py -c "
import json, sys
r = json.load(open('$work/disks-4/summary.json'))['ranks']
sys.exit(not (sum(r['particles_at_start']) == 416 and
              max(r['particles_at_start']) <= 1.1 * 416 / 4))"
# The disks meet in the middle of the grid: on the boxes of the start two
# of 4 ranks empty out and two fill (mpm.rebalance: 0); cut anew as they
# travel (the default), the busiest rank holds fewer, and the run is still
# one process's to round-off (the comparison above).
ranks 4 "$bin" run "$mpm/disks-collision.yaml" --out "$work/disks-kept" \
  --quiet --set mpm.rebalance=0 >/dev/null 2>&1
check "disks on 4 ranks: where the particles went, and the imbalance" $py -c "
import json, sys
def ranks(run):
    return json.load(open('$work/' + run + '/summary.json'))['ranks']
k, c = ranks('disks-kept'), ranks('disks-4')
end, most, imb = k['particles_at_end'], k['particles_most'], k['imbalance']
ok = (sum(end) == 416 and min(end) < 104 < max(end) and k['recuts'] == 0 and
      all(m >= max(a, e) for m, a, e in
          zip(most, k['particles_at_start'], end)) and
      abs(imb['at_end'] - max(end) * 4 / 416) < 1e-12 and
      abs(imb['most'] - max(most) * 4 / 416) < 1e-12 and imb['at_start'] == 1)
# cut anew: at least once, the start's counts kept apart from the last cut's
ok = ok and (c['recuts'] >= 1 and c['particles_at_start'] == [104] * 4 and
             sum(c['particles_at_last_cut']) == 416 and
             c['imbalance']['most'] < imb['most'])
print('most held over the mean: kept', imb['most'], 'cut anew',
      c['imbalance']['most'], 'in', c['recuts'], 'cuts')
sys.exit(not ok)"

# One rank under mpirun is one process.
ranks 1 "$bin" run "$mpm/disks-collision.yaml" --out "$work/disks-np1" \
  --quiet >/dev/null 2>"$work/err"
check "disks on 1 rank: one process, bit for bit" \
  $same "$work/disks-1" "$work/disks-np1"

# An explicit run across ranks exchanges in MPI alone: no rank opens PETSc
# (the loader's record of every library each rank opens).
LD_DEBUG=files ranks 2 "$bin" run "$mpm/disks-collision.yaml" \
  --out "$work/disks-libs" --set time.max_steps=5 --quiet >/dev/null \
  2>"$work/libs"
check "disks on 2 ranks: the libraries opened are recorded" \
  grep -q 'file=libhdf5' "$work/libs"
check "disks on 2 ranks: no rank opens PETSc" \
  sh -c "! grep -q 'file=libpetsc' '$work/libs'"

# The plan prints the decomposition and every rank's share.
ranks 2 "$bin" plan "$mpm/f2-unconstrained-compression.yaml" >"$work/plan" \
  2>"$work/err"
check "plan on 2 ranks: exit 0" test $? -eq 0
check "plan on 2 ranks: the boxes" \
  grep -q '^ranks        2: boxes .* (cuts along x 1, y 0, z 0)' "$work/plan"
check "plan on 2 ranks: z, where a wall moves, not cut" \
  grep -q 'not cut: z: the wall of boundary.3 (zmax) moves' "$work/plan"
check "plan on 2 ranks: a line per rank" \
  test "$(grep -cE '^ +[01] +[0-9]+ +[0-9]+ \(' "$work/plan")" -eq 2

# Migration moves particles and nothing else (compared on rank 0's whole
# model: frames gathered).
for n in 2 3; do
  ranks $n "$migrate" "$mpm/disks-collision.yaml" 157 output.ranks=gather \
    >"$work/mig" 2>&1
  rc=$?
  tail -1 "$work/mig"
  check "migration on $n ranks (disks): exit 0 (got $rc)" test $rc -eq 0
  check "migration on $n ranks (disks): particles moved" \
    grep -qE 'ranks, [1-9][0-9]* particles migrated, 0 failed' "$work/mig"
done
ranks 2 "$migrate" "$mpm/m2-shock-tube-reduced.yaml" 296 output.ranks=gather \
  >"$work/mig" 2>&1
rc=$?
tail -1 "$work/mig"
check "migration on 2 ranks (shock tube): exit 0 (got $rc)" test $rc -eq 0

# Each rank seeds its share from the scene alone, the share cut from the
# whole model bit for bit (ranks_migrate's first check): a membrane with
# bodies inside and outside it and cylinders (the reduced oocyte), dynamic
# relaxation's nodal arrays (F2) and a TIFF image's voxels (I2's slice;
# gathered: the check reads the whole model on rank 0).
for sc in m4-oocyte-reduced f2-unconstrained-compression i2-vessel-slice; do
  ranks 3 "$migrate" "$mpm/$sc.yaml" 1 output.ranks=gather >"$work/mig" 2>&1
  rc=$?
  tail -1 "$work/mig"
  check "shares seeded on 3 ranks ($sc): exit 0 (got $rc)" test $rc -eq 0
done

# A particle that leaves the grid stops every rank with one process's
# message (the particle by its index on one process), not a hang.
fails_alike left-the-grid 2 'step [0-9]*, .*left the grid' \
  "$mpm/disks-collision.yaml" --set "bodies.1.velocity=[3,3]"

# What runs on one process only is refused, naming the key; nothing written.
# Frames in pieces (output.ranks: pieces): each rank writes its own
# particles and rank 0 joins them; read in one-process order, the same
# run's frames as gathered, bit for bit, and one process's to round-off.
# Without checkpoints no rank holds the whole model: the history rows and
# the end's figures are sums over the shares, the gathered run's to
# round-off; the mesh is one process's, bit for bit.
across disks-pieces $mpm/disks-collision.yaml 3 --set output.ranks=pieces
check "disks on 3 ranks: frames in pieces as gathered, bit for bit" \
  $same --frames "$work/disks-3" "$work/disks-pieces-3"
roundoff "disks on 3 ranks: in pieces (sums) against gathered" \
  "$work/disks-3" "$work/disks-pieces-3"
# The errors against a reference field (time-dependent, two components)
# summed over the shares too.
across disks-ref $mpm/disks-collision.yaml 3 --set output.ranks=pieces \
  --set 'reference.displacement.x=0.1*x*t' \
  --set 'reference.displacement.y=0.05*y'
check "disks on 3 ranks: in pieces, the mesh and the end's figures" \
  $py "$src/tests/verification/same_figures.py" "$work/disks-1" \
  "$work/disks-pieces-3" \
  points,particles,grid_nodes,groups,steps,max_von_mises_at,end_min_jacobian_at \
  kinetic_energy,strain_energy,initial_energy,mean_strain_energy_density,max_von_mises,end_min_jacobian,min_jacobian
check "disks on 3 ranks: a piece a rank a frame" \
  test "$(ls "$work/disks-pieces-3/results" | grep -c '\.piece_')" -eq \
  $((3 * $(ls "$work/disks-pieces-3/results" | grep -c '^frame_[0-9]*\.h5$')))
refused "frames in pieces with a membrane on 2 ranks" \
  "frames in pieces hold particles without triangles" \
  "$work/membrane-pieces-2" ranks 2 "$bin" run \
  "$mpm/m3-gas-box-membrane.yaml" --set output.ranks=pieces \
  --out "$work/membrane-pieces-2"

refused "F-bar over node patches on 2 ranks" \
  "mpm.fbar: F-bar over node patches runs on one process" \
  "$work/patch-2" ranks 2 "$bin" run "$mpm/locking-beam.yaml" \
  --out "$work/patch-2"
refused "convergence on 2 ranks" "convergence runs on one process" \
  "$work/conv-2" ranks 2 "$bin" convergence "$mpm/disks-collision.yaml" \
  --set-ladder discretization.mesh_size=0.1,0.05 --out "$work/conv-2"

# Interrupted on 2 ranks and resumed: on 2 ranks bit for bit the run that
# was not interrupted (the boxes come from the reference positions, each
# rank's energy accounts from the checkpoint), on 3 ranks and on one
# process to round-off (a checkpoint is one process's).
tube=$mpm/m2-shock-tube-reduced.yaml
long="--set time.end=2 --set output.every=100"
"$bin" run "$tube" --out "$work/long-1" --quiet $long >/dev/null 2>&1
ranks 2 "$bin" run "$tube" --out "$work/long-2" --quiet $long >/dev/null 2>&1
interrupt 2 "$work/cut" "$tube" $long
resume_on "$work/cut" 1 2 3
check "interrupted on 2 ranks, resumed on 2: the run of 2 ranks, bit for bit" \
  $same "$work/long-2" "$work/cut-2"
roundoff "interrupted on 2 ranks, resumed on 3" "$work/long-2" "$work/cut-3"
roundoff "interrupted on 2 ranks, resumed on 1" "$work/long-1" "$work/cut-1"
# The same with frames in pieces, resumed on 3 ranks: the frames after
# the checkpoint (the signal's) and their pieces dropped, the later ones
# in 3 pieces.  (The checkpoints too are in pieces: ranks-checkpoint.sh.)
interrupt 2 "$work/pcut" "$tube" $long --set output.ranks=pieces \
  --set output.checkpoint.minutes=60
resume_on "$work/pcut" 3
roundoff "in pieces, interrupted on 2 ranks, resumed on 3" "$work/long-2" \
  "$work/pcut-3"
check "in pieces, resumed on 3: no piece of a dropped frame" $py -c "
import os, re, sys
d = sys.argv[1] + '/results'
frames = {m.group(1) for n in os.listdir(d)
          for m in [re.match(r'frame_(\\d+)\\.h5$', n)] if m}
pieces = {m.group(1) for n in os.listdir(d)
          for m in [re.match(r'frame_(\\d+)\\.piece_\\d+\\.h5$', n)] if m}
assert pieces == frames, sorted(pieces ^ frames)
" "$work/pcut-3"

# In pieces without output.checkpoint no rank holds the whole model: a
# signal stops the run with its frames and a checkpoint in pieces, a
# piece a rank.
interrupt 2 "$work/pnone" "$tube" $long --set output.ranks=pieces
check "in pieces, no output.checkpoint, interrupted: a checkpoint in pieces" \
  test -f "$work/pnone/checkpoint.h5" -a \
  "$(ls "$work/pnone/checkpoint.pieces" | grep -c '\.piece_')" -eq 2

# A rank's memory below one process's need: refused before the setup on
# one process with both figures; on 2 ranks in pieces, where no rank
# holds the whole model, it runs (one process's results to round-off).
refused "one process past POINTMECH_MEMORY_LIMIT" \
  "needs an estimated 324.1 KiB" "$work/mem-1" \
  env POINTMECH_MEMORY_LIMIT=250K "$bin" run "$mpm/disks-collision.yaml" \
  --out "$work/mem-1" --quiet
check "past POINTMECH_MEMORY_LIMIT: what is available, said" \
  grep -qF "but 250.0 KiB (256000 bytes) is available" "$work/err"
POINTMECH_MEMORY_LIMIT=250K ranks 2 "$bin" run "$mpm/disks-collision.yaml" \
  --set output.ranks=pieces --out "$work/mem-2" --quiet >/dev/null \
  2>"$work/err"
check "POINTMECH_MEMORY_LIMIT one process passes: 2 ranks in pieces run" \
  test $? -eq 0
roundoff "2 ranks in pieces under the limit" "$work/disks-1" "$work/mem-2"

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
