#!/bin/bash
# Peak resident memory of every rank of an MPM run (/usr/bin/time -v
# around each rank), 20 steps, on 1, 2 and 4 ranks (4 oversubscribed on
# fewer cores: memory, not time), for the 3-D block, the block at half its
# cell (mesh_size 1.25e-3: 884 736 particles) and the reduced oocyte; with
# BEFORE=BUILD_DIR the same runs by that build beside.  One line per rank:
# KiB and CPU seconds (user).  A tiny scene (the disks) gives each rank's
# floor: the program and its libraries (MPI, PETSc, HDF5).
# usage: [BEFORE=BUILD_DIR] benchmarks/bench-rank-memory.sh [BUILD_DIR]
bench_name=rank-memory bench_env="BEFORE RANKS"
source "$(dirname "$0")/bench-lib.sh"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
  OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_mpi_yield_when_idle=1 \
  OMP_NUM_THREADS=1
# One run under mpirun, each rank's figures into $d/time.RANK.
measure() { # LABEL BIN N SCENE [--set KEY=VALUE]...
  local label=$1 b=$2 n=$3 scene=$4 d
  shift 4
  d=$out/$label-$(basename "$scene" .yaml)-$n${1:+-set}
  rm -rf "$d" && mkdir -p "$d"
  mpirun -np "$n" --bind-to none bash -c \
    'exec /usr/bin/time -v -o "$0/time.$OMPI_COMM_WORLD_RANK" "$@"' "$d" \
    "$b" run "$scene" --set time.max_steps=20 "$@" --out "$d/out" --quiet \
    >"$d/log" 2>&1 || echo "$label $scene on $n: failed (see $d/log)"
  for ((r = 0; r < n; r++)); do
    printf '%-8s %-28s %s ranks %d rank %d: %8s KiB %6s s\n' "$label" \
      "$(basename "$scene" .yaml)${1:+ (fine)}" "$n" "$n" "$r" \
      "$(awk '/Maximum resident/ {print $NF}' "$d/time.$r")" \
      "$(awk '/User time/ {print $NF}' "$d/time.$r")"
  done
}
builds=("after:$bin")
[ -n "${BEFORE:-}" ] && builds=("before:$BEFORE/pointmech" "${builds[@]}")
for n in ${RANKS:-1 2 4}; do
  measure floor "$bin" "$n" cases/mpm/disks-collision.yaml
  for lb in "${builds[@]}"; do
    for sc in cases/mpm/bench-block.yaml cases/mpm/m4-oocyte-reduced.yaml; do
      measure "${lb%%:*}" "${lb#*:}" "$n" "$sc"
    done
    measure "${lb%%:*}" "${lb#*:}" "$n" cases/mpm/bench-block.yaml \
      --set discretization.mesh_size=1.25e-3 --set output.every=1000
  done
done
