#!/bin/bash
# Two threads on this machine: ROUNDS times in turn (default 8), the round
# trip of a cache line between two threads (bench-pingpong, ns) and F2's
# explicit kernel on 2 OpenMP threads (point-steps a second, 16000
# steps), each pair a few seconds apart.  On a virtual machine the host
# places its two cores as it likes; the pairs show whether the two-thread
# rate follows the time a cache line takes between them
# (docs/validation.md, "Two threads on this machine").
# usage: [ROUNDS=N] benchmarks/bench-two-threads.sh [BUILD_DIR]   (about 2 min)
bench_name=two-threads bench_env="ROUNDS"
source "$(dirname "$0")/bench-lib.sh"
rounds=${ROUNDS:-8}
echo "| round | cache line round trip (ns) | F2 on 2 threads (point-steps/s) |"
echo "|---|---|---|"
for ((r = 1; r <= rounds; r++)); do
  ns=$("$build/bench-pingpong" 1000000)
  dir=$out/f2-$r
  rm -rf "$dir"
  OMP_NUM_THREADS=2 "$bin" run cases/fpm/f2-unconstrained-compression.yaml \
    --set time.max_steps=16000 --set output.every=100000 --out "$dir" \
    --quiet >/dev/null 2>&1 || true # (not converged in 16000 steps: exit 3)
  rate=$(json "$dir/summary.json" point_steps_per_second)
  printf '| %d | %s | %.3g |\n' "$r" "$ns" "$rate"
  sleep 5
done
