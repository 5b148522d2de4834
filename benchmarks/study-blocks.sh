#!/usr/bin/env bash
# Tables 2 and 3 of the FPM paper: for each case given (default: all six),
# the convergence study of the constrained block at the paper's four
# resolutions against the dense run at h = 2.79e-3 m (about 80000 points),
# mapped by moving least squares: the case's scene (cases/fpm/CASE.yaml)
# over the ladder of its mesh sizes.  REFERENCE=fe compares the four
# resolutions with the case's finite-element referee (cases/fe/CASE)
# instead, without the dense run, and adds the reaction and strain energy
# errors.  Writes out/study-CASE-TAG/convergence.{md,csv}.
#   benchmarks/study-blocks.sh [BUILD_DIR] [CASE ...]
#   CASE: f3-extension-60 f3-extension-100 f3-extension-200
#         f4-compression-20 f4-compression-40 f4-compression-60
# FORMULATION chooses the flux, jump and penalty (TAG is its name):
#   scene  the scenes' own (default): IIPG, quadratic jump, p = 0.05,
#          averaged volume
#   paper  the FPM paper's: IIPG, linear jump, p = 20
#   sipg   symmetric: SIPG, linear jump, p = 100
# QS=static solves each state by Newton's method instead of dynamic
# relaxation (TAG gets -static).  SIZES overrides the ladder of gmsh
# element sizes (comma-separated).
bench_name=study-blocks bench_out=${STUDY_OUT:-out}
bench_env="FORMULATION QS REFERENCE SIZES STUDY_OUT"
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
shift || true
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(f3-extension-60 f3-extension-100
  f3-extension-200 f4-compression-20 f4-compression-40 f4-compression-60)
tag=${FORMULATION:-scene}
fpm_form "$tag"
if [ "${QS:-}" = static ]; then
  form+=(--set time.quasi_static.method=static)
  tag=$tag-static
fi
for c in "${cases[@]}"; do
  if [ "${REFERENCE:-last}" = fe ]; then
    ref=(--reference "fe:cases/fe/$c")
    sizes=${SIZES:-8.72e-3,6.42e-3,4.15e-3,2.98e-3}
  else
    ref=(--reference last)
    sizes=${SIZES:-8.72e-3,6.42e-3,4.15e-3,2.98e-3,2.15e-3}
  fi
  "$bin" convergence --overwrite "cases/fpm/$c.yaml" --quiet \
    "${form[@]}" --set output.every=1000000 "${ref[@]}" \
    --set-ladder discretization.mesh_size=$sizes --out "$out/study-$c-$tag"
done
