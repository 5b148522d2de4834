#!/usr/bin/env bash
# `pointmech bench`:
#  - the CI suite (cases/bench/tiny.yaml: F2 coarse by FPM, the explicit and
#    the implicit MPM) writes its report, every method within its own
#    tolerance of the exact field (FPM and implicit MPM 1e-6, explicit MPM
#    5e-3, the bound of verify_mpm_f2) and of the FE referee's reaction;
#  - the hard cases, coarse (cases/bench/hard-tiny.yaml): every outcome
#    in one table (F4 between plates by a static solve among them), the panel against its FE
#    referee's tip displacement;
#  - FE beside every method (cases/bench/cost-tiny.yaml): CalculiX on
#    N = 2, 4, 6 timed in the same table as FPM, errors against the
#    referee decreasing with N, the figure drawn; the referee's own mesh
#    marked reference, not measured against itself; without ccx the FE row
#    says so and FPM's rows stand;
#  - a two-case suite whose second case goes unstable: the failure is
#    listed with its diagnosis, the first case still reported, exit 2;
#  - variants of one method under labels, with their own overrides;
#  - a bad suite refused at its FILE:LINE:COL before anything runs.
set -u
bin=$1
src=$2
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
VERBOSE_CHECKS=1
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"
le() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && a + 0 <= b + 0) }'; }
lt() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && a + 0 < b + 0) }'; }
# Column NAME of the method row (CASE, LABEL) of a bench.csv, at its last
# (finest) resolution.
field() { # csv, case, label, name
  /usr/bin/python3 - "$@" <<'EOF'
import csv, sys
path, case, label, name = sys.argv[1:5]
last = ""
for r in csv.DictReader(open(path, newline="")):
    if r["kind"] == "method" and r["case"] == case and r["label"] == label:
        last = r[name]
print(last)
EOF
}

# Runs suite into $work/NAME with more arguments: out, rc (its exit
# status) and csv set, its progress printed.
run_suite() { # name, suite, more arguments
  out=$work/$1
  local suite=$2
  shift 2
  "$bin" bench "$suite" --out "$out" --quiet "$@" >"$out.log" 2>"$work/err"
  rc=$?
  cat "$out.log"
  csv=$out/bench.csv
}

# ---- the CI suite --------------------------------------------------------
run_suite tiny "$src/cases/bench/tiny.yaml"
check "tiny: exit 0 (got $rc)" test $rc -eq 0
for f in bench.md bench.csv f2/h-0.0125/compare.md f2/h-0.02/fpm/summary.json \
  f2/h-0.02/mpm/summary.json f2/h-0.02/mpm-implicit/summary.json; do
  check "tiny: $f written" test -s "$out/$f"
done
check "tiny: progress printed" grep -qF "[2/2] f2 at 0.0125" "$out.log"
csv=$out/bench.csv
for m in fpm mpm mpm-implicit; do
  s=$(field "$csv" f2 $m status)
  check "tiny: $m converged ($s)" test "$s" = converged
done
# Measured: FPM 1.7e-16, implicit MPM 8e-15, explicit MPM 1.8e-3 against
# the exact field; reactions against FE 2.6e-8, 2.6e-8, 3.3e-5.
for m in fpm mpm-implicit; do
  e=$(field "$csv" f2 $m nrmse_analytic)
  check "tiny: $m NRMSE $e < 1e-6" lt "$e" 1e-6
done
e=$(field "$csv" f2 mpm nrmse_analytic)
check "tiny: mpm NRMSE $e <= 5e-3" le "$e" 5e-3
for m in fpm mpm mpm-implicit; do
  r=$(field "$csv" f2 $m reaction_error_fe)
  check "tiny: $m reaction error $r within 1%" \
    awk -v r="$r" 'BEGIN { exit !(r != "" && r * r <= 1e-4) }'
  t=$(field "$csv" f2 $m wall_seconds)
  check "tiny: $m wall time $t tabulated" lt 0 "$t"
done
check "tiny: the FE referee's recorded ladder tabulated" \
  grep -q '^fe-recorded,f2,,fe,CalculiX' "$csv"
check "tiny: bench.md table" \
  grep -Eq '^\| f2 \| 0.02 \| mpm-implicit \| converged \|' "$out/bench.md"
# The verdict: FPM and the implicit MPM hold F2's exact state at both
# resolutions, within the referee's own tolerance (1e-5 on the reaction).
for m in fpm mpm-implicit; do
  check "tiny: verdict on $m" grep -Eq \
    "^\| f2 \| $m \| [0-9]+ -> [0-9]+ \|.*\| agrees with FE within its tolerance \|$" \
    "$out/bench.md"
done
if /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
  check "tiny: accuracy-cost.png drawn" test -s "$out/accuracy-cost.png"
fi
refused "tiny again: refused without --overwrite" \
  'already holds a bench' "$out/none" \
  "$bin" bench "$src/cases/bench/tiny.yaml" --out "$out" --quiet

# ---- FE beside every method (cost-tiny.yaml) ----------------------------
# F3 60%: FPM at 237 points and CalculiX on N = 2, 4, 6, each timed, each
# against the referee (N = 20, cases/fe/f3-extension-60).  Measured: FE
# +2.47%, +1.10%, +0.38%; FPM (static, default) at 237 points about +5%.
if command -v ccx >/dev/null && /usr/bin/python3 -c 'import numpy' 2>/dev/null
then
  run_suite cost-tiny "$src/cases/bench/cost-tiny.yaml"
  check "cost-tiny: exit 0 (got $rc)" test $rc -eq 0
  fe_rows() { # name: the column of the fe rows, coarsest first
    /usr/bin/python3 - "$csv" "$1" <<'EOF2'
import csv, sys
print(" ".join(r[sys.argv[2]] for r in csv.DictReader(open(sys.argv[1]))
               if r["kind"] == "method" and r["label"] == "fe"))
EOF2
  }
  check "cost-tiny: three FE rows, N = 2 4 6 ($(fe_rows fe_n))" \
    test "$(fe_rows fe_n)" = "2 4 6"
  check "cost-tiny: every FE mesh converged ($(fe_rows status))" \
    test "$(fe_rows status)" = "converged converged converged"
  read -r e2 e4 e6 <<<"$(fe_rows reaction_error_fe)"
  check "cost-tiny: FE errors decrease with N ($e2 > $e4 > $e6 > 0)" \
    awk -v a="$e2" -v b="$e4" -v c="$e6" \
    'BEGIN { exit !(a != "" && c != "" && a + 0 > b + 0 && b + 0 > c + 0 && c + 0 > 0) }'
  # The referee's own differences (its ladder.csv): 14.516944, 14.322796,
  # 14.220632 against 14.16684 N.
  check "cost-tiny: FE N = 2 at +2.47% of the referee ($e2)" \
    awk -v e="$e2" 'BEGIN { exit !(e != "" && (e - 0.02471) ^ 2 < 1e-8) }'
  read -r n2 n4 n6 <<<"$(fe_rows nrmse_fe)"
  check "cost-tiny: FE NRMSE at the lattice decreases ($n2 > $n4 > $n6)" \
    awk -v a="$n2" -v b="$n4" -v c="$n6" \
    'BEGIN { exit !(c != "" && a + 0 > b + 0 && b + 0 > c + 0 && c + 0 > 0) }'
  for t in wall_seconds cpu_seconds memory_bytes; do
    v=$(fe_rows $t)
    check "cost-tiny: FE $t timed ($v)" \
      awk -v v="$v" 'BEGIN { n = split(v, a, " "); ok = n == 3;
        for (i = 1; i <= n; i++) ok = ok && a[i] + 0 > 0; exit !ok }'
  done
  check "cost-tiny: one thread, as the suite asks ($(fe_rows threads))" \
    test "$(fe_rows threads)" = "1 1 1"
  s=$(field "$csv" f3-60 fpm-static status)
  check "cost-tiny: FPM converged ($s)" test "$s" = converged
  t=$(field "$csv" f3-60 fpm-static cpu_seconds)
  check "cost-tiny: FPM's CPU time tabulated ($t)" lt 0 "$t"
  r=$(field "$csv" f3-60 fpm-static reaction_error_fe)
  check "cost-tiny: FPM's reaction within 10% of the referee ($r)" \
    awk -v r="$r" 'BEGIN { exit !(r != "" && r * r <= 0.01) }'
  check "cost-tiny: FE rows in bench.md" grep -Eq \
    '^\| f3-60 \| N 4 \| fe \| converged \| 141 \|' "$out/bench.md"
  check "cost-tiny: ccx's threads said" grep -q \
    'FE of f3-60: ccx with 1 thread (OMP_NUM_THREADS' "$out/bench.md"
  check "cost-tiny: the FE levels' lattices kept" \
    test -s "$out/f3-60/fe/f3-extension-60/lattice-N6.csv"
  if /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
    check "cost-tiny: accuracy-cost.png drawn" test -s "$out/accuracy-cost.png"
  fi
  # A referee of N = 2, 4 (made here), given on the command line: N = 4
  # is its own mesh, marked reference and not measured against itself.
  # FPM coarse (3e-2) and quick: these runs check the FE rows alone.
  cat >"$work/cost-ref.yaml" <<EOF2
name: cost-ref
methods: [{label: fpm-static, method: fpm, set: [time.quasi_static.method=static]}]
cases:
  - {name: f3-60, scene: $src/cases/fpm/f3-extension-60.yaml,
     resolutions: [3e-2], fe: {ladder: [2, 4], threads: 1}}
EOF2
  /usr/bin/python3 "$src/tools/fe-referee.py" f3-extension-60 --run \
    --ladder 2,4 --out "$work/ref" --work "$work/ref-work" >"$work/ref.log" 2>&1
  run_suite cost-ref "$work/cost-ref.yaml" \
    --set "reference.fe=$work/ref/f3-extension-60"
  check "cost-ref: N = 4 is the reference ($(fe_rows status))" \
    test "$(fe_rows status)" = "converged reference"
  # N = 2 against N = 4: 14.516944 / 14.322796 - 1.
  read -r e2 e4 <<<"$(fe_rows reaction_error_fe)"
  check "cost-ref: N = 2 against the referee N = 4 ($e2), none for N = 4 ($e4)" \
    awk -v e="$e2" -v f="$e4" \
    'BEGIN { exit !(f == "" && e != "" && (e - 0.013555) ^ 2 < 1e-10) }'
  # Without ccx on PATH (a stand-in ssh for MPI's start-up alone): the FE
  # row says so, FPM's rows stand.
  mkdir -p "$work/noccx"
  printf '#!/bin/sh\nexit 1\n' >"$work/noccx/ssh"
  chmod +x "$work/noccx/ssh"
  out=$work/cost-noccx
  PATH=$work/noccx "$bin" bench "$work/cost-ref.yaml" --out "$out" --quiet \
    >"$out.log" 2>"$work/err"
  rc=$?
  csv=$out/bench.csv
  check "cost-noccx: exit 0 without ccx (got $rc)" test $rc -eq 0
  check "cost-noccx: the FE row says ccx is missing" grep -q \
    '^method,f3-60,,fe,fe,not-run,.*CalculiX (ccx) is not on PATH' "$csv"
  s=$(field "$csv" f3-60 fpm-static status)
  check "cost-noccx: FPM converged all the same ($s)" test "$s" = converged
else
  echo "bench: no ccx or numpy: the FE rows are not checked"
fi

# ---- the hard cases, coarse ----------------------------------------------
# hard-tiny.yaml: the near-incompressible panel at 157 points, F3 200% and
# F4 60% at 237, F4 between plates, the reduced shock tube.  Every run
# completes (exit 0); F4 between plates by a static solve (contact in
# Newton's problem) converges at 237 points to +21.61% against the contact
# referee (graded C3D20 N = 4 to 14, face-to-face contact, limit -23.238 N,
# uncertain by 1.8%), its faces glued to the plates as the referee ties
# them (sticking plates, which let the faces' corners go: +18.35%).  The
# bound, 25%, follows the referee, not the code: the same scene at 1851
# points is +6.0% (docs/validation.md, "F4 between plates: the ladder
# and the contact law").
run_suite hard-tiny "$src/cases/bench/hard-tiny.yaml"
check "hard-tiny: exit 0, every run completed (got $rc)" test $rc -eq 0
md=$out/bench.md
s=$(field "$csv" f4-plates-40 fpm-static status)
check "hard-tiny: the plates by a static solve converged ($s)" \
  test "$s" = converged
t=$(field "$csv" f4-plates-40 fpm-static reaction_error_fe)
check "hard-tiny: the plates' reaction within 25% of the contact referee ($t)" \
  awk -v t="$t" 'BEGIN { exit !(t != "" && t * t <= 0.25 * 0.25) }'
check "hard-tiny: the plates in the table" grep -Eq \
  '^\| f4-plates-40 \| 0.02 \| fpm-static \| converged \|' "$md"
for m in fpm-static fpm-paper; do
  s=$(field "$csv" panel $m status)
  check "hard-tiny: panel by $m converged ($s)" test "$s" = converged
  t=$(field "$csv" panel $m tip_error_fe)
  check "hard-tiny: panel by $m: tip error $t tabulated" \
    awk -v t="$t" 'BEGIN { exit !(t != "" && t + 0 > -1 && t + 0 < 1) }'
done
# The default formulation (the quadratic jump, p = 0.05) at 157 points
# against the referee's tip displacement (1.3935 m, CPE8R N = 16):
# measured -4.3%.
t=$(field "$csv" panel fpm-static tip_error_fe)
check "hard-tiny: panel by the default within 5% of FE ($t)" \
  awk -v t="$t" 'BEGIN { exit !(t != "" && t * t <= 0.05 * 0.05) }'
check "hard-tiny: the referee's tip ladder tabulated" \
  grep -q '^fe-recorded,panel,,fe,CalculiX CPE8R,converged,.*,[-0-9.e]*,,,,$' "$csv"
# F3 200% at 237 points against its referee (31.38 N, C3D20R N = 20):
# the default formulation measured +9.2%, the paper's +160%.
t=$(field "$csv" f3-200 fpm-static reaction_error_fe)
p=$(field "$csv" f3-200 fpm-paper reaction_error_fe)
check "hard-tiny: F3 200% by the default within 10% of FE ($t)" \
  awk -v t="$t" 'BEGIN { exit !(t != "" && t * t <= 0.10 * 0.10) }'
check "hard-tiny: F3 200% by the default ($t) within a tenth of the paper's error ($p)" \
  awk -v t="$t" -v p="$p" 'BEGIN { exit !(t != "" && p != "" && 10 * t * t <= p * p / 10) }'
for c in f3-200 f4-60; do
  s=$(field "$csv" $c fpm-static status)
  check "hard-tiny: $c's outcome recorded ($s)" test -n "$s"
  check "hard-tiny: $c in the table" grep -Eq "^\| $c \| 0.02 \| fpm-static \| $s \|" "$md"
done
s=$(field "$csv" m2-shock-tube mpm status)
check "hard-tiny: the shock tube completed ($s)" \
  test "$s" = completed

# ---- a failing case does not stop the suite ------------------------------
# The second case runs the explicit MPM at 25 times its stable step.
suite=$work/two.yaml
cat >"$suite" <<EOF
name: two
methods:
  - {label: linear, method: mpm-implicit}
  - {label: quadratic, method: mpm-implicit, set: [mpm.shape=quadratic, time.quasi_static.linear_solver=direct, time.quasi_static.load_steps=5]}
  - {label: explicit, method: mpm}
cases:
  - {name: unstable, scene: $src/cases/mpm/f2-unconstrained-compression.yaml,
     methods: [explicit], resolutions: [2e-2], set: [time.dt=0.05]}
  - {name: variants, scene: $src/cases/fpm/f2-unconstrained-compression.yaml,
     methods: [linear, quadratic], resolutions: [2e-2]}
EOF
out=$work/two
"$bin" bench "$suite" --out "$out" --quiet >"$out.log" 2>"$work/err"
rc=$?
cat "$out.log"
check "two: exit 2, a numerical failure (got $rc)" test $rc -eq 2
check "two: the error names the failed case" \
  grep -qF '1 of 2 comparisons had a failure (the first: unstable' "$work/err"
check "two: progress of the second case" grep -qF "[2/2] variants" "$out.log"
s=$(field "$out/bench.csv" unstable explicit status)
check "two: the failed case's status ($s)" test "$s" = unstable
check "two: its diagnosis listed (step, cause)" \
  grep -Eq '^- unstable at 0.02, explicit \(unstable\): step [0-9]+' \
  "$out/bench.md"
for m in linear quadratic; do
  s=$(field "$out/bench.csv" variants $m status)
  check "two: variant $m ran after the failure ($s)" test "$s" = converged
done
# The labels run one method with their own overrides: both shape
# functions hold F2's homogeneous state (the quadratic one since the
# conditions extend the field beyond a face: measured 8e-15 and 1.8e-15),
# and the quadratic label's own 5 load steps show in its row.
e=$(field "$out/bench.csv" variants linear nrmse_analytic)
check "two: linear variant exact ($e < 1e-6)" lt "$e" 1e-6
e=$(field "$out/bench.csv" variants quadratic nrmse_analytic)
check "two: quadratic variant exact ($e < 1e-6)" lt "$e" 1e-6
s=$(field "$out/bench.csv" variants quadratic steps)
check "two: quadratic variant its own load steps ($s)" test "$s" = 5
s=$(field "$out/bench.csv" variants linear steps)
check "two: linear variant the scene's load steps ($s)" test "$s" != 5

# ---- a bad suite: refused before anything runs --------------------------
bad() { # label, sed expression, text
  sed "$2" "$suite" >"$work/bad.yaml"
  refused "$1" "$3" "$work/bad-out" "$bin" bench "$work/bad.yaml" \
    --out "$work/bad-out"
}
bad "unknown key" 's/  - {name: variants,/  - {nmae: variants,/' \
  "bad.yaml:9:6: cases.1.nmae: unknown key (expected one of name,"
bad "unknown label" 's/methods: \[linear, quadratic\]/methods: [linear, cubic]/' \
  "cases.1.methods.1: cubic is neither a label of the suite's methods nor a method"
bad "unknown method" 's/method: mpm}/method: mpn}/' \
  "methods.2.method: expected one of"
bad "bad resolution" 's/resolutions: \[2e-2\]}/resolutions: [-1]}/' \
  "bad.yaml:10:50: cases.1.resolutions.0: expected a size above 0 (m), got -1"
bad "method as an override" 's/set: \[time.dt=0.05\]/set: [method=fpm]/' \
  "not an override"
bad "FE ladder not ascending" \
  's/resolutions: \[2e-2\]}/resolutions: [2e-2], fe: {ladder: [4, 2]}}/' \
  "cases.1.fe.ladder.1: expected a mesh N above the one before (coarsest first), got 2"
bad "FE threads" \
  's/resolutions: \[2e-2\]}/resolutions: [2e-2], fe: {ladder: [2], threads: 0}}/' \
  "cases.1.fe.threads: expected a number of threads for CalculiX, 1 to 256, got 0"
bad "missing scene" 's#cases/mpm/f2-unconstrained-compression.yaml#no-such.yaml#' \
  "cases.0.scene: cannot read scene"

echo "bench: $passes passed, $failures failed"
[ "$failures" -eq 0 ]
