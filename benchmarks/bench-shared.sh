#!/usr/bin/env bash
# A run on a shared machine: wall time of a short explicit FPM run (F2,
# two threads) alone and beside another two-thread pointmech run, for each
# OpenMP wait policy of the measured run and of the competing one.  Run it
# on an otherwise idle machine.
#
# usage: benchmarks/bench-shared.sh BUILD [STEPS] [POLICY...]
#   POLICY: default (OMP_WAIT_POLICY and GOMP_SPINCOUNT unset), passive,
#   active, or spin=N (GOMP_SPINCOUNT=N)
[ $# -ge 1 ] || { echo "usage: bench-shared.sh BUILD [STEPS] [POLICY...]" >&2; exit 1; }
bench_name=shared
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
steps=${2:-4000}
shift $(($# >= 2 ? 2 : 1))
policies=("$@")
[ ${#policies[@]} -gt 0 ] || policies=(default passive)
scene=cases/fpm/f2-unconstrained-compression.yaml
work=$(mktemp -d)
competitor=
cleanup() {
  [ -n "$competitor" ] && kill "$competitor" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

# Run with a policy: env settings for it.
policy_env() { # policy
  case $1 in
  default) echo "-u OMP_WAIT_POLICY -u GOMP_SPINCOUNT POINTMECH_WAIT_POLICY=default" ;;
  passive) echo "-u GOMP_SPINCOUNT OMP_WAIT_POLICY=passive" ;;
  active) echo "-u GOMP_SPINCOUNT OMP_WAIT_POLICY=active" ;;
  spin=*) echo "-u OMP_WAIT_POLICY GOMP_SPINCOUNT=${1#spin=}" ;;
  *) echo "unknown policy $1" >&2; exit 1 ;;
  esac
}

# Wall time of the time loop (summary.json) of the measured run.
measure() { # policy, label
  # shellcheck disable=SC2046
  env $(policy_env "$1") OMP_NUM_THREADS=2 "$bin" run "$scene" \
    --set time.max_steps="$steps" --set output.every=1000000 \
    --out "$work/m" --quiet >/dev/null 2>&1 || true
  sed -nE 's/.*"wall_seconds": ([0-9.e+-]+).*/\1/p' "$work/m/summary.json" | head -1
}

start_competitor() { # policy
  # shellcheck disable=SC2046
  env $(policy_env "$1") OMP_NUM_THREADS=2 "$bin" run "$scene" \
    --set time.max_steps=100000000 --set output.every=100000000 \
    --out "$work/c" --quiet >/dev/null 2>&1 &
  competitor=$!
  sleep 2 # past its setup
}

stop_competitor() {
  kill "$competitor" 2>/dev/null || true
  wait "$competitor" 2>/dev/null || true
  competitor=
}

echo "F2 (1851 points), $steps explicit steps, 2 threads; wall seconds of the time loop"
printf '%-12s %10s' "run policy" alone
for c in "${policies[@]}"; do printf ' %16s' "beside $c"; done
echo
for p in "${policies[@]}"; do
  printf '%-12s %10.2f' "$p" "$(measure "$p")"
  for c in "${policies[@]}"; do
    start_competitor "$c"
    printf ' %16.2f' "$(measure "$p")"
    stop_competitor
  done
  echo
done
