#!/usr/bin/env bash
# The test suite's cost, test by test: each test run alone by CTest, its
# wall and CPU seconds (user + sys of its whole process tree) and the cores
# it kept busy on average, beside the PROCESSORS and COST CTest gives it.
# Usage: benchmarks/suite-cost.sh [BUILD] [REGEX]  (default build, every test)
# Prints a Markdown table; a test whose cores busy stay well under its
# PROCESSORS holds a core of `ctest -j2` it does not use.  The CPU seconds
# stand on a shared machine; the wall seconds and cores busy only alone.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
regex=${2:-.}
py=/usr/bin/python3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# name, PROCESSORS and COST of every test matching REGEX
ctest --test-dir "$build" -R "$regex" --show-only=json-v1 >"$tmp/tests.json"
$py - "$tmp/tests.json" >"$tmp/list" <<'PY'
import json, sys
for t in json.load(open(sys.argv[1]))["tests"]:
    p = {q["name"]: q["value"] for q in t.get("properties", [])}
    print(t["name"], p.get("PROCESSORS", 1), p.get("COST", 0))
PY

echo "measured $(date -u '+%Y-%m-%d %H:%M') UTC, commit" \
  "$(git rev-parse --short HEAD)$(git diff --quiet HEAD || echo -dirty)," \
  "$(nproc) cores, load $(cut -d' ' -f1 /proc/loadavg): $0 $build '$regex'"
echo
echo "| test | result | wall s | CPU s | cores busy | PROCESSORS | COST |"
echo "|---|---|---|---|---|---|---|"
while read -r name procs cost; do
  rc=0
  /usr/bin/time -f "%e %U %S" -o "$tmp/time" \
    ctest --test-dir "$build" -R "^${name//./\\.}\$" >"$tmp/log" 2>&1 || rc=$?
  read -r wall user sys <"$tmp/time"
  result=passed
  [ "$rc" -eq 0 ] || result=FAILED
  awk -v n="$name" -v r="$result" -v w="$wall" -v u="$user" -v s="$sys" \
    -v p="$procs" -v c="$cost" 'BEGIN {
      printf "| %s | %s | %.1f | %.1f | %.2f | %s | %s |\n",
        n, r, w, u + s, (w > 0 ? (u + s) / w : 0), p, c }'
done <"$tmp/list"
