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

# Runs across MPI ranks (bench-ranks.sh, bench-scaling.sh), each script
# defining fig SUMMARY (a line of the run's figures: points, steps,
# seconds per step, then its own) and setting $bind (mpirun --bind-to).
# ranks_run NAME RANKS THREADS SCENE [ARGS...]: one run of SCENE into
# $out/NAME-rRANKS-tTHREADS (one process for 1 rank), its fig line.
ranks_run() {
  local name=$1 ranks=$2 threads=$3 scene=$4
  shift 4
  local dir="$out/$name-r$ranks-t$threads"
  local cmd=("$bin" run --overwrite "$scene" --out "$dir" --quiet
    --set output.every=1000000 "$@")
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  if [ "$ranks" -eq 1 ]; then
    OMP_NUM_THREADS=$threads "${cmd[@]}" 2>/dev/null || true
  else
    OMP_NUM_THREADS=$threads mpirun -np "$ranks" --bind-to "${bind:-core}" \
      "${cmd[@]}" 2>/dev/null || true
  fi
  fig "$dir/summary.json"
}

# ranks_row LABEL CORES WORK BASE FILE: the runs of FILE (fig lines)
# against BASE's (the 1 x 1 runs): LABEL, the points, the median seconds
# per step (the fastest and slowest), the speed-up and efficiency per core
# of the medians, that of the fastest runs, then the median run's own
# figures.  WORK is the work over 1 x 1's (2: weak scaling).
ranks_row() {
  /usr/bin/python3 - "$@" <<'PY'
import sys
label, cores, work, base, path = sys.argv[1:6]
def runs(f):
    return sorted((list(map(float, l.split())) for l in open(f) if l.strip()),
                  key=lambda r: r[2])
rs, bs = runs(path), runs(base)
m, b = rs[len(rs) // 2], bs[len(bs) // 2][2]
per, w, n = m[2], float(work), float(cores)
print('%-20s %7d %10.3e %21s %6.2f %6.2f %9.2f' % (
    label, m[0], per, '(%.2e - %.2e)' % (rs[0][2], rs[-1][2]),
    b / per * w, b / per * w / n, bs[0][2] / rs[0][2] * w / n) +
    ''.join(' %10.4g' % v for v in m[3:]))
PY
}

# ranks_case NAME SCENE PPC2 [ARGS...]: REPEAT turns of SCENE on 1 rank x 1
# thread, 1 x 2 threads and 2 ranks x 1 (and, unless PPC2 is -, twice the
# particles, particles_per_cell PPC2, on 2 ranks: weak scaling), their fig
# lines in $out/NAME.CONFIG.runs (TABLE_ONLY=1: the earlier call's), then
# a ranks_row of each configuration.
ranks_case() {
  local name=$1 scene=$2 ppc2=$3
  shift 3
  [ "${TABLE_ONLY:-0}" = 1 ] || rm -f "$out/$name".*.runs
  for _ in $(seq "${repeat:-3}"); do
    [ "${TABLE_ONLY:-0}" = 1 ] && break
    ranks_run "$name" 1 1 "$scene" "$@" >>"$out/$name.1x1.runs"
    ranks_run "$name" 1 2 "$scene" "$@" >>"$out/$name.1x2.runs"
    ranks_run "$name" 2 1 "$scene" "$@" >>"$out/$name.2x1.runs"
    [ "$ppc2" = - ] && continue
    ranks_run "$name-weak" 2 1 "$scene" "$@" \
      --set "mpm.particles_per_cell=[$ppc2]" >>"$out/$name.weak.runs"
  done
  local base="$out/$name.1x1.runs"
  ranks_row "$name 1x1" 1 1 "$base" "$out/$name.1x1.runs"
  ranks_row "$name 1x2thr" 2 1 "$base" "$out/$name.1x2.runs"
  ranks_row "$name 2x1" 2 1 "$base" "$out/$name.2x1.runs"
  [ "$ppc2" = - ] ||
    ranks_row "$name weak2x1" 2 2 "$base" "$out/$name.weak.runs"
}
