#!/usr/bin/env bash
# Newton across MPI ranks: the shared Newton layer (ranks_newton: a chain
# of nonlinear springs against its exact solution and one process's, for
# every linear solver) and the implicit MPM across ranks against the same
# runs on one process.
# Usage: ranks-implicit.sh POINTMECH SOURCE_DIR RANKS_NEWTON
set -u
bin=$1
src=$2
newton=$3
. "$(dirname "$0")/lib.sh"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_mpi_yield_when_idle=1
export OMP_NUM_THREADS=1

ranks() { # N, command...
  local n=$1
  shift
  timeout 300 mpirun -np "$n" --bind-to none "$@"
}

for n in 2 3; do
  ranks $n "$newton" >"$work/out" 2>"$work/err"
  rc=$?
  sed "s/^/newton on $n ranks: /" "$work/out"
  check "newton on $n ranks: every check holds (exit $rc)" test $rc -eq 0
done

# The implicit MPM: case I2 at 64^2 cells (the paper's slice, one particle
# per pixel) on 2 ranks with GMRES + GAMG and on 3 with LU against one
# process, to round-off (measured 5e-14: the ranks' sums come in another
# order; the Newton iterates are the same; GMRES takes other iteration
# counts on other ranks, which the comparison leaves out).
py=/usr/bin/python3
roundoff="$py $src/tests/verification/same_to_roundoff.py"
i2=$src/cases/mpm/i2-vessel-slice.yaml
tol=1e-10
direct="--set time.quasi_static.linear_solver=direct"
across() { # label, ranks, skip, overrides...
  local label=$1 n=$2 skip=$3
  shift 3
  local one=$work/$label-1 many=$work/$label-$n
  [ -d "$one" ] || "$bin" run "$i2" --out "$one" --quiet "$@" >/dev/null \
    2>"$work/err"
  ranks "$n" "$bin" run "$i2" --out "$many" --quiet "$@" >/dev/null \
    2>"$work/err"
  local rc=$?
  check "$label on $n ranks: exit 0 (got $rc)" test $rc -eq 0
  $roundoff "$one" "$many" $tol $skip >"$work/cmp" 2>&1
  rc=$?
  sed "s/^/$label, $n ranks against one process: /" "$work/cmp"
  check "$label on $n ranks: the run of one process to $tol" test $rc -eq 0
}
across i2-gamg 2 linear_iterations
across i2-lu 3 "" $direct

# Interrupted on 2 ranks and resumed (I2 at 32^2 cells, CG + Jacobi, whose
# iterates repeat bit for bit across ranks: LU (MUMPS) and GAMG across
# ranks schedule their work as messages arrive, so their runs repeat to
# round-off only): on 2 ranks bit for bit the run not interrupted, on one
# process and on 3 ranks to round-off the run of one process.
jacobi="--set time.quasi_static.linear_solver=cg-jacobi
  --set discretization.mesh_size=16.8e-6"
"$bin" run "$i2" --out "$work/j-1" --quiet $jacobi >/dev/null 2>&1
ranks 2 "$bin" run "$i2" --out "$work/j-2" --quiet $jacobi >/dev/null 2>&1
timeout 300 mpirun -np 2 --bind-to none "$bin" run "$i2" --out "$work/cut" \
  --quiet $jacobi >/dev/null 2>"$work/err" &
job=$!
for _ in $(seq 1200); do
  [ -f "$work/cut/history.csv" ] &&
    [ "$(wc -l <"$work/cut/history.csv")" -ge 4 ] && break
  sleep 0.05
done
pid=$(sed -n 's/^ *"pid": \([0-9]*\).*/\1/p' "$work/cut/summary.json")
kill -TERM "$pid"
wait $job
check "I2 interrupted on 2 ranks: status interrupted" \
  grep -q '"status": "interrupted"' "$work/cut/summary.json"
rows=$(($(wc -l <"$work/cut/history.csv") - 1))
echo "I2 interrupted on 2 ranks after $rows load steps"
for n in 1 2 3; do
  cp -r "$work/cut" "$work/cut-$n"
  if [ $n -eq 1 ]; then
    "$bin" resume "$work/cut-$n" --quiet >/dev/null 2>"$work/err"
  else
    ranks $n "$bin" resume "$work/cut-$n" --quiet >/dev/null 2>"$work/err"
  fi
  check "I2 interrupted on 2 ranks, resumed on $n: exit 0" test $? -eq 0
done
check "I2 interrupted on 2 ranks, resumed on 2: the run of 2 ranks, bit for bit" \
  $py "$src/tests/verification/same_results.py" "$work/j-2" "$work/cut-2"
for n in 1 3; do
  $roundoff "$work/j-1" "$work/cut-$n" $tol >"$work/cmp" 2>&1
  rc=$?
  sed "s/^/I2 interrupted on 2 ranks, resumed on $n: /" "$work/cmp"
  check "I2 interrupted on 2 ranks, resumed on $n: one process's run to $tol" \
    test $rc -eq 0
done

# What runs on one process only is refused, naming the key, before
# anything is written; plan prints the decomposition.
for kv in "mpm.implicit.grid=reset:mpm.implicit.grid" \
  "mpm.implicit.operator=matrix-free:mpm.implicit.operator" \
  "mpm.fbar=cell:mpm.fbar"; do
  set_kv=${kv%%:*} key=${kv#*:}
  refused "I2 with $set_kv on 2 ranks" "$key" "$work/refused" \
    ranks 2 "$bin" run "$i2" --out "$work/refused" --set "$set_kv"
done
ranks 2 "$bin" plan "$i2" >"$work/plan" 2>&1
check "plan on 2 ranks: the decomposition" grep -q "^ranks        2:" \
  "$work/plan"
check "plan on 2 ranks: each rank's share" grep -qE "^ +1 +131072 " \
  "$work/plan"

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
