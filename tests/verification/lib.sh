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
