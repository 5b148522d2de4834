#!/usr/bin/env bash
# Signals obeyed promptly by FPM's static solve: SIGTERM inside a long
# linear solve stops the run within a few seconds (asserted at 5 s, the
# figure printed) with its reason; SIGTERM after converged load steps
# leaves the checkpoint of the last converged one, which `resume` takes to
# the end; SIGTERM during the setup (meshing, subdomains, operators) stops
# it once the stage running ends, nothing written; two SIGTERMs at once
# are one.
set -u
bin=$1
src=$2
here=$(dirname "$0")
# shellcheck source=lib.sh
. "$here/lib.sh"
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
f3=$src/cases/fpm/f3-extension-60.yaml
f2=$src/cases/fpm/f2-unconstrained-compression.yaml
static=(--set time.quasi_static.method=static)

within() { awk -v l="$1" -v b="$2" 'BEGIN { exit !(l <= b) }'; }

# 1. A linear solve that would run for hours (GMRES without a
# preconditioner to a relative residual of 1e-30) at 1851 points: the
# signal 1 s after its first iteration.
out=$work/long
stop_after ksp 1 "$out" "$f3" "${static[@]}" \
  --set discretization.mesh_size=8.72e-3 \
  --set time.quasi_static.linear_solver=gmres-ilu \
  --set 'time.quasi_static.solver_options=-pm_pc_type none -pm_ksp_rtol 1e-30 -pm_ksp_atol 0 -pm_ksp_max_it 1000000000 -pm_ksp_monitor'
echo "SIGTERM in a static linear solve: exit $rc after $lag s"
check "linear solve: exit 4 (got $rc)" test $rc -eq 4
check "linear solve: stopped within 5 s of the signal (took $lag s)" \
  within "$lag" 5
check "linear solve: the message names the signal and the solve" \
  grep -q "interrupted by SIGTERM in a linear solve, linear iteration" "$work/err"
check "linear solve: the first frame kept" test -s "$out/results/frame_000000.h5"
check "linear solve: summary says interrupted" \
  grep -q '"status": "interrupted"' "$out/summary.json"

# 2. F2 at 1851 points (10 load steps), stopped after converged steps: the
# checkpoint of the last one, and resume ends as the straight run.
out=$work/stepped
stop_after 3 0.2 "$out" "$f2" "${static[@]}" --set output.every=1
echo "SIGTERM after converged load steps: exit $rc after $lag s"
if [ $rc -eq 0 ]; then
  echo "the run ended before the signal: nothing to check"
else
  check "stepped: exit 4 (got $rc)" test $rc -eq 4
  check "stepped: within 5 s of the signal (took $lag s)" within "$lag" 5
  check "stepped: checkpoint written" test -s "$out/checkpoint.h5"
  check "stepped: message says resume" grep -q "pointmech resume" "$work/err"
  # The summary's field figures are the last converged state's, the one
  # the last frame holds, not the iterate the signal found (before: the
  # largest von Mises stress 362.5 Pa against the frame's 240.8).
  /usr/bin/python3 - "$out" "$src" >"$work/fig" 2>&1 <<'PY'
import sys, json, numpy as np
sys.path.insert(0, sys.argv[2] + '/python')
import pointmech
s = json.load(open(sys.argv[1] + '/summary.json'))
f = pointmech.open(sys.argv[1]).frames[-1]
sig = np.asarray(f['stress']).reshape(-1, 3, 3)
dev = sig - np.trace(sig, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3
vm = np.sqrt(1.5 * np.einsum('pij,pij->p', dev, dev)).max()
J = np.asarray(f['jacobian']).min()
print(f'frame step {f.step}, summary steps {s["steps"]}: von Mises {vm} and '
      f'{s["max_von_mises"]}, smallest J {J} and {s["end_min_jacobian"]}')
assert f.step == s['steps']
assert abs(vm - s['max_von_mises']) <= 1e-12 * vm
assert abs(J - s['end_min_jacobian']) <= 1e-12
PY
  check "stepped: the summary's figures are the last frame's" test $? -eq 0
  sed 's/^/  /' "$work/fig"
  "$bin" resume "$out" --quiet >/dev/null 2>"$work/err"
  check "stepped: resumed to exit 0" test $? -eq 0
  check "stepped: completed" grep -q '"status": "converged"' "$out/summary.json"
fi

# 3. During the setup at 4036 points (meshing, subdomains, operators take
# about a second): stopped at the end of the stage running.
out=$work/setup
stop_after 0 0.2 "$out" "$f3" "${static[@]}"
echo "SIGTERM during the setup: exit $rc after $lag s"
check "setup: exit 4 (got $rc)" test $rc -eq 4
check "setup: within 5 s of the signal (took $lag s)" within "$lag" 5
check "setup: the message says where" \
  grep -Eq "interrupted by SIGTERM (after|during) .*\(nothing written\)" "$work/err"

# 4. Two SIGTERMs 0.05 s apart, as GNU timeout sends them (one to the
# run, one to its process group): one request, the run stops as for one
# (before, the second killed it with nothing written but the frames).
out=$work/twice
STOP_AGAIN=0.05 stop_after 3 0.2 "$out" "$f2" "${static[@]}" --set output.every=1
echo "two SIGTERMs 0.05 s apart: exit $rc after $lag s"
if [ $rc -eq 0 ]; then
  echo "the run ended before the signals: nothing to check"
else
  check "twice: exit 4 (got $rc)" test $rc -eq 4
  check "twice: checkpoint written" test -s "$out/checkpoint.h5"
  check "twice: summary says interrupted" \
    grep -q '"status": "interrupted"' "$out/summary.json"
fi

echo "$passes passed, $failures failed"
[ $failures -eq 0 ]
