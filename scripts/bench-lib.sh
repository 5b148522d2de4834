# Shared by the bench scripts (sourced): strict mode, the repository root,
# the program (BUILD_DIR/pointmech, BUILD_DIR from $1, default build), the
# flux and penalty (FLUX, PENALTY), the output folder (BENCH_OUT, default
# out/bench-NAME) and get KEY FILE for a top-level summary.json value.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build}/pointmech
flux=${FLUX:-iipg}
penalty=${PENALTY:-20}
out=${BENCH_OUT:-out/bench-$bench_name}
mkdir -p "$out"
get() { sed -n "s/^  \"$1\": \"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$2" | head -1; }
