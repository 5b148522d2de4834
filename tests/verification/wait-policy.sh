#!/usr/bin/env bash
# pointmech runs its OpenMP threads with the passive wait policy unless the
# user chose one (OMP_WAIT_POLICY or GOMP_SPINCOUNT) or asked for the
# runtime's default (POINTMECH_WAIT_POLICY=default): the environment of the
# running process (/proc/PID/environ, the same process after it restarts
# itself) says which.
set -u
bin=$1
src=$2
scene=$src/cases/mpm/f2-unconstrained-compression.yaml
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"

# OMP_WAIT_POLICY in the environment of a run one second in ("" if unset).
policy_of_run() { # env settings...
  env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT -u POINTMECH_WAIT_POLICY "$@" \
    "$bin" run "$scene" --set time.max_steps=100000000 --set time.end=1e9 \
    --out "$work/out" --quiet >/dev/null 2>&1 &
  local pid=$!
  sleep 1
  tr '\0' '\n' <"/proc/$pid/environ" | sed -n 's/^OMP_WAIT_POLICY=//p'
  kill -KILL $pid 2>/dev/null
  wait $pid 2>/dev/null
  rm -rf "$work/out"
}

p=$(policy_of_run)
check "unset: the run restarts itself passive (got '$p')" test "$p" = passive
p=$(policy_of_run OMP_WAIT_POLICY=active)
check "OMP_WAIT_POLICY=active is kept (got '$p')" test "$p" = active
p=$(policy_of_run GOMP_SPINCOUNT=1000)
check "GOMP_SPINCOUNT set: no policy added (got '$p')" test -z "$p"
p=$(policy_of_run POINTMECH_WAIT_POLICY=default)
check "POINTMECH_WAIT_POLICY=default: the runtime's default (got '$p')" test -z "$p"

echo "$passes passed, $failures failed"
[ $failures -eq 0 ]
