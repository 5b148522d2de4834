#!/usr/bin/env bash
# Install dependencies, build, and run every test: the optimized build runs
# the whole suite (unit + verification, runs across MPI ranks among them); a
# second build with AddressSanitizer and UndefinedBehaviorSanitizer, and
# without MPI (PM_MPI=OFF: the build that is one process whatever starts
# it), builds and runs the unit tests alone (target unit-tests, label unit).
#
# The sanitizer build compiles at the lowest priority (nice 19) from the
# start, beside the optimized build and its tests: those leave part of the
# two cores idle (the serial configure and links, single-threaded
# stretches of tests that hold both cores, signals awaited, files polled),
# and a compiler at nice 19 takes only what they leave.  Its unit tests run
# after the optimized build's, at normal priority (their timeouts are wall
# time).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)

./scripts/install-deps.sh

# The sanitizer build in the background, in its own process group (setsid),
# stopped with everything it started if the script stops first.
mkdir -p build-sanitize
san_log=build-sanitize/build.log
setsid -w nice -n 19 bash -c "
  cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug -DPM_SANITIZE=ON \
    -DPM_VERIFICATION=OFF -DPM_MPI=OFF -DPM_WARNINGS_AS_ERRORS=ON &&
  cmake --build build-sanitize -j$jobs --target unit-tests" >"$san_log" 2>&1 &
san=$!
trap 'kill -- -$san 2>/dev/null || true' EXIT

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPM_WARNINGS_AS_ERRORS=ON
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"

san_rc=0
wait $san || san_rc=$?
trap - EXIT
cat "$san_log"
if [ "$san_rc" -ne 0 ]; then
  echo "test.sh: the sanitizer build failed (exit $san_rc)" >&2
  exit "$san_rc"
fi
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-sanitize --output-on-failure -L unit -j"$jobs"
