#!/usr/bin/env bash
# pointmech runs its OpenMP threads with a short spin (GOMP_SPINCOUNT=3000)
# unless the user chose a policy (OMP_WAIT_POLICY or GOMP_SPINCOUNT) or asked for the
# runtime's default (POINTMECH_WAIT_POLICY=default): the environment of the
# running process (/proc/PID/environ, the same process after it restarts
# itself) says which.
set -u
bin=$1
src=$2
scene=$src/cases/mpm/f2-unconstrained-compression.yaml
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"

# VAR (OMP_WAIT_POLICY or GOMP_SPINCOUNT) in the environment of a run that
# has begun its work ("" if unset).
setting_of_run() { # variable, env settings...
  local var=$1
  shift
  env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT -u POINTMECH_WAIT_POLICY "$@" \
    "$bin" run "$scene" --set time.max_steps=100000000 --set time.end=1e9 \
    --out "$work/out" --quiet >/dev/null 2>&1 &
  local pid=$!
  # Past its start (the restart comes first) once it has made its output
  # folder; a loaded machine may take longer than a second to get there.
  local waited=0
  while [ ! -d "$work/out" ] && [ $waited -lt 200 ] && kill -0 $pid 2>/dev/null; do
    sleep 0.1
    waited=$((waited + 1))
  done
  tr '\0' '\n' <"/proc/$pid/environ" | sed -n "s/^$var=//p"
  kill -KILL $pid 2>/dev/null
  wait $pid 2>/dev/null
  rm -rf "$work/out"
}

p=$(setting_of_run GOMP_SPINCOUNT)
check "unset: the run restarts itself with a spin of 3000 (got '$p')" test "$p" = 3000
p=$(setting_of_run OMP_WAIT_POLICY OMP_WAIT_POLICY=passive)
check "OMP_WAIT_POLICY=passive is kept (got '$p')" test "$p" = passive
p=$(setting_of_run GOMP_SPINCOUNT OMP_WAIT_POLICY=passive)
check "OMP_WAIT_POLICY set: no spin count added (got '$p')" test -z "$p"
p=$(setting_of_run GOMP_SPINCOUNT GOMP_SPINCOUNT=1000)
check "GOMP_SPINCOUNT=1000 is kept (got '$p')" test "$p" = 1000
p=$(setting_of_run GOMP_SPINCOUNT POINTMECH_WAIT_POLICY=default)
check "POINTMECH_WAIT_POLICY=default: the runtime's default (got '$p')" test -z "$p"

echo "$passes passed, $failures failed"
[ $failures -eq 0 ]
