# Shared by the shell verification tests: a scratch directory removed on
# exit, and check NAME COMMAND... which counts passes and failures.
# VERBOSE_CHECKS=1 also prints the passes.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
passes=0

check() { # name, condition-command...
  local name=$1
  shift
  if "$@"; then
    passes=$((passes + 1))
    [ "${VERBOSE_CHECKS:-0}" = 1 ] && echo "ok: $name"
    return 0
  else
    failures=$((failures + 1))
    echo "FAIL: $name"
    [ -f "$work/err" ] && sed 's/^/    stderr: /' "$work/err" | head -5
    return 0
  fi
}

# nrows: the complete lines of OUT/history.csv, as wc -l counts them (0
# while it does not exist), read by the shell itself: wait_rows asks a
# hundred times a second, and a wc and a sleep started each time took
# about 3 ms of CPU a poll from the run it waits on.
count_rows() { # out
  nrows=0
  [ -f "$1/history.csv" ] || return 0
  local lines
  mapfile lines <"$1/history.csv"
  nrows=${#lines[@]}
  if [ "$nrows" -gt 0 ] && [ "${lines[nrows - 1]: -1}" != $'\n' ]; then
    nrows=$((nrows - 1))
  fi
}

# Rows in OUT/history.csv (0 while it does not exist).
rows() { count_rows "$1"; echo "$nrows"; }

# A pause of 10 ms without starting a process: a read from a FIFO that
# nothing writes, timing out.
pause() {
  if [ -z "${pause_fd:-}" ]; then
    mkfifo "$work/pause"
    exec {pause_fd}<>"$work/pause"
  fi
  read -r -t 0.01 -u "$pause_fd" _ || true
}

# Wait while process PID runs and OUT/history.csv holds fewer than N lines
# (at most about a minute).
wait_rows() { # pid, out, lines
  local waited=0
  count_rows "$2"
  while [ "$nrows" -lt "$3" ] && kill -0 "$1" 2>/dev/null &&
    [ $waited -lt 6000 ]; do
    pause
    waited=$((waited + 1))
    count_rows "$2"
  done
}

# Column NAME of the row whose first field is LEVEL in a convergence.csv.
col() { # csv, level, name
  awk -F, -v lv="$2" -v name="$3" '
    NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i; next }
    $1 == lv { print $c }' "$1"
}

# A command that must refuse its input: exit status 1, TEXT in its error
# output, and nothing written at OUT.
refused() { # label, text, out, command...
  local label=$1 text=$2 out=$3
  shift 3
  "$@" >/dev/null 2>"$work/err"
  local rc=$?
  check "$label: exit 1 (got $rc)" test $rc -eq 1
  check "$label: message" grep -qF -- "$text" "$work/err"
  check "$label: nothing written" test ! -e "$out"
}

# A bad scene made from SCENE by a sed expression: exit 1 from
# `run`, the message "FILE:LINE:COL: ... MESSAGE" at the line matching
# PATTERN, and no output dir ($bin and $work set by the caller).
bad_scene() { # name, scene, sed expression, line pattern, message
  local name=$1 scene=$2 expr=$3 pattern=$4 msg=$5 f="$work/$1.yaml"
  sed "$expr" "$scene" >"$f"
  if cmp -s "$f" "$scene"; then # the sed expression must change the scene
    check "$name: sed expression applies" false
    return
  fi
  local line
  line=$(grep -n -- "$pattern" "$f" | head -1 | cut -d: -f1)
  "$bin" run "$f" --out "$work/out-$name" --quiet >/dev/null 2>"$work/err"
  local rc=$?
  check "$name: exit status 1 (got $rc)" test $rc -eq 1
  check "$name: names $f:$line:<col>" grep -Eq "$f:$line:[0-9]+: " "$work/err"
  check "$name: says '$msg'" grep -qF -- "$msg" "$work/err"
  check "$name: no output created" test ! -e "$work/out-$name"
}

# Run SCENE in the background and send it SIGTERM once OUT/history.csv
# holds LINES lines (0: once OUT exists, the setup begun; ksp: once a
# linear solve has begun, by the -pm_ksp_monitor the arguments must ask
# for) and SECONDS more have passed; sets rc (its exit status) and lag
# (seconds from the signal to the exit).
stop_after() { # lines, seconds, out, scene, args...
  local n=$1 secs=$2 out=$3 scene=$4
  shift 4
  "$bin" run "$scene" --out "$out" --quiet "$@" >"$work/stdout" 2>"$work/err" &
  local pid=$!
  if [ "$n" != ksp ] && [ "$n" -gt 0 ]; then
    wait_rows $pid "$out" "$n"
  else
    local waited=0
    while kill -0 $pid 2>/dev/null && [ $waited -lt 6000 ]; do
      if [ "$n" = ksp ]; then
        grep -q "KSP Residual norm" "$work/stdout" && break
      elif [ -e "$out" ]; then
        break
      fi
      sleep 0.01
      waited=$((waited + 1))
    done
  fi
  sleep "$secs"
  local t0
  t0=$(date +%s.%N)
  kill -TERM $pid 2>/dev/null
  # STOP_AGAIN=SECONDS: a second SIGTERM that long after the first.
  if [ -n "${STOP_AGAIN:-}" ]; then
    sleep "$STOP_AGAIN"
    kill -TERM $pid 2>/dev/null
  fi
  wait $pid
  rc=$?
  lag=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')
}
