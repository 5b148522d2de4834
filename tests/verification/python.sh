#!/usr/bin/env bash
# The Python module python/pointmech (Debian's h5py and numpy): opened from
# the repository, it reads a coarse F2 run's frames, mesh, history and
# summary (u_z = -0.4 z, F2's exact state, at every point of the last frame),
# follows a run while it goes on: every frame, in order, as written; and
# has the program vet each HDF5 file before h5py opens it (a damaged frame
# refused with the reason).
set -u
bin=$1
src=$2
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
export PYTHONPATH=$src/python
export POINTMECH=$bin # the program that vets the files
py=/usr/bin/python3
scene=$src/cases/fpm/f2-unconstrained-compression.yaml
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"

# The issue's one line, from the repository.
out=$work/f2
"$bin" run "$scene" --set discretization.mesh_size=0.02 --out "$out" \
  --quiet >/dev/null 2>"$work/err"
check "coarse F2 runs" test $? -eq 0
(cd "$src" && $py -c "import pointmech; r = pointmech.open('$out'); r.frames[-1]['displacement']") 2>"$work/err"
check "import pointmech; r.frames[-1]['displacement']" test $? -eq 0

$py - "$out" >"$work/read" 2>"$work/err" <<'PY'
import sys, numpy as np, pointmech
r = pointmech.open(sys.argv[1])
s = r.summary
last = r.frames[-1]
x, u = r.mesh["coordinates"], last["displacement"]
assert len(r.frames) == s["frames"], (len(r.frames), s["frames"])
assert u.shape == (s["points"], 3) and x.shape == u.shape
assert np.max(np.abs(u[:, 2] + 0.4 * x[:, 2])) < 1e-6
assert last.time == s["time"] and last.index == s["frames"] - 1
h = r.history
assert len(h["time"]) == s["frames"]
assert abs(h["time"][-1] - last.time) <= 1e-9 * last.time  # CSV: 10 digits
assert "stress" in last and last["stress"].shape == (s["points"], 3, 3)
print("frames", len(r.frames), "points", s["points"])
PY
check "frames, mesh, history and summary agree; u_z = -0.4 z" test $? -eq 0

# Following a run: started in the background, read as it goes.
out=$work/follow
"$bin" run "$scene" --set discretization.mesh_size=0.02 --set output.every=500 \
  --out "$out" --quiet >/dev/null 2>"$work/err-run" &
pid=$!
$py - "$out" >"$work/follow.txt" 2>"$work/err" <<'PY'
import os, sys, time, pointmech
out = sys.argv[1]
for _ in range(200):  # the folder appears once the run has started
    if os.path.exists(os.path.join(out, "summary.json")):
        break
    time.sleep(0.05)
r = pointmech.open(out)
running_at_first = r.running()
seen = [(f.index, f.step) for f in r.follow(poll=0.1, timeout=120)]
print(running_at_first, len(seen), r.summary["frames"])
assert [i for i, _ in seen] == list(range(len(seen)))
assert all(a[1] < b[1] for a, b in zip(seen, seen[1:]))
assert len(seen) == r.summary["frames"] and r.summary["status"] != "running"
PY
check "follow: every frame in order, as many as the summary's" test $? -eq 0
wait $pid
check "the followed run ends well" test $? -eq 0
echo "python: $(cat "$work/read"); followed: $(cat "$work/follow.txt")"

# A frame whose global heap loops HDF5 (tests/fuzz/upstream/): refused by
# the program's vetting, with its reason, before h5py opens it.
bad=$work/bad
mkdir -p "$bad/results"
cp "$src/tests/fuzz/upstream/checkpoint/hdf5-global-heap-loop" \
  "$bad/results/frame_000000.h5"
PM_ISOLATE_CPU_SECONDS=1 $py - "$bad" >"$work/refused" 2>"$work/err" <<'PY'
import sys, pointmech
try:
    pointmech.open(sys.argv[1]).frames[0].keys()
except pointmech.Refused as e:
    print(e)
else:
    raise SystemExit("not refused")
PY
check "a damaged frame refused by pointmech vet, with the reason" \
  grep -q "frame_000000.h5: HDF5 used more than 1 CPU seconds" "$work/refused"

# tools/paraview-open.py where ParaView is installed (Debian's paraview and
# python3-paraview; xvfb-run for a machine without a display): a picture of
# the coarse F2 run coloured by von Mises, and a state file.
if command -v pvbatch >/dev/null && command -v xvfb-run >/dev/null; then
  (cd "$work" && timeout 300 xvfb-run -a pvbatch "$src/tools/paraview-open.py" \
    "$work/f2" --screenshot f2.png --state f2.pvsm) >"$work/pv" 2>"$work/err"
fi
if grep -q "bad X server connection" "$work/err" 2>/dev/null; then
  # xvfb-run's server was not there for pvbatch (seen in 3 of 16 runs here):
  # the machine's, not the script's; said, not counted.
  echo "paraview-open: skipped (xvfb-run gave pvbatch no X server)"
elif command -v pvbatch >/dev/null && command -v xvfb-run >/dev/null; then
  check "paraview-open: coloured by von_mises" grep -q "coloured by von_mises" "$work/pv"
  check "paraview-open: a picture and a state" test -s "$work/f2.png" -a -s "$work/f2.pvsm"
else
  echo "paraview-open: skipped (pvbatch or xvfb-run not installed)"
fi

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
