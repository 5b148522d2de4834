#!/bin/bash
# Peak resident memory of every rank of an MPM run (/usr/bin/time -v
# around each rank; after it, the peak the run's summary.json gives the
# rank, without the child that meshes), 20 steps, on 1, 2 and 4 ranks (4
# oversubscribed on fewer cores: memory, not time), for the 3-D block,
# the block at half its
# cell (mesh_size 1.25e-3: 884 736 particles), the block with its frames
# in pieces (output.ranks: pieces, no checkpoints: rank 0 without the
# whole model; label "pieces", the fine block too), both blocks with the
# default output and a checkpoint after step 10 (label BUILD-ckpt), the
# reduced oocyte and I2
# by the implicit MPM at 256^2 cells (its 10 load steps; label i2-256: the
# default output, in pieces across ranks; "gather": output.ranks: gather;
# BUILD-ckpt: a checkpoint after load step 5); with
# BEFORE=BUILD_DIR the same runs by that build beside.  One line per rank:
# KiB and CPU seconds (user).  A tiny scene (the disks) gives each rank's
# floor: the program and its libraries (MPI, HDF5; PETSc only where the
# run solves, Scotch where FPM partitions).  With
# METHOD=fpm: FPM F3 at 60% at 4036 and 13762 points (mesh_size 6.42e-3,
# 4.15e-3), 20 steps and, labelled "setup", one step (the setup's CPU
# seconds), its floor the same at 45 points (mesh_size 0.05); labelled
# BUILD-pieces, the 20 steps with frames in pieces (no rank keeps the whole
# model), by either build.
# ONLY="block block-fine" measures those MPM scenes alone (and the floor;
# ONLY=i2-256: I2 alone).
# usage: [BEFORE=BUILD_DIR] [RANKS="1 2 4"] [METHOD=fpm] [ONLY=NAMES] [RESUME=1] benchmarks/bench-rank-memory.sh [BUILD_DIR]
bench_name=rank-memory bench_env="BEFORE RANKS METHOD ONLY RESUME"
source "$(dirname "$0")/bench-lib.sh"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
  OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_mpi_yield_when_idle=1 \
  OMP_NUM_THREADS=1
# One run under mpirun, each rank's figures into $d/time.RANK.
measure() { # LABEL BIN N NAME SCENE [--set KEY=VALUE]...
  local label=$1 b=$2 n=$3 name=$4 scene=$5 d
  shift 5
  [ -z "${ONLY:-}" ] || [ "$label" = floor ] ||
    [[ " $ONLY " == *" $name "* ]] || return 0
  d=$out/$label-$name-$n
  rm -rf "$d" && mkdir -p "$d"
  mpirun -np "$n" --bind-to none bash -c \
    'exec /usr/bin/time -v -o "$0/time.$OMPI_COMM_WORLD_RANK" "$@"' "$d" \
    "$b" run "$scene" --set time.max_steps=20 "$@" --out "$d/out" --quiet \
    >"$d/log" 2>&1 || echo "$label $name on $n: failed (see $d/log)"
  for ((r = 0; r < n; r++)); do
    printf '%-8s %-18s %s ranks, rank %d: %8s KiB %6s s %8s KiB\n' "$label" \
      "$name" "$n" "$r" "$(awk '/Maximum resident/ {print $NF}' "$d/time.$r")" \
      "$(awk '/User time/ {print $NF}' "$d/time.$r")" \
      "$(awk -v r="$r" '/"peak_rss_per_rank"/ {on = 1; k = 0; next}
        on && /\]/ {on = 0} on {if (k++ == r) printf "%d", $1 / 1024}' \
        "$d/out/summary.json" 2>/dev/null)"
  done
}
builds=("after:$bin")
[ -n "${BEFORE:-}" ] && builds=("before:$BEFORE/pointmech" "${builds[@]}")
if [ "${METHOD:-mpm}" = fpm ]; then
  f3=cases/fpm/f3-extension-60.yaml
  for n in ${RANKS:-1 2 4}; do
    measure floor "$bin" "$n" f3-45 "$f3" --set discretization.mesh_size=0.05
    for lb in "${builds[@]}"; do
      l=${lb%%:*} b=${lb#*:}
      for h in 6.42e-3 4.15e-3; do
        measure "$l" "$b" "$n" "f3-$h" "$f3" --set discretization.mesh_size=$h
        measure "$l-pieces" "$b" "$n" "f3-$h" "$f3" \
          --set discretization.mesh_size=$h --set output.ranks=pieces
        measure "$l-setup" "$b" "$n" "f3-$h" "$f3" \
          --set discretization.mesh_size=$h --set time.max_steps=1
      done
    done
  done
  exit 0
fi
fine=(--set discretization.mesh_size=1.25e-3 --set output.every=1000)
i2=(--set discretization.mesh_size=2.1e-6 --set output.every=1000)
counts=${RANKS:-1 2 4}
[ "${RESUME:-0}" = 1 ] && counts="" # (the resumes alone, below)
for n in $counts; do
  measure floor "$bin" "$n" disks cases/mpm/disks-collision.yaml
  for lb in "${builds[@]}"; do
    l=${lb%%:*} b=${lb#*:}
    measure "$l" "$b" "$n" block cases/mpm/bench-block.yaml
    [ "$l" = after ] && measure pieces "$b" "$n" block \
      cases/mpm/bench-block.yaml --set output.ranks=pieces
    measure "$l" "$b" "$n" oocyte cases/mpm/m4-oocyte-reduced.yaml
    measure "$l" "$b" "$n" block-fine cases/mpm/bench-block.yaml "${fine[@]}"
    [ "$l" = after ] && measure pieces "$b" "$n" block-fine \
      cases/mpm/bench-block.yaml "${fine[@]}" --set output.ranks=pieces
    measure "$l" "$b" "$n" i2-256 cases/mpm/i2-vessel-slice.yaml "${i2[@]}"
    [ "$l" = after ] && measure gather "$b" "$n" i2-256 \
      cases/mpm/i2-vessel-slice.yaml "${i2[@]}" --set output.ranks=gather
    measure "$l-ckpt" "$b" "$n" i2-256 cases/mpm/i2-vessel-slice.yaml \
      "${i2[@]}" --set output.checkpoint.every=5
    measure "$l-ckpt" "$b" "$n" block cases/mpm/bench-block.yaml \
      --set output.checkpoint.every=10
    measure "$l-ckpt" "$b" "$n" block-fine cases/mpm/bench-block.yaml \
      "${fine[@]}" --set output.checkpoint.every=10
  done
done
# RESUME=1, in place of the runs above (after them, with i2-256 among
# them, into the same folder): each build's checkpoint of I2 on 2 ranks
# (BUILD-ckpt, load step 5) resumed to the end on 1, 2 and 4 ranks by the
# same build, each rank's peak (the finished run's status set to
# interrupted in a copy: resume takes only a run that did not end).
[ "${RESUME:-0}" = 1 ] || exit 0
for lb in "${builds[@]}"; do
  l=${lb%%:*} b=${lb#*:}
  for n in 1 2 4; do
    d=$out/$l-resume-i2-256-$n
    rm -rf "$d" && mkdir -p "$d" && cp -r "$out/$l-ckpt-i2-256-2/out" "$d/out"
    sed -i 's/"status": "[a-z_]*"/"status": "interrupted"/' \
      "$d/out/summary.json"
    mpirun -np "$n" --bind-to none bash -c \
      'exec /usr/bin/time -v -o "$0/time.$OMPI_COMM_WORLD_RANK" "$@"' "$d" \
      "$b" resume "$d/out" --quiet >"$d/log" 2>&1 ||
      echo "$l resume on $n: failed (see $d/log)"
    for ((r = 0; r < n; r++)); do
      printf '%-8s %-18s %s ranks, rank %d: %8s KiB %6s s\n' "$l-resume" \
        i2-256 "$n" "$r" \
        "$(awk '/Maximum resident/ {print $NF}' "$d/time.$r")" \
        "$(awk '/User time/ {print $NF}' "$d/time.$r")"
    done
  done
done
