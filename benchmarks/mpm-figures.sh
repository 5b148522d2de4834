#!/bin/bash
# The figures of the explicit MPM cases:
#   OUT/m2-shock-tube/profiles.png  M2 at the paper's size (pressure ratio
#                                   1000), iterative and non-iterative
#                                   energy update against the exact solution
#   OUT/m2-sod/profiles.png         the same tube at the Sod ratio
#   OUT/disks-energy.png            the colliding disks' energy, FLIP and PIC
# usage: benchmarks/mpm-figures.sh [BUILD_DIR] [OUT]  (defaults build, out/mpm-figures)
bench_name=mpm-figures bench_out=${2:-out/mpm-figures}
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
benchmarks/shock-tube-figure.sh "$build" cases/mpm/m2-shock-tube.yaml "$out/m2-shock-tube"
benchmarks/shock-tube-figure.sh "$build" cases/mpm/m2-sod.yaml "$out/m2-sod"
for blend in 1 0; do
  "$bin" run --overwrite cases/mpm/disks-collision.yaml --quiet \
    --out "$out/disks-flip$blend" --set mpm.flip=$blend --set output.every=2
done
$py tools/plot-history.py --sum total=kinetic_energy+strain_energy \
  --title "two elastic disks colliding: energy (J per m)" \
  --out "$out/disks-energy.png" FLIP="$out/disks-flip1" PIC="$out/disks-flip0"
