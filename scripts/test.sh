#!/usr/bin/env bash
# Install dependencies, build, and run every test: the optimized build runs
# the whole suite (unit + verification, runs across MPI ranks among them); a
# second build with AddressSanitizer and UndefinedBehaviorSanitizer, and
# without MPI (PM_MPI=OFF: the build that is one process whatever starts
# it), builds and runs the unit tests alone (target unit-tests, label unit).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)

./scripts/install-deps.sh

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPM_WARNINGS_AS_ERRORS=ON
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"

cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug -DPM_SANITIZE=ON \
  -DPM_VERIFICATION=OFF -DPM_MPI=OFF -DPM_WARNINGS_AS_ERRORS=ON
cmake --build build-sanitize -j"$jobs" --target unit-tests
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-sanitize --output-on-failure -L unit -j"$jobs"
