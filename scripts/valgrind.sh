#!/usr/bin/env bash
# Valgrind's memcheck over every unit test and a short run of each method
# (FPM explicit, FPM static, MPM solid, MPM fluid), in a build of its own
# without sanitizers (build-valgrind, RelWithDebInfo).  Suppressions
# (tests/valgrind.supp) cover third-party libraries only.  Prints, per
# program, the errors and the bytes definitely and indirectly lost, and exits
# 1 if any program has an error or a leak.
#
# usage: scripts/valgrind.sh [PROGRAM-NAME-PATTERN]   (e.g. test_mpm, run-)
set -uo pipefail
cd "$(dirname "$0")/.."
command -v valgrind >/dev/null || {
  echo "valgrind is not installed (Debian: apt-get install valgrind)" >&2
  exit 1
}
root=$PWD
build=${PM_VALGRIND_BUILD:-$root/build-valgrind}
pattern=${1:-}
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPM_SANITIZE=OFF \
  -DPM_VERIFICATION=OFF -DPM_WARNINGS_AS_ERRORS=ON >/dev/null || exit 1
cmake --build "$build" -j"$jobs" >/dev/null || exit 1

logs=$build/valgrind
rm -rf "$logs"
mkdir -p "$logs"
# Memcheck runs one thread at a time; one OpenMP thread keeps the runs short
# and the passive wait policy keeps idle threads from spinning.
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} OMP_WAIT_POLICY=passive

vg() { # name, command...
  local name=$1
  shift
  [ -n "$pattern" ] && [[ $name != *$pattern* ]] && return 0
  local t0=$SECONDS
  valgrind --tool=memcheck --leak-check=full \
    --show-leak-kinds=definite,indirect --errors-for-leak-kinds=definite,indirect \
    --track-origins=yes --num-callers=40 --error-exitcode=42 \
    --suppressions="$root/tests/valgrind.supp" --gen-suppressions=all \
    --log-file="$logs/$name.log" "$@" >"$logs/$name.out" 2>&1
  local rc=$?
  echo "$name $rc $((SECONDS - t0))" >>"$logs/status"
}

# Every unit test, from its ctest working directory.
for t in "$build"/tests/test_*; do
  [ -x "$t" ] || continue
  (cd "$build/tests" && vg "$(basename "$t")" "$t")
done

# A short run of each method: a few steps of a coarse scene, on two threads
# (the per-thread accumulators and colour sweeps), one at a time under
# memcheck.
bin=$build/pointmech
f2=$root/cases/fpm/f2-unconstrained-compression.yaml
OMP_NUM_THREADS=2 vg run-fpm-explicit "$bin" run --overwrite "$f2" --set discretization.mesh_size=0.02 \
  --set time.max_steps=40 --set output.every=20 --out "$logs/out-fpm-explicit" --quiet
# A checkpoint, and the run resumed from it (the summary as if interrupted).
OMP_NUM_THREADS=2 vg run-fpm-checkpoint "$bin" run --overwrite "$f2" \
  --set discretization.mesh_size=0.02 --set time.max_steps=40 \
  --set output.checkpoint.every=15 --out "$logs/out-fpm-checkpoint" --quiet
sed -i 's/"status": "[a-z-]*"/"status": "interrupted"/' "$logs/out-fpm-checkpoint/summary.json"
OMP_NUM_THREADS=2 vg resume-fpm "$bin" resume "$logs/out-fpm-checkpoint" --quiet
OMP_NUM_THREADS=2 vg run-fpm-static "$bin" run --overwrite "$f2" --set discretization.mesh_size=0.02 \
  --set time.quasi_static.method=static --set time.quasi_static.load_steps=2 \
  --set time.quasi_static.tolerance=1e-6 --out "$logs/out-fpm-static" --quiet
OMP_NUM_THREADS=2 vg run-mpm-solid "$bin" run --overwrite "$root/cases/mpm/f2-unconstrained-compression.yaml" \
  --set discretization.mesh_size=0.02 --set time.max_steps=20 \
  --set output.every=10 --out "$logs/out-mpm-solid" --quiet
OMP_NUM_THREADS=2 vg run-mpm-fluid "$bin" run --overwrite "$root/cases/mpm/m2-shock-tube.yaml" \
  --set time.max_steps=20 --set output.every=10 --out "$logs/out-mpm-fluid" --quiet

# Summary: a program fails on an error or on a definite or indirect leak
# (valgrind's own exit status, 42, says the same).
bytes() { # log, kind
  local v
  v=$(grep -E "$2 lost: " "$1" | tail -1 | sed -E 's/.*lost: ([0-9,]+) bytes.*/\1/' | tr -d ,)
  echo "${v:-0}"
}
printf '%-22s %7s %12s %12s %6s  %s\n' program errors definitely indirectly secs status
failed=0
while read -r name rc secs; do
  log=$logs/$name.log
  errors=$(grep -E "ERROR SUMMARY: " "$log" | tail -1 | sed -E 's/.*SUMMARY: ([0-9,]+) errors.*/\1/' | tr -d ,)
  def=$(bytes "$log" definitely)
  ind=$(bytes "$log" indirectly)
  status=ok
  if [ "${errors:-1}" != 0 ] || [ "$def" != 0 ] || [ "$ind" != 0 ] || [ "$rc" = 42 ]; then
    status=FAIL
    failed=1
  fi
  # A run may end with its own status (3: not converged); memcheck's is 42.
  printf '%-22s %7s %12s %12s %6s  %s (exit %s)\n' "$name" "${errors:-?}" "$def" "$ind" "$secs" "$status" "$rc"
done <"$logs/status"
echo "logs in $logs"
exit $failed
