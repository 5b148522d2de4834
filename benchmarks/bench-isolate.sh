#!/bin/bash
# What reading a file in a child process costs (tools/bench_isolate.c):
# the sphere of tests/data/geometry/sphere.geo meshed by gm_gmsh_load at
# two sizes (H, default 0.1 and 0.05), and the checkpoint of a 500 000
# particle MPM run (100 MB, made first in OUT) vetted as `resume` vets it,
# each REPEATS times (5), in a child and in the process: CPU seconds of the
# process and of its children, wall seconds, and the process's peak
# resident memory after each way.
# usage: benchmarks/bench-isolate.sh [BUILD_DIR]
bench_name=isolate bench_env="H REPEATS"
source "$(dirname "$0")/bench-lib.sh"
tool=$(dirname "$bin")/bench-isolate
repeats=${REPEATS:-5}
ck=$out/checkpoint-run
rm -rf "$ck"
OMP_NUM_THREADS=1 "$bin" run tests/data/scenes/minimal-2d.yaml -o "$ck" \
  --set discretization.mesh_size=0.002 --set time.max_steps=3 \
  --set output.every=1 --set output.checkpoint.every=1 --quiet >/dev/null
echo "checkpoint: $(stat -c %s "$ck/checkpoint.h5") bytes"
for h in ${H:-0.1 0.05}; do
  OMP_NUM_THREADS=1 "$tool" tests/data/geometry/sphere.geo "$h" "$ck" \
    "$repeats"
done
