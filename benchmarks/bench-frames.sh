#!/bin/bash
# What a frame costs as a run grows: a tiny scene (tests/data/scenes
# minimal-2d at mesh size 0.25, 32 points) writing a frame at every step,
# run for N steps for each N in NS, as CPU seconds (user + system, from
# /usr/bin/time) per frame: the run's less those of the same run writing
# only its first and last frame, over the frames that adds.  A cost per
# frame that does not grow with N is the index and XDMF appended; one that
# grows linearly is the files rewritten whole (total cost quadratic in N).
# BEFORE: another build's pointmech to run beside this one's (for N up to
# BEFORE_MAX only: rewritten whole, 1e5 frames take hours).
# usage: benchmarks/bench-frames.sh [BUILD_DIR]   (NS: frame counts,
#        "100 1000 10000 100000"; BEFORE: a pointmech to compare, none;
#        BEFORE_MAX: its largest N, 10000; BENCH_OUT: the runs' folder,
#        /dev/shm/bench-frames where it exists: the per-frame fsyncs cost
#        wall time on a disk, not CPU, and 1e5 frames take 400 MB)
bench_name=frames bench_env="NS BEFORE BEFORE_MAX BENCH_OUT"
[ -d /dev/shm ] && bench_out=/dev/shm/bench-frames
source "$(dirname "$0")/bench-lib.sh"
ns=${NS:-100 1000 10000 100000}
before=${BEFORE:-}
before_max=${BEFORE_MAX:-10000}
scene=tests/data/scenes/minimal-2d.yaml
export OMP_NUM_THREADS=1

# cpu BIN N EVERY DIR: CPU seconds of a run of N steps, a frame every
# EVERY, into DIR (its summary kept).
cpu() {
  rm -rf "$4"
  /usr/bin/time -f "%U %S" "$1" run "$scene" --out "$4" --quiet \
    --set discretization.mesh_size=0.25 --set time.end=1e9 \
    --set time.max_steps="$2" --set output.every="$3" 2>&1 >/dev/null |
    tail -1 | awk '{print $1 + $2}'
}

# one BIN LABEL N: runs of N steps with a frame each and with none, and
# the table row.
one() {
  local dir="$out/$2-$3" with without
  with=$(cpu "$1" "$3" 1 "$dir")
  without=$(cpu "$1" "$3" "$3" "$dir-none")
  $py - "$dir/summary.json" "$dir-none/summary.json" "$2" "$with" \
    "$without" <<'EOF'
import json, sys
s, s0 = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
with_, without = float(sys.argv[4]), float(sys.argv[5])
assert s["status"] == s0["status"] == "completed", (s["status"], s0["status"])
frames = s["frames"] - s0["frames"]
print("%-7s %7d %7d %10.2f %10.2f %14.1f" % (
    sys.argv[3], s["steps"], s["frames"], with_, without,
    1e6 * (with_ - without) / frames))
EOF
  rm -rf "$dir" "$dir-none"
}

printf '%-7s %7s %7s %10s %10s %14s\n' build steps frames "CPU s" \
  "no frames" "CPU us/frame"
for n in $ns; do
  one "$bin" this "$n"
  if [ -n "$before" ] && [ "$n" -le "$before_max" ]; then
    one "$before" before "$n"
  fi
done
echo "CPU s: user + system seconds of the run writing a frame every step;"
echo "no frames: of the same run writing only its first and last frame;"
echo "CPU us/frame: the difference over the frames it adds."
