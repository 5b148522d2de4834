#!/usr/bin/env bash
# How safe is the stable-step estimate?  For cases F2 (unconstrained 40%
# compression) and F3 (constrained 60% extension) at h = 1.09e-2, finds by
# bisection the largest step, as a multiple of the bound of eqs. 24-26,
# with which the quasi-static run stays stable (no inverted subdomain, no
# energy created beyond stability.max_energy_error) and prints its ratio
# to the bound and to the measured spectral step.
# QS=none runs plain dynamics (no damping) to END seconds (default 2)
# instead of dynamic relaxation; only the symmetric flux conserves energy
# there.
#   benchmarks/bench-dt.sh [BUILD_DIR]   FLUX=iipg|sipg  PENALTY=p  QS=...  END=s
bench_name=dt bench_env="FLUX PENALTY QS END"
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
num() { sed -n "s/.*$1 *\([0-9.eE+-]*\) s.*/\1/p" | head -1; }
echo "largest stable step, flux $flux, penalty $penalty, ${QS:-dynamic-relaxation}"
printf '%-22s %11s %11s %11s %9s %9s %7s\n' case dt_paper dt_spectral \
  dt_max "/paper" "/spectral" trials
for c in f2-unconstrained-compression f3-extension-60; do
  scene=cases/fpm/$c.yaml
  sets=(--set discretization.mesh_size="$(paper_mesh_size 1.09e-2)"
    --set fpm.flux="$flux" --set fpm.penalty="$penalty"
    --set output.every=1000000)
  if [ "${QS:-dynamic-relaxation}" = none ]; then
    sets+=(--set time.quasi_static.method=none --set time.end="${END:-2}")
  else
    sets+=(--set time.end="${END:-10}")
  fi
  plan=$("$bin" plan "$scene" "${sets[@]}")
  paper=$(echo "$plan" | num "bound of eqs. 24-26:")
  spectral=$(echo "$plan" | num "spectral (power iteration):")
  lo=1 hi=32 trials=0 # multiples of the paper bound; lo is stable
  while awk -v l="$lo" -v h="$hi" 'BEGIN { exit !(h / l > 1.02) }'; do
    mid=$(awk -v l="$lo" -v h="$hi" 'BEGIN { printf "%.6g", sqrt(l * h) }')
    dt=$(awk -v f="$mid" -v p="$paper" 'BEGIN { printf "%.6g", f * p }')
    trials=$((trials + 1))
    if bench_run "$out/$c" "$scene" "${sets[@]}" --set time.dt="$dt"; then
      lo=$mid
    else
      rc=$?
      # exit 3 (not converged in time) is stable; 2 is a numerical failure
      if [ $rc -eq 3 ]; then lo=$mid; else hi=$mid; fi
    fi
  done
  dtmax=$(awk -v f="$lo" -v p="$paper" 'BEGIN { printf "%.4g", f * p }')
  printf '%-22s %11.4g %11.4g %11s %9.2f %9.2f %7d\n' "$c" \
    "$paper" "$spectral" "$dtmax" "$lo" \
    "$(awk -v m="$dtmax" -v s="$spectral" 'BEGIN { print m / s }')" "$trials"
done
