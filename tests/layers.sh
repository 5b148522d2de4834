#!/usr/bin/env bash
# The layers hold (docs/architecture.md): the core of each method includes
# no MPI, no rank code and nothing above it; the ranks layer nothing of the
# backends; src/common and geometry neither method; and no source file is
# over 600 lines (C sources, Python tools) but the single-subject tables
# named here.
set -u
cd "$1"
bad=0
fail() { echo "$1"; bad=$((bad + 1)); }

# headers of a folder set, as an alternation for grep -E
names() { find "$@" -name '*.h' -printf '%f\n' 2>/dev/null | sed 's/\./\\./g' | paste -sd'|'; }

check() { # check LABEL PATTERN FILES...: no file includes a header matching PATTERN
  # (one grep for all the files: one a file took most of the test's time)
  local label=$1 pat=$2; shift 2
  [ -n "$pat" ] && [ $# -gt 0 ] || return 0
  grep -HnE "^#include [<\"]($pat)[>\"]" "$@" | while IFS= read -r l; do
    echo "$label: $l"
  done
}

mpi='mpi\.h|petscsf\.h|petscdm[a-z]*\.h|pm_par\.h|pm_par_mpi\.h|pm_halo\.h'
out=$(
  # the physics cores: no MPI, no rank code, nothing of the layers above
  mcore=$(find src/mpm/core src/mpm/step src/mpm/implicit src/mpm/kinds -name '*.[ch]' 2>/dev/null)
  check "MPM core reaches MPI or ranks" "$mpi|$(names src/mpm/ranks src/mpm/backend)" $mcore
  fcore=$(find src/fpm/core -name '*.[ch]' 2>/dev/null)
  check "FPM core reaches MPI or ranks" "$mpi|$(names src/fpm/ranks src/fpm/backend)" $fcore
  # the ranks layers: nothing of the backends
  check "MPM ranks include a backend" "$(names src/mpm/backend)" $(find src/mpm/ranks -name '*.[ch]' 2>/dev/null)
  check "FPM ranks include a backend" "$(names src/fpm/backend)" $(find src/fpm/ranks -name '*.[ch]' 2>/dev/null)
  # the methods never know each other; src/common and geometry neither
  check "FPM includes MPM" "$(names src/mpm)" $(find src/fpm -name '*.[ch]')
  check "MPM includes FPM" "$(names src/fpm)" $(find src/mpm -name '*.[ch]')
  check "common includes a method" "$(names src/fpm src/mpm src/cli src/api include)" $(find src/common geometry -name '*.[ch]' -o -name '*.cpp')
)
[ -n "$out" ] && { echo "$out"; bad=$((bad + $(echo "$out" | wc -l))); }

# one subject a file (the C sources and the Python tools): the tables
# allowed past 600 lines
tables=" src/common/scene/pm_scene_vocab.c "
while read -r n f; do
  if [ "$n" -gt 600 ] && [[ "$tables" != *" $f "* ]]; then
    fail "over 600 lines: $f ($n)"
  fi
done < <(find src geometry tools \( -name '*.[ch]' -o -name '*.cpp' \
  -o -name '*.py' \) -exec wc -l {} + | grep -v ' total$')
n=$(find src geometry tools -name '*.[ch]' -o -name '*.cpp' -o -name '*.py' |
  wc -l)
echo "$((n - bad)) passed, $bad failed"
[ $bad -eq 0 ]
