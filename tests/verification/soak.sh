#!/usr/bin/env bash
# Interrupted and resumed N times, a run ends bit for bit as the straight
# run: the MPM shock tube (reduced, run on to step 750, a frame every 5
# steps, a checkpoint every 10) is stopped N times at points drawn from a
# fixed seed (a history row, then up to 20 ms more), by SIGTERM or SIGKILL
# (drawn too), and resumed after each.  After every SIGKILL the results
# read back (results.h5 lists only frames on disk, results.xdmf parses);
# at the end the frames, the history and the summary's figures (all but
# the timings, the memory and the counts of resumes and checkpoints) are the straight
# run's.  Prints the interruptions by signal, and the frames and history
# rows compared.
# usage: soak.sh POINTMECH SOURCE_DIR [N=10] [SEED=1]
#        (the 50-interruption soak: benchmarks/soak-resume.sh)
set -u
bin=$1
src=$2
n=${3:-10}
seed=${4:-1}
here=$(dirname "$0")
py=/usr/bin/python3
# shellcheck source=lib.sh
. "$here/lib.sh"
export OMP_NUM_THREADS=1
scene=$src/cases/mpm/m2-shock-tube-reduced.yaml
args=(--set time.max_steps=750 --set time.end=1 --set output.every=5
  --set output.checkpoint.every=10)

straight=$work/straight
"$bin" run "$scene" --out "$straight" --quiet "${args[@]}" >/dev/null 2>&1
check "straight run completed" \
  grep -q '"status": "completed"' "$straight/summary.json"
total=$(rows "$straight")

# The interruptions: N distinct history rows from the 3rd (after the first
# checkpoint) to two thirds of the run (room for the poll to land before
# the end), each with a delay in ms and a signal.
plan=$($py - "$n" "$seed" "$total" <<'EOF'
import random, sys
n, seed, total = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
rng = random.Random(seed)
for row in sorted(rng.sample(range(4, 2 * total // 3), n)):
    print(row, rng.randrange(21), rng.choice(["TERM", "KILL"]))
EOF
)

out=$work/soak
term=0 kill=0 missed=0 failed=0 unreadable=0
start=("$bin" run "$scene" --out "$out" --quiet "${args[@]}")
while read -r row delay sig; do
  "${start[@]}" >/dev/null 2>"$work/err" &
  pid=$!
  wait_rows $pid "$out" "$row"
  sleep "$(printf '0.%03d' "$delay")"
  kill -"$sig" $pid 2>/dev/null
  { wait $pid; } 2>/dev/null # no "Killed" line from the shell
  rc=$?
  # SIGTERM: exit 4 (stopped, checkpoint written), or 143 when it came
  # before the run's handler was installed; 0: the run had ended first.
  case $sig:$rc in
  TERM:4 | TERM:143) term=$((term + 1)) ;;
  KILL:137) kill=$((kill + 1)) ;;
  *:0) missed=$((missed + 1)) ;;
  *)
    failed=$((failed + 1))
    sed "s/^/    $sig, exit $rc: /" "$work/err" | head -3
    ;;
  esac
  [ "$sig" = KILL ] &&
    ! $py "$here/results_readable.py" "$out" >/dev/null 2>>"$work/err" &&
    unreadable=$((unreadable + 1))
  start=("$bin" resume "$out" --quiet)
done <<<"$plan"
"${start[@]}" >/dev/null 2>"$work/err"

echo "soak: $n interruptions planned (seed $seed): $term by SIGTERM, $kill by" \
  "SIGKILL, $missed missed (the run ended first), $failed failed otherwise;" \
  "$(rows "$out") history lines"
check "every interruption landed ($missed missed)" test "$missed" -eq 0
check "no process failed otherwise ($failed)" test "$failed" -eq 0
check "results readable after every SIGKILL ($unreadable not)" \
  test "$unreadable" -eq 0
check "resumed run completed" grep -q '"status": "completed"' "$out/summary.json"
check "frames and history bit for bit the straight run's" \
  $py "$here/same_results.py" "$straight" "$out"
check "summary's figures the straight run's" $py - "$straight" "$out" <<'EOF'
import json, sys
a, b = (json.load(open(d + "/summary.json")) for d in sys.argv[1:3])
# Not figures of the solution: timings, and what interrupting changes.
skip = ("seconds", "per_second", "resume", "checkpoint", "memory")
bad = [k for k in a if not any(s in k for s in skip) and a[k] != b.get(k)]
assert not bad, [(k, a[k], b.get(k)) for k in bad]
print("summary: %d figures the same" % sum(1 for k in a if not any(s in k for s in skip)))
EOF
echo "soak: $passes checks passed, $failures failed"
[ "$failures" -eq 0 ]
