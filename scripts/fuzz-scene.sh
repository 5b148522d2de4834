#!/usr/bin/env bash
# Fuzz the scene loader: build tests/fuzz/fuzz_scene.c with clang, libFuzzer,
# AddressSanitizer and UndefinedBehaviorSanitizer in build-fuzz/, then run
# one campaign job seeded from cases/ and tests/fuzz/corpus/ with a
# dictionary of the scene vocabulary (from `pointmech keys`).
#
#   scripts/fuzz-scene.sh [SECONDS | -runs=N] [LIBFUZZER OPTION]...
#
# New inputs go to build-fuzz/fuzz-corpus/; crashes, leaks and hangs to
# build-fuzz/findings/.  To fold a campaign back into the small replayed
# corpus: build-fuzz/tests/fuzz_scene -merge=1 NEWDIR tests/fuzz/corpus
# build-fuzz/fuzz-corpus, then replace tests/fuzz/corpus with NEWDIR.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang >/dev/null || {
  echo "clang is not installed (Debian: apt-get install clang)" >&2
  exit 1
}
limit=${1:-600}
shift || true
case $limit in
-runs=*) budget=$limit ;;
*[!0-9]* | '')
  echo "usage: $0 [SECONDS | -runs=N] [LIBFUZZER OPTION]..." >&2
  exit 1
  ;;
*) budget=-max_total_time=$limit ;;
esac

build=build-fuzz
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DPM_FUZZ=ON -DPM_OPENMP=OFF -DPM_VERIFICATION=OFF >/dev/null
cmake --build "$build" -j"${PM_FUZZ_BUILD_JOBS:-1}" --target fuzz_scene pointmech

# Seeds: every scene of cases/ and tests/data/, the replayed corpus, and
# the scenes with override lines (after a NUL byte) of tests/fuzz/seeds.
seeds=$build/fuzz-seeds
corpus=$build/fuzz-corpus
findings=$build/findings
mkdir -p "$seeds" "$corpus" "$findings"
find cases tests/data/scenes -name '*.yaml' -exec cp {} "$seeds"/ \;
bash tests/fuzz/seeds.sh "$seeds"

# The dictionary: every key name and every name a key takes, the
# expression functions and YAML's own tokens.
dict=$build/scene.dict
{
  "$build/pointmech" keys |
    grep -oE '^[a-z0-9_.N]+' | tr '.' '\n' | grep -vE '^(N|)$' | sort -u |
    sed 's/.*/"&:"/'
  "$build/pointmech" keys | grep -oE 'one of [a-z0-9_, -]+' |
    sed 's/^one of //' | tr ',' '\n' | tr -d ' ' | grep -v '^$' | sort -u |
    sed 's/.*/"&"/'
  for w in sqrt exp log sin cos tan asin acos atan sinh cosh tanh abs step \
    delta nandelta erf pi e x y z t; do echo "\"$w\""; done
  for w in '{' '}' '[' ']' ': ' '- ' '&a ' '*a' '!!str ' '---' '...' '"' \
    "'" '=' '\x00' '.nan' '.inf' '-.inf' 'nan' 'inf' '1e999' '1/0' '^' '('; do
    echo "\"$w\""
  done
} >"$dict"

export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
exec "$build/tests/fuzz_scene" "$budget" -max_len=16384 \
  -timeout=10 -rss_limit_mb=2048 -dict="$dict" -print_final_stats=1 \
  -artifact_prefix="$findings/" "$@" "$corpus" "$seeds" tests/fuzz/corpus
