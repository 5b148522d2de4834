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

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
