#!/bin/bash
# The explicit kernels of two builds side by side, for a quiet machine: F2
# (FPM, 1851 points), the MPM 3-D block (110592 particles) and the shock
# tube (20000 particles), each on 1 and 2 OpenMP threads, the two builds in
# turn, REPEATS times (default 3); the medians of point_steps_per_second
# (summary.json: the step loop, setup excluded) and the efficiency on two
# threads (the 2-thread rate over twice the 1-thread rate).  Each run is
# about 5-10 s on one quiet core; STEPS_F2, STEPS_BLOCK, STEPS_TUBE change
# the step counts, TUBE the tube's scene.
# usage: benchmarks/kernels-quiet.sh OLD_BUILD NEW_BUILD   (about 6 min)
bench_name=kernels-quiet
bench_env="REPEATS STEPS_F2 STEPS_BLOCK STEPS_TUBE TUBE"
source "$(dirname "$0")/bench-lib.sh"
old=$1 new=${2:?usage: benchmarks/kernels-quiet.sh OLD_BUILD NEW_BUILD}
repeats=${REPEATS:-3}
# The runtime's own waiting policy, as pointmech sets it (a short spin).
export GOMP_SPINCOUNT=${GOMP_SPINCOUNT:-3000}
cases=(
  "F2 cases/fpm/f2-unconstrained-compression.yaml ${STEPS_F2:-16000}"
  "block cases/mpm/bench-block.yaml ${STEPS_BLOCK:-150}"
  "tube ${TUBE:-cases/mpm/m2-shock-tube.yaml} ${STEPS_TUBE:-5000}"
)
rates=$out/rates.txt
: >"$rates"
for ((r = 1; r <= repeats; r++)); do
  for c in "${cases[@]}"; do
    read -r name scene steps <<<"$c"
    for threads in 1 2; do
      for b in old new; do
        dir=$out/$name-$b-t$threads-r$r
        bin=${!b}/pointmech
        OMP_NUM_THREADS=$threads bench_run "$dir" "$scene" \
          --set time.max_steps="$steps" --set output.every=1000000 || true
        echo "$name $b $threads $(json "$dir/summary.json" \
          point_steps_per_second)" >>"$rates"
      done
    done
  done
done
$py - "$rates" "$old" "$new" <<'PY'
import sys, statistics
runs = {}
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) == 4 and f[3]:
        runs.setdefault((f[0], f[1], int(f[2])), []).append(float(f[3]))
print("| case | build | 1 thread | 2 threads | per core | efficiency on two | runs (1 thread; 2 threads) |")
print("|---|---|---|---|---|---|---|")
for case in dict.fromkeys(k[0] for k in runs):
    for b, path in (("old", sys.argv[2]), ("new", sys.argv[3])):
        one, two = runs.get((case, b, 1), []), runs.get((case, b, 2), [])
        m1 = statistics.median(one) if one else float("nan")
        m2 = statistics.median(two) if two else float("nan")
        each = lambda v: " ".join("%.3g" % x for x in v)
        print("| %s | %s (%s) | %.3g | %.3g | %.3g | %.0f%% | %s; %s |" % (
            case, b, path, m1, m2, m2 / 2, 100 * m2 / (2 * m1),
            each(one), each(two)))
PY
