#!/usr/bin/env bash
# Every C source (and the C++ of geometry/cgal) is formatted with the
# repository's .clang-format.  One clang-format process for all the files
# (one a file took 49 CPU seconds of its start-up, the files 2): it names
# every file that differs, and each is reported once.
set -u
cd "$1"
files=$(ls src/*/*.[ch] src/*/*/*.[ch] src/*/*/*/*.[ch] geometry/*.[ch] geometry/cgal/*.cpp \
  tests/*/*.[ch] 2>/dev/null)
# shellcheck disable=SC2086
out=$(clang-format --dry-run --Werror $files 2>&1)
rc=$?
bad_files=$(echo "$out" | sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: error: .*/\1/p' | sort -u)
bad=0
for f in $bad_files; do
  echo "not formatted: $f (run clang-format -i $f)"
  bad=$((bad + 1))
done
# clang-format failed without naming a file (a missing .clang-format, a
# file it could not read): say so rather than pass.
if [ $rc -ne 0 ] && [ $bad -eq 0 ]; then
  echo "$out" | head -20
  echo "clang-format failed (exit $rc) without naming a file"
  bad=1
fi
n=$(echo "$files" | wc -w)
echo "$((n - bad)) passed, $bad failed"
[ $bad -eq 0 ]
