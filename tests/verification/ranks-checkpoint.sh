#!/usr/bin/env bash
# Checkpoints across ranks written in pieces (frames in pieces, no whole
# model on any rank): each rank its share, rank 0 the index naming them;
# a run interrupted on 2 or 3 ranks and resumed from its pieces on 1, 2
# or 3: on as many ranks bit for bit the run that was not interrupted, on
# another count to round-off (the bound of ranks.sh); a damaged piece
# refused by name.
# Usage: ranks-checkpoint.sh POINTMECH SOURCE_DIR
set -u
bin=$1
src=$2
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/ranks-lib.sh"

# The disks (2-D, each disk's particles shared among the boxes, moving
# between them), slowed to some 1600 steps so that a signal stops them
# midway; a checkpoint every 300 steps besides the signal's.
disks=$mpm/disks-collision.yaml
slow="--set time.dt_safety=0.05 --set output.every=100
      --set output.ranks=pieces --set output.checkpoint.every=300"
# shellcheck disable=SC2086
"$bin" run "$disks" --out "$work/whole-1" --quiet $slow >/dev/null 2>&1 &
one=$!
# shellcheck disable=SC2086
ranks 2 "$bin" run "$disks" --out "$work/whole-2" --quiet $slow \
  >/dev/null 2>&1
wait $one

# shellcheck disable=SC2086
interrupt 2 "$work/cut" "$disks" $slow
check "interrupted on 2 ranks: the index and one piece a rank" $py -c "
import os, sys, h5py
d = sys.argv[1]
names = sorted(os.listdir(d + '/checkpoint.pieces'))
assert len(names) == 2 and names[0].endswith('.piece_0000.h5'), names
assert names[0].split('.')[0] == names[1].split('.')[0], names
with h5py.File(d + '/checkpoint.h5', 'r') as f:
    assert f['pieces.n'][0] == 2 and 'mpm.00.position' not in f
" "$work/cut"
resume_on "$work/cut" 1 2 3
check "interrupted on 2 ranks, resumed on 2: the run of 2 ranks, bit for bit" \
  $same "$work/whole-2" "$work/cut-2"
roundoff "interrupted on 2 ranks, resumed on 3" "$work/whole-2" "$work/cut-3"
roundoff "interrupted on 2 ranks, resumed on 1" "$work/whole-1" "$work/cut-1"

# shellcheck disable=SC2086
# On 4 ranks the boxes are cut anew as the disks meet (mpm.rebalance):
# interrupted after some of those cuts, the run resumed on 4 ranks goes on
# on the boxes it had (the checkpoint's cut), bit for bit.
ranks 4 "$bin" run "$disks" --out "$work/whole-4" --quiet $slow \
  >/dev/null 2>&1
rows=10 interrupt 4 "$work/cut4" "$disks" $slow
check "interrupted on 4 ranks: after the boxes were cut anew" $py -c "
import h5py, sys
with h5py.File(sys.argv[1] + '/checkpoint.h5', 'r') as f:
    assert f['run.ranks.cut'][0] >= 1, f['run.ranks.cut'][:5]
" "$work/cut4"
resume_on "$work/cut4" 4
check "interrupted on 4 ranks, resumed on 4: bit for bit" \
  $same "$work/whole-4" "$work/cut4-4"

interrupt 3 "$work/cut3" "$disks" $slow
resume_on "$work/cut3" 2
roundoff "interrupted on 3 ranks, resumed on 2" "$work/whole-1" "$work/cut3-2"

# One process's checkpoint (whole) resumed on 2 ranks, where no rank
# keeps the whole model: each rank's share cut from it, then let go.
# shellcheck disable=SC2086
interrupt 1 "$work/cut1" "$disks" $slow
resume_on "$work/cut1" 2
roundoff "interrupted on one process, resumed on 2" "$work/whole-1" \
  "$work/cut1-2"

# A piece whose bytes changed: refused by name before the run goes on.
cp -r "$work/cut" "$work/bad"
piece=$(ls "$work/bad/checkpoint.pieces/"*.piece_0001.h5)
size=$(stat -c %s "$piece")
printf '\x55\x55\x55\x55\x55\x55\x55\x55' |
  dd of="$piece" bs=1 seek=$((size - 64)) conv=notrunc status=none
ranks 2 "$bin" resume "$work/bad" --quiet >/dev/null 2>"$work/err"
rc=$?
check "a damaged piece: refused (exit $rc)" test $rc -ne 0
check "a damaged piece: named" grep -q "piece_0001.h5" "$work/err"

# A piece standing in for another (rank 0's copied over rank 1's): its
# particles are refused as placed twice, by name, before its checksum is
# read (one process reads every piece).
cp -r "$work/cut" "$work/twice"
first=$(ls "$work/twice/checkpoint.pieces/"*.piece_0000.h5)
cp "$first" "${first%.piece_0000.h5}.piece_0001.h5"
"$bin" resume "$work/twice" --quiet >/dev/null 2>"$work/err"
rc=$?
check "a piece copied over another: refused (exit $rc)" test $rc -ne 0
check "a piece copied over another: a particle in two pieces, named" \
  grep -q "is in two of its pieces (the second: piece 1)" "$work/err"

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
