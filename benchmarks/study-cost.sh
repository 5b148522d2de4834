#!/usr/bin/env bash
# What accuracy costs in time, one picture per case: each F3/F4 case given
# (default: F3 60%) by every FPM setting -- the scenes' own (IIPG, quadratic
# jump, p = 0.05) by dynamic relaxation and by static solves, the paper's
# (IIPG, linear jump, p = 20) and the symmetric flux (SIPG, p = 100) -- at
# the resolutions of SIZES (default: the paper's three coarsest), against
# the case's finite-element referee, with the referee's own meshes and
# times on the reaction panel.  Runs benchmarks/study-blocks.sh (REFERENCE=fe)
# once per setting, then tools/plot-convergence.py;
# writes out/study-CASE-*/ and out/cost-CASE-cost.png.
#   benchmarks/study-cost.sh [BUILD_DIR] [CASE ...]
# Time it on an otherwise idle machine: the wall times are the figure.
bench_name=study-cost bench_out=${STUDY_OUT:-out} bench_env="SIZES STUDY_OUT"
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
shift || true
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(f3-extension-60)
export REFERENCE=fe SIZES=${SIZES:-8.72e-3,6.42e-3,4.15e-3}
o=$out
for c in "${cases[@]}"; do
  FORMULATION=scene benchmarks/study-blocks.sh "$build" "$c"
  FORMULATION=scene QS=static benchmarks/study-blocks.sh "$build" "$c"
  FORMULATION=paper benchmarks/study-blocks.sh "$build" "$c"
  FORMULATION=sipg benchmarks/study-blocks.sh "$build" "$c"
  $py tools/plot-convergence.py \
    "$o/study-$c-scene/convergence.csv" \
    "$o/study-$c-scene-static/convergence.csv" \
    "$o/study-$c-paper/convergence.csv" "$o/study-$c-sipg/convergence.csv" \
    --labels "quadratic jump p = 0.05 (DR),quadratic jump p = 0.05 (static),paper: IIPG p = 20 (DR),SIPG p = 100 (DR)" \
    --fe "cases/fe/$c" --title "$c" --out-prefix "$o/cost-$c"
done
