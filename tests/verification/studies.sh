#!/usr/bin/env bash
# The block studies of the FPM paper through `pointmech convergence`, with
# figures printed beside wall times:
#  - F1 penalty study (2D, 157 points): p = 0 is inconsistent, p >= 20 close
#    to p = 100 (paper's upper figures: extension 1.54e-2, compression
#    7.01e-2);
#  - observed rates of F3 60% extension and F4 20% compression on coarse
#    ladders against a finer run (self-convergence, --reference last):
#    q >= 1.6 (paper 2.02 and 1.91);
#  - the same ladders with the scenes' own formulation against the
#    finite-element referee: displacement and reaction error rates (see
#    below);
#  - the finest level of those ladders, F3 60% and F4 20% at the paper's
#    coarsest resolution (h = 1.09e-2 m, 1851 points; F4's graded cloud has
#    2009 for that budget), against FE: converged, top reaction within 1%
#    (F3) and 3% (F4), displacement NRMSE at the FE lattice at or below the
#    paper's figure (F3);
#  - F3 200% and F4 60% at the coarsest paper resolution: converged, J > 0
#    throughout, energy balance within 1% of the external work.
# The self-convergence and extreme checks use the symmetric flux
# (fpm.flux: sipg, linear jump, p = 100), the one whose force derives from
# an energy.
#
# One OpenMP thread unless the caller sets OMP_NUM_THREADS: the scenes have
# 157 to 1851 points, where a step is mostly fork/join, and two threads on
# cores shared with another job spin against each other (the F1 ladder took
# about ten times the CPU seconds of one thread on a loaded machine).
set -u
bin=$1
src=$2
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
VERBOSE_CHECKS=1
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"
le() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && a + 0 <= b + 0) }'; }
ge() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && a + 0 >= b + 0) }'; }
json() { # file, key: a number from summary.json
  sed -n "s/^ *\"$2\": \\([-+0-9.eE]*\\),\\{0,1\\}\$/\\1/p" "$1" | head -1
}
rate() { sed -n 's/^Observed rate (.*q = \([-0-9.]*\)\..*/\1/p' "$1"; }
rate_reaction() {
  sed -n 's/^Observed rate of the reaction error: q = \([-0-9.]*\)\..*/\1/p' "$1"
}
absle() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && (a < 0 ? -a : a) <= b + 0) }'; }

# ---- F1 penalty study ------------------------------------------------------
for kind in extension compression-guided; do
  out=$work/f1-$kind
  "$bin" convergence "$src/cases/fpm/f1-$kind.yaml" --quiet \
    --set fpm.formulation=paper --set-ladder fpm.penalty=0,10,20,50,100 \
    --reference last --out "$out" \
    >"$out.log" 2>&1
  check "F1 $kind: the ladder ran (exit $?)" test -f "$out/convergence.csv"
  sed -n '/^|/p' "$out.log"
  e0=$(col "$out/convergence.csv" 1 error)
  e20=$(col "$out/convergence.csv" 3 error)
  e50=$(col "$out/convergence.csv" 4 error)
  check "F1 $kind: p = 0 ($e0) is at least twice p = 20 ($e20)" \
    ge "$e0" "$(awk -v x="$e20" 'BEGIN { print 2 * x }')"
  if [ "$kind" = extension ]; then bound=1.54e-2; else bound=7.01e-2; fi
  check "F1 $kind: p = 50 NRMSE $e50 <= $bound" le "$e50" "$bound"
  if [ "$kind" != extension ]; then
    check "F1 $kind: p = 20 NRMSE $e20 <= $bound" le "$e20" "$bound"
  fi
done

# ---- rates on coarse ladders -----------------------------------------------
# On the uniform clouds (discretization.refine.size_ratio=1: F4 20%'s scene
# is graded toward its clamped faces by default; the rates and bounds here
# were measured on uniform clouds, and F3's scenes are uniform).  No
# stiffening: F4 60%'s scene names one for its default formulation, which
# verification.verify_fe_blocks runs; here every case runs SIPG's.  By
# static solve, as the ladders against FE below: on 4d73feb the rates were
# those of dynamic relaxation to every printed digit (F3 1.976, F4 1.749)
# in 16 CPU seconds against 29.
ladder=discretization.mesh_size=0.025,0.02,0.016,0.0125,0.00872
common="--set fpm.flux=sipg --set fpm.jump=linear --set fpm.penalty=100
  --set fpm.stiffening=0
  --set time.dt_rule=spectral --set discretization.refine.size_ratio=1
  --set time.dt_safety=0.5 --set output.every=100000"
for c in f3-extension-60 f4-compression-20; do
  out=$work/$c
  # shellcheck disable=SC2086
  "$bin" convergence "$src/cases/fpm/$c.yaml" --quiet $common \
    --set time.quasi_static.method=static \
    --set-ladder "$ladder" --reference last --out "$out" >"$out.log" 2>&1
  check "$c: the ladder ran (exit $?)" test -f "$out/convergence.md"
  sed -n '/^|/p' "$out.log"
  q=$(rate "$out/convergence.md")
  check "$c: observed rate q = $q >= 1.6" ge "$q" 1.6
done

# ---- rates against the finite-element referee ------------------------------
# The scenes as committed, with the default formulation (IIPG, quadratic
# jump, p = 0.05, averaged volume), errors of the displacement at the FE
# lattice and of the top reaction against the CalculiX referee the scene
# names.  F3 60% (uniform cloud): both rates >= 1.8 (measured 2.30 and
# 2.62; the FE reaction is converged to 5e-4).  F4 20% runs its scene's
# cloud, graded toward the clamped faces with mesh_size as the point
# budget (237, 351, 544, 889, 2009 points): its displacement rate is held
# to the issue's 1.5 (measured 1.76; the uniform ladder's was 1.36, held to
# 1.25 before the scene was graded; docs/validation.md, "Graded clouds
# relative to mesh_size").  F4's reaction rate is printed, not asserted:
# its errors on this ladder are not monotone (-1.1% at the coarsest level,
# +8.5% at the next), and FE's own reaction converges only at order 1.6
# on meshes graded towards the clamped edges.
# By static solve: the equilibrium dynamic relaxation (the scenes' method)
# comes to, to the solvers' tolerances.  On 13a3af0 the two ladders gave
# the same NRMSE, reaction errors and rates to every printed digit (F3:
# 2.298 and 2.618; F4: 1.764, +2.44% at 2009 points) in 28 CPU seconds
# against 80.  Relaxation against the static solve is checked by
# verification.verify_fpm_static, and relaxation at the extremes below.
for c in f3-extension-60 f4-compression-20; do
  out=$work/fe-$c
  "$bin" convergence "$src/cases/fpm/$c.yaml" --quiet \
    --set time.quasi_static.method=static \
    --set output.every=100000 --set-ladder "$ladder" --out "$out" \
    >"$out.log" 2>&1
  check "$c against FE: the ladder ran (exit $?)" test -f "$out/convergence.md"
  sed -n '/^|/p' "$out.log"
  q=$(rate "$out/convergence.md")
  qr=$(rate_reaction "$out/convergence.md")
  if [ "$c" = f3-extension-60 ]; then
    check "$c against FE: displacement rate q = $q >= 1.8" ge "$q" 1.8
    check "$c against FE: reaction error rate q = $qr >= 1.8" ge "$qr" 1.8
  else
    check "$c against FE: displacement rate q = $q >= 1.5 (measured 1.76)" \
      ge "$q" 1.5
    echo "  $c against FE: reaction error rate q = $qr (not asserted)"
  fi
  # The finest level (mesh size 8.72e-3 m, h = 1.09e-2 m: 1851 points for
  # F3, the budget of F4's graded cloud, 2009 points) is the block scene as
  # committed at the paper's coarsest resolution, against FE: the top
  # reaction within 1% for F3 (measured +0.63%) and within the issue's 3%
  # for F4 20% (measured +2.44% on the graded cloud; the uniform cloud's
  # +6.08% was held to 7%).  F3's displacement NRMSE at the FE lattice at
  # or below the FPM paper's figure for this h, 1.11e-2 (F4 20%'s, 1.41e-2,
  # and on the paper's sampling 1.28e-2, are printed beside the paper's
  # 8.59e-3: not met; docs/validation.md, "F4 20%: displacement NRMSE
  # against the paper").
  csv=$out/convergence.csv
  st=$(col "$csv" 5 status)
  re=$(col "$csv" 5 reaction_error)
  e=$(col "$csv" 5 error)
  check "$c at 1851 points against FE: converged ($st)" test "$st" = converged
  if [ "$c" = f3-extension-60 ]; then
    check "$c at 1851 points against FE: reaction error $re within 1%" \
      absle "$re" 0.01
    check "$c at 1851 points against FE: NRMSE $e <= 1.11e-2 (paper)" \
      le "$e" 1.11e-2
  else
    check "$c at the 1851-point budget against FE: reaction error $re within 3%" \
      absle "$re" 0.03
    ev=$(col "$csv" 5 error_volume)
    echo "  $c at the 1851-point budget against FE: NRMSE $e, on the" \
      "paper's sampling $ev (paper 8.59e-3, not asserted)"
  fi
done

# ---- extreme deformation ---------------------------------------------------
# The coarsest level of the paper's ladder (h = 1.09e-2 m).
for c in f3-extension-200 f4-compression-60; do
  out=$work/x-$c
  # shellcheck disable=SC2086
  "$bin" run "$src/cases/fpm/$c.yaml" --quiet $common \
    --set discretization.mesh_size=8.72e-3 --out "$out" >"$out.log" 2>&1
  rc=$?
  s=$out/summary.json
  check "$c: converged (exit $rc)" grep -q '"status": "converged"' "$s"
  jmin=$(json "$s" min_jacobian)
  ee=$(json "$s" energy_balance_error)
  echo "  $c: steps $(json "$s" steps), wall $(json "$s" wall_seconds) s," \
    "min J $jmin, energy error $ee, max von Mises $(json "$s" max_von_mises) Pa"
  check "$c: J > 0 at every point and step (min $jmin)" ge "$jmin" 1e-6
  ae=$(awk -v x="$ee" 'BEGIN { print (x < 0 ? -x : x) }')
  check "$c: energy balance error |$ee| < 1%" le "$ae" 0.01
  check "$c: no NaN in the summary" sh -c "! grep -qi nan '$s'"
done

echo "studies: $passes passed, $failures failed"
[ "$failures" -eq 0 ]
