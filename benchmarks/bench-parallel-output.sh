#!/bin/bash
# A frame across ranks written five ways (tools/bench_parallel_output.c):
# gathered to rank 0 and written in one-process order (what a run does),
# one file a rank with an XDMF index of the pieces, the same joined by
# rank 0's frame file of virtual datasets (pm_results_join_pieces's way),
# and one file collectively through parallel HDF5 (each rank's particles
# at their one-process places, or as one block a rank with their indices
# beside),
# for the particles of the full oocyte (56^3 = 175 616) and of a million,
# on 1 and 2 ranks, each synced to disk and renamed as pointmech's frames
# are.  The ways take turns, REPS times (5); each line gives the median
# and the fastest seconds of a frame.
# usage: benchmarks/bench-parallel-output.sh [BUILD_DIR]
bench_name=parallel-output bench_env=REPS
source "$(dirname "$0")/bench-lib.sh"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
tool=$(dirname "$bin")/bench-parallel-output
[ -x "$tool" ] || {
  echo "bench-parallel-output: $tool not built (hdf5-openmpi missing?)" >&2
  exit 1
}
reps=${REPS:-5}
mkdir -p "$out/frames"
for size in "56 56 56" "100 100 100"; do
  for n in 1 2; do
    # shellcheck disable=SC2086
    OMP_NUM_THREADS=1 mpirun -np $n --bind-to core "$tool" "$out/frames" \
      $size "$reps" | { [ "$n$size" = "156 56 56" ] && cat || tail -n +2; }
  done
done
rm -rf "$out/frames"
