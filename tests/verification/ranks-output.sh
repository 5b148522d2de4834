#!/usr/bin/env bash
# A frame across ranks written in pieces, each rank its own, joined by rank
# 0's frame file of virtual datasets, against the same frame gathered to
# rank 0 and written whole (ranks_output: bit for bit, in one-process
# order), on 2 and 3 ranks; then the pieces' frame read as one field by the
# Python module (one-process order), by `pointmech probe` and by ParaView
# (pvpython, where installed: one grid of every particle).
# Usage: ranks-output.sh SOURCE_DIR RANKS_OUTPUT POINTMECH
set -u
src=$1
tool=$2
bin=$3
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/ranks-lib.sh"

# command..., its output kept in $work/err (shown if it fails).
quiet() { "$@" >"$work/err" 2>&1; }
# The pieces' frame (1) by `pointmech probe --at points`, the same table as
# the gathered frame's (0).
probe_same() {
  "$bin" probe "$1" --at points --frame 0 >"$work/p0.csv" &&
    "$bin" probe "$1" --at points --frame 1 >"$work/p1.csv" &&
    cmp "$work/p0.csv" "$work/p1.csv"
}

for n in 2 3; do
  out=$work/out-$n
  check "a frame in pieces on $n ranks is the gathered frame" \
    ranks "$n" "$tool" "$out" 7 5 3
  check "the Python module reads $n ranks' pieces in one-process order" \
    env PYTHONPATH="$src/python" "$py" -c '
import sys, h5py, numpy as np, pointmech
r = pointmech.open(sys.argv[1])
whole, pieces = r.frames[0], r.frames[1]
assert sorted(whole.keys()) == sorted(pieces.keys()), pieces.keys()
for name in whole.keys():
    assert np.array_equal(whole[name], pieces[name]), name
with h5py.File(sys.argv[1] + "/results.h5", "r") as f:
    assert f["frames/000001"].attrs["pieces"] == int(sys.argv[2])
    assert f["frames/000001/index"].shape == (105,)
    for name in whole.keys():
        assert np.array_equal(pointmech.read_rows(f["frames/000000"], name),
                              pointmech.read_rows(f["frames/000001"], name))
' "$out" "$n"
  check "probe reads $n ranks' pieces in one-process order" \
    probe_same "$out"
  if command -v pvpython >/dev/null; then
    check "ParaView reads $n ranks' pieces as one grid a frame" \
      quiet timeout 120 pvpython -c '
import sys
from paraview import simple as pv, servermanager as sm
r = pv.XDMFReader(FileNames=[sys.argv[1] + "/results.xdmf"])
r.UpdatePipelineInformation()
assert list(r.TimestepValues) == [0.0, 0.1], r.TimestepValues
ranges = []
for t in r.TimestepValues:
    r.UpdatePipeline(t)
    d = sm.Fetch(r)
    assert d.GetNumberOfPoints() == 105, d.GetNumberOfPoints()
    ranges.append(d.GetPointData().GetArray("displacement").GetRange(-1))
assert ranges[0] == ranges[1], ranges
' "$out"
  fi
done

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
