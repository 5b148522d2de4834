# Shared by the verification tests across MPI ranks (ranks.sh, ranks-fpm.sh,
# ranks-implicit.sh, ranks-membranes.sh),
# sourced after lib.sh with $bin and $src set: runs on N ranks, each with one
# OpenMP thread, ranks waiting in a collective yielding their core
# (mpi_yield_when_idle: more ranks than cores otherwise spin against each
# other, 20 times slower), and their comparisons with one process.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_mpi_yield_when_idle=1
# One machine: the ranks talk through shared memory (ob1 over vader), and
# Open MPI probes no network device at each start (its default selection
# tries UCX, libfabric and PSM first: 0.2-0.5 s an mpirun here).
export OMPI_MCA_pml=ob1 OMPI_MCA_btl=self,vader
export OMP_NUM_THREADS=1
py=/usr/bin/python3
same="$py $src/tests/verification/same_results.py"
tol=1e-10
mpm=$src/cases/mpm

# Each rank's exit status is its own: mpirun does not abort the job when a
# rank exits with a status other than 0 (orte_abort_on_non_zero_status 0),
# each rank writes its status to a file, and ranks returns it when every
# rank's is the same (else it prints them and returns 99).  Aborting cost
# each run that ends with a status of the program's (3, not yet
# quasi-static; 2, unstable; 4, interrupted) a second: mpirun's wait
# between the SIGTERM and the SIGKILL it sends the ranks it aborts.  A rank
# killed by a signal (status above 128) stops mpirun (its parent), which
# stops the others: a rank's death by a signal with the abort off leaves
# mpirun waiting (Open MPI 4.1), and the ranks left would wait in their
# collectives.
ranks() { # N, command...
  local n=$1 dir rc r codes=""
  shift
  dir=$(mktemp -d -p "$work" rc.XXXXXX)
  # shellcheck disable=SC2016
  PM_RANKS_RC=$dir timeout 300 mpirun --mca orte_abort_on_non_zero_status 0 \
    -np "$n" --bind-to none sh -c '"$@"; rc=$?
      echo $rc >"$PM_RANKS_RC/$OMPI_COMM_WORLD_RANK"
      [ $rc -le 128 ] || kill -TERM $PPID
      exit $rc' sh "$@"
  rc=$?
  for r in $(seq 0 $((n - 1))); do
    codes="$codes $(cat "$dir/$r" 2>/dev/null || echo none)"
  done
  rm -rf "$dir"
  set -- $codes
  if [ "$rc" -ne 0 ]; then
    echo "ranks: mpirun exit $rc, ranks:$codes" >&2
    return "$rc"
  fi
  for r; do
    if [ "$r" != "$1" ] || [ "$r" = none ]; then
      echo "ranks: the ranks' exit statuses differ or are missing:$codes" >&2
      return 99
    fi
  done
  return "$1"
}

# Two runs' results and history to round-off: $tol, and the history
# columns named in $bounds (COLUMN=BOUND ...) to their own; the largest
# differences printed after LABEL.
roundoff() { # label, run, run
  $py "$src/tests/verification/same_to_roundoff.py" "$2" "$3" $tol \
    ${bounds:-} >"$work/cmp" 2>&1
  local rc=$?
  sed "s/^/$1: /" "$work/cmp"
  check "$1: to $tol" test $rc -eq 0
}

# One process (once) beside N ranks, of SCENE with overrides, compared to
# round-off; the runs end with exit status $want (default 0).  The
# one-process run has one thread and the test holds both cores: run after
# the ranks, it left one of them idle; it now runs beside them (the runs
# are independent: their own folders, the comparison after both).
across() { # label, scene, ranks, overrides...
  local label=$1 scene=$2 n=$3 want=${want:-0} one_pid=""
  shift 3
  local one=$work/$label-1 many=$work/$label-$n
  if [ ! -d "$one" ]; then
    "$bin" run "$scene" --out "$one" --quiet "$@" >/dev/null \
      2>"$work/err1" &
    one_pid=$!
  fi
  ranks "$n" "$bin" run "$scene" --out "$many" --quiet "$@" >/dev/null \
    2>"$work/err"
  local rc=$?
  [ -z "$one_pid" ] || wait "$one_pid"
  check "$label on $n ranks: exit $want (got $rc)" test $rc -eq "$want"
  roundoff "$label, $n ranks against one process" "$one" "$many"
}

# Run SCENE with overrides on N ranks into OUT and send SIGTERM to rank 0
# (its pid is in summary.json) once history.csv has $rows rows (default 3), which stops
# every rank after the step with a checkpoint; mpirun forwards a signal of
# its own about 2 s late, or not before it gives up on its ranks (docs/user-guide.md,
# "Across MPI ranks").
interrupt() { # ranks, out, scene, overrides...
  local n=$1 out=$2 scene=$3 job pid
  shift 3
  ranks "$n" "$bin" run "$scene" --out "$out" --quiet "$@" >/dev/null \
    2>"$work/err" &
  job=$!
  for _ in $(seq 600); do
    [ -f "$out/history.csv" ] &&
      [ "$(wc -l <"$out/history.csv")" -gt "${rows:-3}" ] && break
    sleep 0.05
  done
  pid=$(sed -n 's/^ *"pid": \([0-9]*\).*/\1/p' "$out/summary.json")
  kill -TERM "$pid"
  wait $job
  check "interrupted on $n ranks: status interrupted" \
    grep -q '"status": "interrupted"' "$out/summary.json"
}

# Resume copies of the interrupted run OUT on each count of ranks (1: one
# process, without mpirun) into OUT-N; they end with exit status $want
# (default 0).  The one-process resume (one thread) runs beside the
# ranks' (as in across); its exit status is checked last.
resume_on() { # out, counts...
  local out=$1 want=${want:-0} n rc one_pid=""
  shift
  for n in "$@"; do cp -r "$out" "$out-$n"; done
  for n in "$@"; do
    if [ "$n" -eq 1 ]; then
      "$bin" resume "$out-1" --quiet >/dev/null 2>"$work/err1" &
      one_pid=$!
      continue
    fi
    ranks "$n" "$bin" resume "$out-$n" --quiet >/dev/null 2>"$work/err"
    rc=$?
    check "interrupted, resumed on $n: exit $want (got $rc)" \
      test $rc -eq "$want"
  done
  if [ -n "$one_pid" ]; then
    wait "$one_pid"
    rc=$?
    check "interrupted, resumed on 1: exit $want (got $rc)" \
      test $rc -eq "$want"
  fi
}

# A run of SCENE with overrides that fails: on N ranks it stops every rank
# with one process's message (what PATTERN matches of it: the step, the
# point or particle by its index on one process), exit 2, status unstable.
# The one-process run beside the ranks' (as in across).
fails_alike() { # label, ranks, pattern, scene, overrides...
  local label=$1 n=$2 pattern=$3 scene=$4 rc one_pid
  shift 4
  "$bin" run "$scene" --out "$work/$label-1" --quiet "$@" >/dev/null \
    2>"$work/err1" &
  one_pid=$!
  ranks "$n" "$bin" run "$scene" --out "$work/$label-$n" --quiet "$@" \
    >/dev/null 2>"$work/err"
  rc=$?
  wait "$one_pid"
  check "$label on $n ranks: exit 2 (got $rc)" test $rc -eq 2
  check "$label on $n ranks: one process's message" \
    grep -qF "$(grep -o "$pattern" "$work/err1")" "$work/err"
  check "$label on $n ranks: status unstable" \
    grep -q '"status": "unstable"' "$work/$label-$n/summary.json"
}
