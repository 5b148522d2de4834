#!/usr/bin/env bash
# Fuzz one reader: build tests/fuzz/fuzz_TARGET.c with clang, libFuzzer,
# AddressSanitizer and UndefinedBehaviorSanitizer in build-fuzz/, then run
# one campaign job seeded from the project's own files of that kind
# (cases/, tests/data/, /work/shared/data where present) and the replayed
# corpus.
#
#   scripts/fuzz.sh TARGET [SECONDS | -runs=N] [LIBFUZZER OPTION]...
#
# TARGET: scene (the scene loader and --set overrides), tiff (TIFF
# stacks), raw (raw volumes), points (point clouds and voxel centres),
# table (CSV tables: FE ladders, lattices, tolerances, history.csv), gmsh
# (.msh volume and surface meshes), checkpoint (checkpoint.h5), index (the
# results folder `resume` reads), pipe (what a child reading a file passes
# back, pm_isolate.h).
#
# gmsh, checkpoint and index run as the program reads such files: the
# library in a child (gmsh initialized once before the children, HDF5's
# child limited to about a CPU second), the project's code on what the
# child passed back or vetted in the fuzzer's process, where any crash,
# leak, sanitizer report or hang is the program's; libFuzzer's ordinary
# mode.  With PM_ISOLATE=0 in the environment they read in the fuzzer's
# process instead (coverage and the sanitizers then see the readers' own
# code), in libFuzzer's fork mode, which goes on past a crash: libgmsh and
# libhdf5 stop on some inputs by themselves (tests/fuzz/upstream/).  The
# other readers run in the fuzzer's process.
#
# New inputs go to build-fuzz/corpus-TARGET/ (with PM_ISOLATE=0, to
# build-fuzz/corpus-TARGET-screened/, the inputs that read through in the
# process alone; see below); crashes, leaks and hangs to
# build-fuzz/findings-TARGET/ (triage: build-fuzz/tests/fuzz_TARGET FILE
# prints the stack; a crash wholly inside libgmsh or libhdf5 goes to
# tests/fuzz/upstream/TARGET/, one in the project's code is fixed and its
# input goes to tests/fuzz/regressions/TARGET/).  To fold a campaign back into the small
# replayed corpus (tests/fuzz/corpus-TARGET, tests/fuzz/corpus for the
# scene): build-fuzz/tests/fuzz_TARGET -merge=1 NEWDIR CORPUS
# build-fuzz/corpus-TARGET, then replace CORPUS with NEWDIR.
set -euo pipefail
cd "$(dirname "$0")/.."
usage() {
  echo "usage: $0 scene|tiff|raw|points|table|gmsh|checkpoint|index|pipe" \
    "[SECONDS | -runs=N] [LIBFUZZER OPTION]..." >&2
  exit 1
}
target=${1:-}
case $target in
scene | tiff | raw | points | table | gmsh | checkpoint | index | pipe) ;;
*) usage ;;
esac
shift
command -v clang >/dev/null || {
  echo "clang is not installed (Debian: apt-get install clang)" >&2
  exit 1
}
limit=${1:-600}
shift || true
case $limit in
-runs=*) budget=$limit ;;
*[!0-9]* | '') usage ;;
*) budget=-max_total_time=$limit ;;
esac

build=build-fuzz
mkdir -p "$build"
# The program makes the scene's dictionary and the run whose checkpoint
# and results seed those targets.
targets=("fuzz_$target")
case $target in scene | checkpoint | index) targets+=(pointmech) ;; esac
# Campaigns started together configure and build one at a time (two
# configurations of one folder at once break each other's files).
(
  flock 9
  CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DPM_FUZZ=ON -DPM_OPENMP=OFF -DPM_VERIFICATION=OFF >/dev/null
  cmake --build "$build" -j"${PM_FUZZ_BUILD_JOBS:-1}" --target "${targets[@]}"
) 9>"$build/.build.lock"

seeds=$build/seeds-$target
corpus=$build/corpus-$target
findings=$build/findings-$target
replayed=tests/fuzz/corpus-$target
[ "$target" = scene ] && replayed=tests/fuzz/corpus
rm -rf "$seeds"
mkdir -p "$seeds" "$corpus" "$findings"
bash tests/fuzz/seeds.sh "$target" "$seeds" "$build/pointmech"

# The largest input: past it a reader's time goes to sizes no seed has
# (gmsh and HDF5 parse whole files; a scene is short text).
max_len=16384
extra=()
case $target in
scene)
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
  extra+=(-dict="$dict")
  ;;
checkpoint | index) max_len=81920 ;;
pipe) max_len=4096 ;;
gmsh) max_len=8192 ;;
esac

timeout=10
case $target in
gmsh | checkpoint | index)
  if [ "${PM_ISOLATE:-}" = 0 ]; then
    # In the process: libgmsh 4.8 and libhdf5 1.10 stop on some inputs by
    # themselves (tests/fuzz/upstream/): the campaign runs in a child of
    # libFuzzer's that is restarted after a crash, a leak, a hang or
    # running out of memory, and each finding is kept in
    # build-fuzz/findings-TARGET/ for triage by its stack.
    extra+=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
    screen=1
    # Inputs of at most 80 kB: no reader needs an allocation past a few
    # MB (a damaged file's announced blocks, zeroed page by page, cost
    # most of such an input), and a small quarantine of freed memory keeps
    # the pages the process touches few.  A loop of libhdf5 (a damaged
    # global heap) is cut after 3 s, not 10: an input takes milliseconds.
    # Together: 54 inputs a second on two jobs, against 30 (the index).
    alloc_mb=64
    asan=:quarantine_size_mb=16
    timeout=3
  else
    # As the program reads: an input may start a dozen children (the
    # results folder's files vetted one after the other), each allowed
    # about a CPU second (PM_ISOLATE_CPU_SECONDS, fuzz_isolate).
    timeout=60
    # A child that dies with a sanitizer's report is a refusal; its input
    # is kept as findings-TARGET/child-PID, for triage by its report.
    export PM_FUZZ_CHILD_FINDINGS=$PWD/$findings
    # A fork copies the page tables of what the process holds: a small
    # quarantine of freed memory keeps that small (13 against 20 ms of CPU
    # a checkpoint).
    asan=:quarantine_size_mb=16
    # Inputs of at most 80 kB need no allocation past a few MB (see
    # ASAN_OPTIONS below).
    alloc_mb=64
    # gmsh runs only in the children, whose leaks end with them: the
    # fuzzer's process may unwind allocations by frame pointers.
    [ "$target" = gmsh ] && unwind=1
  fi
  ;;
scene | tiff | raw | points | table) export PM_ISOLATE=0 ;;
pipe) unwind=1 ;; # no library reads in its process
esac
# A child reading HDF5 may allocate at most 1 GB at once: under
# AddressSanitizer no address-space limit holds (pm_isolate_memory_limit),
# so its allocator refuses what a damaged file announces.  The isolated
# targets' inputs are at most 80 kB, which no reader needs more than a few
# MB for: there the bound is 64 MB (what libhdf5 calloc'ed for a damaged
# file's announced blocks, zeroed page by page at this machine's price of
# a page fault, was most of an input's cost).
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1:max_allocation_size_mb=${alloc_mb:-1024}${asan:-}
# What the distribution's libraries leak by themselves (tests/lsan.supp),
# matched on whole stacks (libgmsh and libhdf5 keep no frame pointers).
export LSAN_OPTIONS=suppressions=$PWD/tests/lsan.supp:fast_unwind_on_malloc=${unwind:-0}
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
dirs=("$corpus" "$seeds" "$replayed")
if [ "${screen:-}" = 1 ]; then
  # In the process, an input of the corpus that stops libgmsh or libhdf5
  # by itself (a replayed input the program refuses in its child, say)
  # would stop every job of the fork mode that draws it, and the campaign
  # would spend its time restarting jobs (3 inputs a second, against 54).
  # The jobs draw from the inputs that read through alone: each is read
  # once in a process of its own, and those that stop it are left out.
  screened=$build/corpus-$target-screened
  mkdir -p "$screened"
  kept=0 left=0
  for f in "$corpus"/* "$seeds"/* "$replayed"/*; do
    [ -f "$f" ] || continue
    [ -f "$screened/${f##*/}" ] && continue
    if timeout $((timeout + 2)) "$build/tests/fuzz_$target" -timeout=$timeout \
      "$f" >/dev/null 2>&1; then
      cp "$f" "$screened/"
      kept=$((kept + 1))
    else
      left=$((left + 1))
    fi
  done
  echo "fuzz: $kept new inputs screened in, $left left out (they stop" \
    "the library in the process); corpus $screened" >&2
  dirs=("$screened")
fi
exec "$build/tests/fuzz_$target" "$budget" -max_len=$max_len \
  -timeout=$timeout -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$findings/" "${extra[@]}" "$@" "${dirs[@]}"
