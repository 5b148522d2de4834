#!/usr/bin/env bash
# Install dependencies, build, and run every test: the optimized build runs
# the whole suite (unit + verification, runs across MPI ranks among them); a
# second build with AddressSanitizer and UndefinedBehaviorSanitizer, and
# without MPI (PM_MPI=OFF: the build that is one process whatever starts
# it), builds and runs the unit tests alone (target unit-tests, label unit).
#
# The sanitizer build keeps line tables alone (-g1): its reports name the
# file and line of every frame, as with -g, and it builds in 156 CPU
# seconds instead of 180.
#
# The sanitizer build and its unit tests run beside the optimized build and
# its tests, at the lowest priority (nice 19): those leave part of the two
# cores idle (the serial configure and links, single-threaded stretches of
# tests that hold both cores, signals awaited, files polled), and a job at
# nice 19 takes only what they leave.  The sanitizer build's timeouts are
# wall time, five times the optimized build's, so that a test kept waiting
# for its share does not time out.  Whatever of them is left when the
# optimized build's tests end runs alone, and then the optimized build's
# runs across MPI ranks (below).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)

./scripts/install-deps.sh

# The sanitizer build and its tests in the background, in their own
# process group (setsid), stopped with everything they started if the
# script stops first.  A new session is a new scheduling group where the
# kernel groups by session (autogroup, /proc/sys/kernel/sched_autogroup_
# enabled): nice then orders processes only within the group, and the
# groups share the cores equally.  The group's own nice is set to 19 as
# well, so that it takes only what the optimized side leaves (without it
# the sanitizer build took half the cores from the optimized build, which
# took about 190 s instead of 80, and from the first tests beside it).
mkdir -p build-sanitize
san_log=build-sanitize/build.log
san_tests=build-sanitize/tests.log
setsid -w bash -c "
  echo 19 >/proc/self/autogroup 2>/dev/null || true
  nice -n 19 cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_C_FLAGS_DEBUG=-g1 -DCMAKE_CXX_FLAGS_DEBUG=-g1 \
    -DPM_SANITIZE=ON -DPM_VERIFICATION=OFF -DPM_MPI=OFF \
    -DPM_WARNINGS_AS_ERRORS=ON >'$san_log' 2>&1 &&
  nice -n 19 cmake --build build-sanitize -j$jobs --target unit-tests \
    >>'$san_log' 2>&1 || exit 90
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 nice -n 19 \
    ctest --test-dir build-sanitize --output-on-failure -L unit -j$jobs \
    >'$san_tests' 2>&1" &
san=$!
trap 'kill -- -$san 2>/dev/null || true' EXIT

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPM_WARNINGS_AS_ERRORS=ON
cmake --build build -j"$jobs"
# The runs across MPI ranks last, once the sanitizer side is done: their
# ranks step in lockstep, and a rank that waits for another yields its
# core (mpi_yield_when_idle, for runs of more ranks than cores), to
# whatever else is ready, however low its priority, for a scheduler tick.
# Beside the sanitizer tests `verification.ranks_fpm` took 105 s; alone,
# 65.
lockstep='^verification[.]ranks'
rc=0
ctest --test-dir build --output-on-failure -j"$jobs" -E "$lockstep" || rc=$?

san_rc=0
wait $san || san_rc=$?
trap - EXIT
ctest --test-dir build --output-on-failure -j"$jobs" -R "$lockstep" || rc=$?

cat "$san_log"
if [ "$san_rc" -eq 90 ]; then
  echo "test.sh: the sanitizer build failed" >&2
  exit 1
fi
cat "$san_tests"
if [ "$rc" -ne 0 ]; then
  echo "test.sh: the optimized build's tests failed (ctest exit $rc)" >&2
  exit "$rc"
fi
if [ "$san_rc" -ne 0 ]; then
  echo "test.sh: the sanitizer build's unit tests failed (ctest exit $san_rc)" >&2
  exit "$san_rc"
fi
