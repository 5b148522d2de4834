#!/usr/bin/env bash
# The layers of MPM (src/mpm): no file of the core (core, step, implicit,
# kinds, and the kinds still at src/mpm's top level) includes MPI, PETSc's
# star forests, the program's ranks (pm_par) or a header of the ranks or
# backend layers; the ranks layer includes no backend header.
set -u
cd "$1/src/mpm"
bad=0
hdr() { ls "$@" 2>/dev/null | xargs -r -n1 basename | sed 's/[.]/[.]/g' | paste -sd'|'; }
ranks=$(hdr ranks/*.h)
backend=$(hdr backend/*.h)
core=$(ls *.[ch] core/*.[ch] step/*.[ch] implicit/*.[ch] kinds/*.[ch] \
  kinds/*/*.[ch] 2>/dev/null)
forbid="mpi[.]h|petscsf[.]h|pm_par[.]h|pm_par_mpi[.]h${ranks:+|$ranks}${backend:+|$backend}"
for f in $core; do
  if grep -nE "^[[:space:]]*#[[:space:]]*include[[:space:]]*[<\"]([^\">]*/)?($forbid)[\">]" "$f"; then
    echo "core file includes MPI or a ranks/backend header: src/mpm/$f"
    bad=$((bad + 1))
  fi
done
for f in $(ls ranks/*.[ch] 2>/dev/null); do
  if [ -n "$backend" ] && grep -nE "#[[:space:]]*include[[:space:]]*\"([^\"]*/)?($backend)\"" "$f"; then
    echo "ranks file includes a backend header: src/mpm/$f"
    bad=$((bad + 1))
  fi
done
echo "$(echo "$core" | wc -w) core files checked, $bad failed"
[ $bad -eq 0 ]
