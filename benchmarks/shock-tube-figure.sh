#!/bin/bash
# Shock-tube profiles against the exact Riemann solution, for the iterative
# and the non-iterative energy update: runs a scene through
# verify_shock_tube --profiles and draws density, velocity, pressure and
# internal energy with tools/plot-shock-tube.py.
# usage: benchmarks/shock-tube-figure.sh BUILD [SCENE] [OUT_DIR]
#   default SCENE cases/mpm/m2-shock-tube.yaml (the paper's size, ~30 s),
#   default OUT_DIR out/shock-tube; writes OUT_DIR/profiles.png and the CSVs.
set -euo pipefail
build=${1:?usage: $0 BUILD [SCENE] [OUT_DIR]}
scene=${2:-cases/mpm/m2-shock-tube.yaml}
out=${3:-out/shock-tube}
mkdir -p "$out"
"$build/tests/verify_shock_tube" --profiles "$out" --scene "$scene" |
  grep -E "^(iterative|non-iterative)" | tee "$out/table.txt"
/usr/bin/python3 tools/plot-shock-tube.py --exact "$out/exact.csv" \
  --title "$(basename "$scene" .yaml)" --out "$out/profiles.png" \
  "iterative=$out/iterative.csv" "non-iterative=$out/non-iterative.csv"
echo "figure: $out/profiles.png"
