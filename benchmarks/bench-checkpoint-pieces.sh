#!/bin/bash
# CPU seconds of a checkpoint of the block at about a million particles
# (mesh_size 1.2e-3: 1 000 000) across RANKS ranks (default 2), gathered
# into rank 0 (output.ranks: gather) against written in pieces (the
# default): each way run for 6 steps with a checkpoint after steps 1 to 5
# (output.checkpoint.every=1) and without one, REPEAT times (default 2);
# every rank's user + system CPU seconds (/usr/bin/time), the least of the
# repeats, their difference over 5 the CPU of a checkpoint.  One line per
# way and rank: CPU s without and with the checkpoints, CPU s a
# checkpoint, peak RSS (KiB) with them, and the checkpoint's bytes on disk.
# usage: [RANKS=2] [REPEAT=2] benchmarks/bench-checkpoint-pieces.sh [BUILD_DIR]
bench_name=checkpoint-pieces bench_env="RANKS REPEAT"
source "$(dirname "$0")/bench-lib.sh"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
  OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_mpi_yield_when_idle=1 \
  OMP_NUM_THREADS=1
n=${RANKS:-2}
# One run under mpirun into $out/LABEL, each rank's figures into time.RANK.
run() { # LABEL [--set KEY=VALUE]...
  local d=$out/$1
  shift
  rm -rf "$d" && mkdir -p "$d"
  mpirun -np "$n" --bind-to none bash -c \
    'exec /usr/bin/time -f "%U %S %M" -o "$0/time.$OMPI_COMM_WORLD_RANK" "$@"' \
    "$d" "$bin" run cases/mpm/bench-block.yaml \
    --set discretization.mesh_size=1.2e-3 --set time.max_steps=6 \
    --set output.every=1000 "$@" --out "$d/out" --quiet >"$d/log" 2>&1 ||
    echo "$d: failed (see $d/log)"
}
# cpu LABEL RANK: the least CPU seconds of the repeats.
cpu() {
  for ((k = 1; k <= ${REPEAT:-2}; k++)); do
    awk '{print $1 + $2}' "$out/$1-$k/time.$2"
  done | sort -g | head -1
}
for ((k = 1; k <= ${REPEAT:-2}; k++)); do
  for way in gather pieces; do
    run "$way-none-$k" --set output.ranks=$way
    run "$way-ckpt-$k" --set output.ranks=$way --set output.checkpoint.every=1
  done
done
printf '%-7s %-5s %10s %10s %14s %12s %14s\n' way rank "CPU s none" \
  "CPU s ckpt" "CPU s a ckpt" "peak KiB" "ckpt bytes"
for way in gather pieces; do
  d=$out/$way-ckpt-1
  bytes=$(find "$d/out" \( -name checkpoint.h5 -o -path '*.pieces/*' \) \
    -type f -printf '%s\n' | awk '{s += $1} END {print s}')
  for ((r = 0; r < n; r++)); do
    a=$(cpu "$way-none" "$r") b=$(cpu "$way-ckpt" "$r")
    printf '%-7s %-5s %10.2f %10.2f %14.3f %12s %14s\n' "$way" "$r" "$a" \
      "$b" "$(echo "($b - $a) / 5" | bc -l)" \
      "$(awk '{print $3}' "$d/time.$r")" "$bytes"
  done
done
# Peak resident memory of every rank resuming each way's checkpoint (of
# step 5) on 1, 2 and 4 ranks, to step 6: a gathered checkpoint is read
# whole by every rank, which cuts its share from it; one in pieces by each
# rank from the pieces in its cells.  (The finished run's status is set to
# interrupted in a copy: resume takes only a run that did not end.)
printf '\n%-7s %-5s %-5s %12s\n' way ranks rank "peak KiB"
for way in gather pieces; do
  for m in 1 2 4; do
    d=$out/$way-resume-$m
    rm -rf "$d" && mkdir -p "$d" && cp -r "$out/$way-ckpt-1/out" "$d/out"
    sed -i 's/"status": "[a-z_]*"/"status": "interrupted"/' "$d/out/summary.json"
    mpirun -np "$m" --bind-to none bash -c \
      'exec /usr/bin/time -f "%M" -o "$0/time.$OMPI_COMM_WORLD_RANK" "$@"' \
      "$d" "$bin" resume "$d/out" --quiet >"$d/log" 2>&1 ||
      echo "$d: failed (see $d/log)"
    for ((r = 0; r < m; r++)); do
      printf '%-7s %-5s %-5s %12s\n' "$way" "$m" "$r" "$(tail -1 "$d/time.$r")"
    done
  done
done
