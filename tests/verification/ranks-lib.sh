# Shared by the tests across MPI ranks (ranks.sh, ranks-membranes.sh), after
# lib.sh: mpirun's environment (as root, more ranks than cores, one thread
# a rank, ranks that wait yield their core), ranks N COMMAND... and across
# LABEL SCENE N OVERRIDES... (one process, then N ranks, compared to
# round-off; $bin, $src and $work set by the caller).
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_mpi_yield_when_idle=1
export OMP_NUM_THREADS=1
py=/usr/bin/python3
roundoff="$py $src/tests/verification/same_to_roundoff.py"
tol=1e-10
mpm=$src/cases/mpm

ranks() { # N, command...
  local n=$1
  shift
  timeout 300 mpirun -np "$n" --bind-to none "$@"
}

# One process, then N ranks, of SCENE with overrides, compared to
# round-off (less the history columns $skip, comma-separated); the runs
# end with exit status $want (default 0).
across() { # label, scene, ranks, overrides...
  local label=$1 scene=$2 n=$3 want=${want:-0}
  shift 3
  local one=$work/$label-1 many=$work/$label-$n
  [ -d "$one" ] || "$bin" run "$scene" --out "$one" --quiet "$@" \
    >/dev/null 2>"$work/err"
  ranks "$n" "$bin" run "$scene" --out "$many" --quiet "$@" >/dev/null \
    2>"$work/err"
  local rc=$?
  check "$label on $n ranks: exit $want (got $rc)" test $rc -eq "$want"
  $roundoff "$one" "$many" $tol ${skip:-} >"$work/cmp" 2>&1
  rc=$?
  sed "s/^/$label, $n ranks against one process: /" "$work/cmp"
  check "$label on $n ranks: the run of one process to $tol" test $rc -eq 0
}

# SCENE with overrides on one process and on 2 ranks, and on 2 ranks
# stopped by SIGTERM to rank 0 (its pid is in summary.json) once
# history.csv has ROWS lines, then resumed on each count of ranks in COUNTS
# (1: one process): on 2 the straight 2-rank run bit for bit, on the others
# the straight run of as many to round-off.
resumed() { # label, rows, counts, scene, overrides...
  local label=$1 rows=$2 counts=$3 scene=$4
  shift 4
  local long=$work/$label-long cut=$work/$label-cut
  "$bin" run "$scene" --out "$long-1" --quiet "$@" >/dev/null 2>&1
  ranks 2 "$bin" run "$scene" --out "$long-2" --quiet "$@" >/dev/null 2>&1
  timeout 300 mpirun -np 2 --bind-to none "$bin" run "$scene" \
    --out "$cut" --quiet "$@" >/dev/null 2>"$work/err" &
  local job=$!
  for _ in $(seq 600); do
    [ -f "$cut/history.csv" ] &&
      [ "$(wc -l <"$cut/history.csv")" -ge "$rows" ] && break
    sleep 0.05
  done
  local pid
  pid=$(sed -n 's/^ *"pid": \([0-9]*\).*/\1/p' "$cut/summary.json")
  kill -TERM "$pid"
  wait $job
  check "$label interrupted on 2 ranks: status interrupted" \
    grep -q '"status": "interrupted"' "$cut/summary.json"
  local n rc
  for n in $counts; do
    cp -r "$cut" "$cut-$n"
    if [ "$n" -eq 1 ]; then
      "$bin" resume "$cut-$n" --quiet >/dev/null 2>"$work/err"
    else
      ranks "$n" "$bin" resume "$cut-$n" --quiet >/dev/null 2>"$work/err"
    fi
    check "$label interrupted on 2 ranks, resumed on $n: exit 0" test $? -eq 0
    if [ "$n" -eq 2 ]; then
      check "$label interrupted on 2 ranks, resumed on 2: the run of 2 ranks, bit for bit" \
        $py "$src/tests/verification/same_results.py" "$long-2" "$cut-2"
      continue
    fi
    $roundoff "$long-$([ "$n" -eq 1 ] && echo 1 || echo 2)" "$cut-$n" $tol \
      >"$work/cmp" 2>&1
    rc=$?
    sed "s/^/$label interrupted on 2 ranks, resumed on $n: /" "$work/cmp"
    check "$label interrupted on 2 ranks, resumed on $n: the straight run to $tol" \
      test $rc -eq 0
  done
}
