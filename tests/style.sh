#!/usr/bin/env bash
# Every C source (and the C++ of geometry/cgal) is formatted with the
# repository's .clang-format.
set -u
cd "$1"
files=$(ls src/*/*.[ch] src/*/*/*.[ch] src/*/*/*/*.[ch] geometry/*.[ch] geometry/cgal/*.cpp \
  tests/*/*.[ch] 2>/dev/null)
bad=0
for f in $files; do
  if ! clang-format --dry-run --Werror "$f" >/dev/null 2>&1; then
    echo "not formatted: $f (run clang-format -i $f)"
    bad=$((bad + 1))
  fi
done
n=$(echo "$files" | wc -w)
echo "$((n - bad)) passed, $bad failed"
[ $bad -eq 0 ]
