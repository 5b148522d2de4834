#!/bin/bash
# Two builds side by side on every scene of cases/ (a refactoring's check:
# the figures of the program must not change): each scene a few steps on one
# thread (40 steps, a frame every 10, static solves in 2 load steps; the
# full-size I1, M2 and M4 left out), the static FPM solver on F2 and F3 60%,
# and FPM, the shock tube, M5 and I2 on 2 MPI ranks, by both builds; then
# every run's frames, history rows and summary figures compared bit for bit
# (same-builds.py), and the instructions of the FPM time loop (fpm_run, F2,
# 200 steps) and of the MPM step (mpm_step, the 3-D block, 20 steps) counted
# by callgrind for each build.
# usage: benchmarks/same-builds.sh BUILD_BEFORE BUILD_AFTER   (about 15 min)
bench_name=same-builds bench_env=""
source "$(dirname "$0")/bench-lib.sh"
before=$1 after=${2:?usage: benchmarks/same-builds.sh BUILD_BEFORE BUILD_AFTER}
export OMP_NUM_THREADS=1 GOMP_SPINCOUNT=3000
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_mpi_yield_when_idle=1
few=(--set time.max_steps=40 --set output.every=10
  --set time.quasi_static.load_steps=2)
np2=(mpirun -np 2 --bind-to none)
runs() { # BUILD DIR
  local p=$1/pointmech d=$2 f n
  for f in cases/fpm/*.yaml cases/mpm/*.yaml; do
    n=$(basename "$(dirname "$f")")-$(basename "$f" .yaml)
    case $n in mpm-i1-construct | mpm-m4-oocyte | mpm-m2-shock-tube) continue ;; esac
    bench_run "$d/$n" "$f" "${few[@]}" || true
  done
  bench_run "$d/fpm-f2-static" cases/fpm/f2-unconstrained-compression.yaml \
    --set time.quasi_static.method=static --set time.quasi_static.load_steps=4 || true
  bench_run "$d/fpm-f3-60-static" cases/fpm/f3-extension-60.yaml \
    --set discretization.mesh_size=8.72e-3 --set time.quasi_static.method=static \
    --set time.quasi_static.load_steps=4 || true
  "${np2[@]}" "$p" run cases/fpm/f2-unconstrained-compression.yaml "${few[@]}" \
    --out "$d/fpm-f2-np2" --overwrite >"$d/fpm-f2-np2.log" 2>&1 || true
  for n in m2-shock-tube-reduced m5-gas-dogbone i2-vessel-slice; do
    "${np2[@]}" "$p" run "cases/mpm/$n.yaml" "${few[@]}" \
      --out "$d/mpm-$n-np2" --overwrite >"$d/mpm-$n-np2.log" 2>&1 || true
  done
}
count() { # BUILD FUNCTION OUT SCENE STEPS
  valgrind --tool=callgrind --collect-atstart=no --toggle-collect="$2" \
    --callgrind-out-file="$3.cg" "$1/pointmech" run "$4" --out "$3" \
    --overwrite --set time.max_steps="$5" --set output.every=1000000 \
    >"$3.log" 2>&1 || true
  callgrind_annotate "$3.cg" 2>/dev/null | sed -n 's/^ *\([0-9,]*\) .*PROGRAM TOTALS.*/\1/p'
}
for side in before after; do
  build=${!side}
  bin=$build/pointmech
  runs "$build" "$out/$side"
done
$py "$(dirname "$0")/same-builds.py" "$out/before" "$out/after" || true
printf '%-34s %18s %18s\n' "instructions (callgrind)" before after
for k in "fpm_run cases/fpm/f2-unconstrained-compression.yaml 200" \
  "mpm_step cases/mpm/bench-block.yaml 20"; do
  set -- $k
  printf '%-34s %18s %18s\n' "$1, $(basename "$2" .yaml), $3 steps" \
    "$(count "$before" "$1" "$out/cg-before-$1" "$2" "$3")" \
    "$(count "$after" "$1" "$out/cg-after-$1" "$2" "$3")"
done
