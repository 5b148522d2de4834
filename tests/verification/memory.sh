#!/usr/bin/env bash
# Scenes sized past the machine are refused before anything is allocated:
# exit status 1 within seconds, the message naming the estimated and the
# available bytes and where the available figure comes from, no output;
# --force-memory is accepted and overrides the refusal (shown on a small
# scene under a POINTMECH_MEMORY_LIMIT cap, never on a huge one).
set -u
bin=$1
src=$2
fpm=$src/cases/fpm/f2-unconstrained-compression.yaml
mpm=$src/cases/mpm/f2-unconstrained-compression.yaml
tube=$src/cases/mpm/m2-shock-tube.yaml
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"

# Refused quickly (at most 5 s: setup at these sizes would take hours and
# terabytes), both figures in bytes, their source, nothing written.
too_big() { # label, out, command...
  local label=$1 out=$2
  shift 2
  local t0 t1
  t0=$(date +%s.%N)
  refused "$label" "is available" "$out" "$@"
  t1=$(date +%s.%N)
  check "$label: refused in $(echo "$t1 - $t0" | bc) s (at most 5 s)" \
    test "$(echo "$t1 - $t0 <= 5" | bc)" -eq 1
  check "$label: names the estimate in bytes" \
    grep -Eq "needs an estimated [0-9.]+ [KMGTP]?i?B \([0-9]+ bytes, [0-9]+ points\)" "$work/err"
  check "$label: names the available bytes and their source" \
    grep -Eq "but [0-9.]+ [KMGTP]?i?B \([0-9]+ bytes\) is available \((MemAvailable in /proc/meminfo|the cgroup limit|POINTMECH_MEMORY_LIMIT)" "$work/err"
  check "$label: names the override" grep -q -- "--force-memory" "$work/err"
}

# FPM at mesh size 1e-4 on the 0.1 m block: 1e9 points.
too_big "FPM run, mesh size 1e-4" "$work/out-fpm" \
  "$bin" run "$fpm" --set discretization.mesh_size=1e-4 --out "$work/out-fpm" --quiet
too_big "FPM plan, mesh size 1e-4" "$work/none" \
  "$bin" plan "$fpm" --set discretization.mesh_size=1e-4
# A study refuses before its first level runs.
too_big "FPM convergence, a level at mesh size 1e-4" "$work/out-study" \
  "$bin" convergence "$fpm" --set-ladder discretization.mesh_size=8.72e-3,1e-4 \
  --reference analytic --set time.max_steps=2 --out "$work/out-study" --quiet
# MPM at cell size 1e-5: 8e12 particles.
too_big "MPM run, cell size 1e-5" "$work/out-mpm" \
  "$bin" run "$mpm" --set discretization.mesh_size=1e-5 --out "$work/out-mpm" --quiet

# A static solve counts its tangent's factors: F2 at 1851 points by LU
# peaks at 379 MiB (docs/validation.md), so a 200 MiB cap refuses it before
# meshing, where the same scene by dynamic relaxation (no factors) runs
# under it; implicit MPM's grid solve likewise (I2 peaks at 197 MiB).
POINTMECH_MEMORY_LIMIT=200M refused "static F2, capped at 200 MiB" \
  "POINTMECH_MEMORY_LIMIT=200M" "$work/out-static" "$bin" run "$fpm" \
  --set time.quasi_static.method=static --out "$work/out-static" --quiet
POINTMECH_MEMORY_LIMIT=200M "$bin" plan "$fpm" >/dev/null 2>"$work/err"
check "F2 by dynamic relaxation under a 200 MiB cap: planned" test $? -eq 0
POINTMECH_MEMORY_LIMIT=150M refused "I2 implicit MPM, capped at 150 MiB" \
  "POINTMECH_MEMORY_LIMIT=150M" "$work/out-i2" "$bin" run \
  "$src/cases/mpm/i2-vessel-slice.yaml" --out "$work/out-i2" --quiet
# A cap below a small scene's estimate refuses it, naming the cap; with
# --force-memory it is planned and run.
POINTMECH_MEMORY_LIMIT=1M refused "capped at 1 MiB" "POINTMECH_MEMORY_LIMIT=1M" \
  "$work/out-cap" "$bin" run "$mpm" --set time.max_steps=2 --out "$work/out-cap" --quiet
POINTMECH_MEMORY_LIMIT=1M "$bin" plan "$mpm" --force-memory >"$work/plan" 2>"$work/err"
rc=$?
check "--force-memory: plan exit 0 (got $rc)" test $rc -eq 0
check "--force-memory: the plan prints the estimate beside the measured memory" \
  grep -Eq "^memory est\. +[0-9.]+ [KMG]iB before setup.*1.0 MiB available \(POINTMECH_MEMORY_LIMIT=1M" "$work/plan"
POINTMECH_MEMORY_LIMIT=1M "$bin" run "$tube" --force-memory --set time.max_steps=2 \
  --out "$work/out-forced" --quiet >/dev/null 2>"$work/err"
rc=$?
check "--force-memory: run exit 0 (got $rc)" test $rc -eq 0
check "--force-memory: summary written" test -s "$work/out-forced/summary.json"
check "--force-memory: listed in --help" \
  bash -c "'$bin' --help | grep -q -- --force-memory"
POINTMECH_MEMORY_LIMIT=lots "$bin" plan "$mpm" >/dev/null 2>"$work/err"
rc=$?
check "bad POINTMECH_MEMORY_LIMIT: exit 1 (got $rc)" test $rc -eq 1
check "bad POINTMECH_MEMORY_LIMIT: named" grep -q 'got "lots"' "$work/err"

echo "$passes passed, $failures failed"
[ $failures -eq 0 ]
