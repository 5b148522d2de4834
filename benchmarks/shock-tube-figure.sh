#!/bin/bash
# Shock-tube profiles against the exact Riemann solution, for the iterative
# and the non-iterative energy update: runs a scene through
# verify_shock_tube --profiles and draws density, velocity, pressure and
# internal energy with tools/plot-shock-tube.py.
# usage: benchmarks/shock-tube-figure.sh BUILD [SCENE] [OUT_DIR]
#   default SCENE cases/mpm/m2-shock-tube.yaml (the paper's size, ~30 s),
#   default OUT_DIR out/shock-tube; writes OUT_DIR/profiles.png and the CSVs.
[ $# -ge 1 ] || { echo "usage: $0 BUILD [SCENE] [OUT_DIR]" >&2; exit 1; }
bench_name=shock-tube bench_out=${3:-out/shock-tube}
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
scene=${2:-cases/mpm/m2-shock-tube.yaml}
{
  bench_stamp
  "$build/tests/verify_shock_tube" --profiles "$out" --scene "$scene" |
    grep -E "^(iterative|non-iterative)"
} | tee "$out/table.txt"
$py tools/plot-shock-tube.py --exact "$out/exact.csv" \
  --title "$(basename "$scene" .yaml)" --out "$out/profiles.png" \
  "iterative=$out/iterative.csv" "non-iterative=$out/non-iterative.csv"
echo "figure: $out/profiles.png"
