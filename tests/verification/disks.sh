#!/usr/bin/env bash
# Bad disks: a run whose output folder fills up (a small tmpfs, by the
# run's own frames and by another file taking the rest), turns read-only
# (a read-only bind mount over it) or is removed during the run stops at
# once with exit status 1 and the reason naming the file it was writing;
# every frame already written stays readable, the results index
# (results.h5, results.xdmf) lists only those, and the summary is the last
# one written whole (atomic files).  Mounting needs root or a
# user namespace: where neither is allowed the test says so and skips
# (exit 77).
set -u
bin=$1
src=$2
here=$(dirname "$0")
# A private mount namespace, so that the mounts go with the test.
if [ -z "${PM_DISKS_NS:-}" ]; then
  for ns in "unshare -m --propagation private" "unshare -rm"; do
    if $ns true 2>/dev/null; then
      PM_DISKS_NS=1 exec $ns bash "$0" "$@"
    fi
  done
fi
# shellcheck source=lib.sh
. "$here/lib.sh"
export OMP_NUM_THREADS=1
tube=$src/cases/mpm/m2-shock-tube-reduced.yaml
mnt=$work/mnt
mkdir -p "$mnt"
trap 'umount -l "$mnt/ro" "$mnt" 2>/dev/null; rm -rf "$work"' EXIT
if ! why=$(mount -t tmpfs -o size=1m tmpfs "$mnt" 2>&1); then
  echo "skipped: cannot mount a tmpfs here (${why:-not allowed}; needs root or user namespaces)"
  exit 77
fi

# Start a run of the shock tube writing a frame every 2 steps for far
# longer than the test; wait for N frame files (or its end).
start() { # out, frames
  "$bin" run "$tube" --out "$1" --quiet --set output.every=2 \
    --set time.end=1000 >/dev/null 2>"$work/err" &
  pid=$!
  local waited=0
  while [ "$(ls "$1/results" 2>/dev/null | grep -c frame_)" -lt "$2" ] &&
    kill -0 $pid 2>/dev/null && [ $waited -lt 2000 ]; do
    sleep 0.01
    waited=$((waited + 1))
  done
}

# Every frame the index lists opens and holds its positions; the XDMF
# names only frame files that exist.  Prints the frames listed.
index_ok() { # out
  /usr/bin/python3 - "$1" <<'PY'
import os, re, sys, h5py
out = sys.argv[1]
with h5py.File(os.path.join(out, "results.h5"), "r") as f:
    names = list(f["frames"])
    for k in names:
        assert f["frames"][k]["position"].shape[0] > 0, k
xdmf = open(os.path.join(out, "results.xdmf")).read()
for name in set(re.findall(r"results/frame_\d+\.h5", xdmf)):
    assert os.path.exists(os.path.join(out, name)), name
    with h5py.File(os.path.join(out, name), "r") as g:
        pass
print(len(names))
PY
}

# A stopped run: exit 1, the file and cause named, the frames kept.
stopped() { # label, out, cause
  local label=$1 out=$2 cause=$3 t0
  t0=$(date +%s.%N)
  wait $pid
  local rc=$?
  local lag
  lag=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')
  echo "$label: exit $rc $lag s after the disk went bad: $(head -1 "$work/err")"
  check "$label: exit 1 (got $rc)" test $rc -eq 1
  check "$label: names the file in $out and the cause '$cause'" \
    grep -Eq "'$out/[^']+'.*$cause" "$work/err"
  # A removed folder keeps nothing to check (rm -rf racing the run's
  # writes may leave the folder with a few of its newest files).
  [ -d "$out" ] && [ "$label" != removed ] || return 0
  # The summary is the last one written whole (where the disk let the
  # run write it, it says failed).
  check "$label: summary.json whole" /usr/bin/python3 -c \
    "import json, sys; json.load(open(sys.argv[1]))" "$out/summary.json"
  local n
  n=$(index_ok "$out" 2>"$work/py")
  check "$label: the index lists readable frames only (got '$n' $(tail -1 "$work/py"))" \
    test "${n:-0}" -ge 2
}

# 1. The run's own frames fill the 1 MiB disk: refused before the frame
# that would not fit (its size against the free space).
out=$mnt/full
start "$out" 100
stopped "full, by the frames" "$out" "No space left on device"

# 2. Another file takes the rest of a 16 MiB disk during the run: the
# next write fails with ENOSPC.
umount "$mnt" && mount -t tmpfs -o size=16m tmpfs "$mnt"
out=$mnt/filled
start "$out" 4
dd if=/dev/zero of="$mnt/filler" bs=64k 2>/dev/null
stopped "full, by another file" "$out" "No space left on device"
rm -f "$mnt/filler"

# 3. The folder turns read-only (a read-only bind mount over it: as root,
# chmod does not stop writes).  On a disk of its own of 64 MiB: the run
# writes frames until the remount takes hold, and under the suite's load
# the two mounts took long enough for 75 frames (12 MiB) that filled the
# 16 MiB disk first (ENOSPC, not the read-only file system).
umount "$mnt" && mount -t tmpfs -o size=64m tmpfs "$mnt"
out=$mnt/ro
start "$out" 4
if mount --bind "$out" "$out" 2>/dev/null && mount -o remount,bind,ro "$out" 2>/dev/null; then
  stopped "read-only" "$out" "Read-only file system"
  umount "$out"
  index_ok "$out" >/dev/null 2>&1
  check "read-only: the index lists readable frames only" test $? -eq 0
else
  kill $pid
  wait $pid
  echo "read-only: skipped (a read-only bind mount is not allowed here)"
fi

# 4. The folder is removed during the run.  The folders of 2 and 3, checked,
# go first: their runs write frames until stopped, as fast as the step
# allows, and what they leave must not fill the disk before this run's
# folder is removed (else it stops on ENOSPC, not on the removal).
rm -rf "$mnt/filled" "$mnt/ro"
out=$mnt/gone
start "$out" 4
# rm -rf racing the run's next frame can leave the folder behind (a file
# made between its unlink and rmdir): remove until it is gone.
until rm -rf "$out" 2>/dev/null && [ ! -e "$out" ]; do :; done
stopped "removed" "$out" "no longer exists|No such file"

echo "$passes passed, $failures failed"
[ $failures -eq 0 ]
