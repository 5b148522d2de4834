# shellcheck shell=bash
# Shared by the bench and study scripts (sourced after setting bench_name,
# and optionally bench_out, a default output folder, and bench_env, the
# names of the environment settings the script reads): strict mode, the
# repository root, the program (BUILD_DIR/pointmech, BUILD_DIR from $1,
# default build; $build is BUILD_DIR), the flux and penalty (FLUX,
# PENALTY), the output folder (BENCH_OUT, else bench_out, else
# out/bench-NAME), and the stamp line every table starts with (bench_stamp).
set -euo pipefail
bench_cmd=("$0" "$@")
cd "$(dirname "$0")/.."
build=${1:-build}
bin=$build/pointmech
flux=${FLUX:-iipg}
penalty=${PENALTY:-20}
out=${BENCH_OUT:-${bench_out:-out/bench-$bench_name}}
py=/usr/bin/python3
mkdir -p "$out"

# get KEY FILE: a top-level number or string value of a summary.json.
get() { sed -n "s/^  \"$1\": \"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$2" | head -1; }

# json FILE KEY...: a value of a summary.json (or any JSON) down the path
# of keys, "" where it has none.
json() {
  $py - "$@" <<'PY'
import json, sys
v = json.load(open(sys.argv[1]))
for k in sys.argv[2:]:
    v = v.get(k, "") if isinstance(v, dict) else ""
print(v)
PY
}

# The line a table starts with: when it was measured (UTC), on which
# commit (-dirty: with changes not committed), on how many cores, and the
# command that made it, with the environment settings it read.
bench_stamp() {
  local commit env="" v
  commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
  git diff --quiet HEAD -- 2>/dev/null || commit=$commit-dirty
  for v in ${bench_env:-}; do
    [ -n "${!v+x}" ] && env+="$v=${!v} "
  done
  echo "measured $(date -u '+%Y-%m-%d %H:%M UTC'), commit $commit," \
    "$(nproc) cores: $env${bench_cmd[*]}"
}
bench_stamp

# The gmsh element size of the FPM papers' average nodal spacing h (the
# block scenes' ladder: 0.8 h, 0.77 h for the dense reference).
paper_mesh_size() {
  case $1 in
  1.09e-2) echo 8.72e-3 ;;
  8.02e-3) echo 6.42e-3 ;;
  5.19e-3) echo 4.15e-3 ;;
  3.73e-3) echo 2.98e-3 ;;
  2.79e-3) echo 2.15e-3 ;;
  *)
    echo "h = $1: expected one of 1.09e-2 8.02e-3 5.19e-3 3.73e-3 2.79e-3" >&2
    return 1
    ;;
  esac
}

# fpm_form NAME: the array form set to the overrides of an FPM
# formulation:
#   scene, quadratic  the block scenes' own: IIPG, quadratic jump, p = 0.05
#   paper             the FPM paper's: IIPG, linear jump, p = 20
#   p0                IIPG, linear jump, p = 0 (no penalty: inconsistent)
#   sipg              SIPG, linear jump, p = 100
#   sipg-quadratic    SIPG, quadratic jump, p = 100 (the symmetric flux
#                     needs this penalty for coercivity: p = 10 diverges in
#                     undamped dynamics)
# (SIPG with the measured stable step x 0.5).  All but the scenes' own run
# the paper's uniform clouds (discretization.refine.size_ratio=1; F4 20%'s
# scene is graded toward its clamped faces).
fpm_form() {
  local uniform=(--set discretization.refine.size_ratio=1)
  local sipg=("${uniform[@]}" --set fpm.flux=sipg --set fpm.penalty=100
    --set time.dt_rule=spectral --set time.dt_safety=0.5)
  case $1 in
  scene | quadratic) form=() ;;
  paper) form=("${uniform[@]}" --set fpm.formulation=paper) ;;
  p0) form=("${uniform[@]}" --set fpm.formulation=paper --set fpm.penalty=0) ;;
  sipg) form=("${sipg[@]}" --set fpm.jump=linear) ;;
  sipg-quadratic) form=("${sipg[@]}") ;;
  *)
    echo "unknown FPM formulation $1: expected scene, paper, p0, sipg," \
      "sipg-quadratic or quadratic" >&2
    return 1
    ;;
  esac
}

# bench_run DIR SCENE [ARGS...]: one quiet run of SCENE into DIR (replaced)
# with ARGS (--set ...), its messages in DIR.log; returns its exit status.
bench_run() {
  local dir=$1 scene=$2
  shift 2
  mkdir -p "$(dirname "$dir")"
  "$bin" run --overwrite "$scene" --out "$dir" --quiet "$@" >"$dir.log" 2>&1
}

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
  $py - "$@" <<'PY'
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

# ranks_case NAME SCENE PPC2 [ARGS...]: the runs of a case side by side:
# REPEAT turns of SCENE on 1 rank x 1 thread, 1 x 2 threads and 2 ranks x
# 1 (and, unless PPC2 is -, twice the particles, particles_per_cell PPC2,
# on 2 ranks: weak scaling), taking turns so that the machine's slow spells
# fall on all of them; their fig lines in $out/NAME.CONFIG.runs
# (TABLE_ONLY=1: the earlier call's), then a ranks_row of each
# configuration.
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

# ranks_specs SPEC...: ranks_case over cases given as "NAME SCENE PPC2
# [KEY=VALUE ...]" (each KEY=VALUE an override); with CASES set, only the
# cases it names.
ranks_specs() {
  local spec name scene ppc2 extra sets kv
  for spec in "$@"; do
    read -r name scene ppc2 extra <<<"$spec"
    case " ${CASES:-$name} " in *" $name "*) ;; *) continue ;; esac
    sets=()
    for kv in ${extra:-}; do sets+=(--set "$kv"); done
    ranks_case "$name" "$scene" "$ppc2" "${sets[@]}"
  done
}
