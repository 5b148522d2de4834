#!/usr/bin/env bash
# Figure 2/3 of the FPM paper for case F1: the 2D block at 20% extension
# with p = 0 and p = 20, each point's subdomain drawn moved by its own
# linear field, so that the gaps and overlaps of the inconsistent p = 0
# solution show (jumps magnified 5 times in the second figure).
#   benchmarks/f1-figure.sh [BUILD_DIR]    -> out/f1-figure/*.png
bench_name=f1-figure bench_out=${FIGURE_OUT:-out/f1-figure}
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
for p in 0 20; do
  "$bin" run --overwrite cases/fpm/f1-extension.yaml --set fpm.formulation=paper \
    --set fpm.penalty=$p --quiet \
    --out "$out/p$p"
done
for mag in 1 5; do
  $py tools/plot-points.py "$out/p0" "$out/p20" \
    --labels "p = 0,p = 20" --subdomains --magnify $mag \
    --out "$out/f1-extension-subdomains-x$mag.png"
done
