#!/usr/bin/env bash
# Tables 2 and 3 of the FPM paper: for each case given (default: all six),
# the convergence study of the constrained block at the paper's four
# resolutions against the dense run at h = 2.79e-3 m (about 80000 points),
# mapped by moving least squares.  REFERENCE=fe compares the four
# resolutions with the case's finite-element referee (cases/fe/CASE)
# instead, without the dense run, and adds the reaction and strain energy
# errors.  Writes out/study-CASE-FLUX/convergence.{md,csv}.
#   scripts/study-blocks.sh [BUILD_DIR] [CASE ...]
#   CASE: f3-extension-60 f3-extension-100 f3-extension-200
#         f4-compression-20 f4-compression-40 f4-compression-60
# FLUX (default sipg), PENALTY (default 100 for sipg, 20 for iipg), RULE
# (default spectral) and SAFETY (default 0.5) choose the formulation and
# step; the paper's own is FLUX=iipg PENALTY=20 RULE=paper SAFETY=0.9.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(f3-extension-60 f3-extension-100
  f3-extension-200 f4-compression-20 f4-compression-40 f4-compression-60)
flux=${FLUX:-sipg}
if [ "$flux" = sipg ]; then penalty=${PENALTY:-100}; else penalty=${PENALTY:-20}; fi
for c in "${cases[@]}"; do
  if [ "${REFERENCE:-last}" = fe ]; then
    ref=(--reference "fe:cases/fe/$c")
    sizes=8.72e-3,6.42e-3,4.15e-3,2.98e-3
  else
    ref=(--reference last)
    sizes=8.72e-3,6.42e-3,4.15e-3,2.98e-3,2.15e-3
  fi
  "$build/pointmech" convergence "cases/fpm/$c-h1.09e-2.yaml" --quiet \
    --set fpm.flux="$flux" --set fpm.penalty="$penalty" \
    --set time.dt_rule="${RULE:-spectral}" --set time.dt_safety="${SAFETY:-0.5}" \
    --set output.every=1000000 "${ref[@]}" \
    --set-ladder discretization.mesh_size=$sizes \
    --out "${STUDY_OUT:-out}/study-$c-$flux"
done
