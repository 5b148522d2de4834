#!/usr/bin/env bash
# The interface flux against the finite-element referee: case F3 60%
# (constrained extension) at three Poisson ratios (0.3, 0.45, 0.495) and
# three resolutions (h = 1.09e-2, 8.02e-3, 5.19e-3 m), for each FPM
# formulation given (default: all five), by dynamic relaxation.  Prints one
# table: the top reaction's error against FE, the displacement NRMSE at the
# FE lattice and the wall time per run; the runs are in
# out/study-flux/FORM-nuNU/convergence.{md,csv}.
#   benchmarks/study-flux.sh [BUILD_DIR] [FORM ...]
#   FORM: paper     IIPG, linear jump, p = 20 (the FPM paper)
#         p0        IIPG, linear jump, p = 0 (no penalty: inconsistent)
#         sipg      SIPG, linear jump, p = 100
#         sipg-quadratic  SIPG, quadratic jump, p = 100 (the symmetric
#                   flux needs this penalty for coercivity: p = 10 diverges
#                   in undamped dynamics)
#         quadratic IIPG, quadratic jump, p = 0.05 (the block scenes')
bench_name=study-flux bench_out=${STUDY_OUT:-out}/study-flux
bench_env="SIZES STUDY_OUT"
# shellcheck source=bench-lib.sh
. "$(dirname "$0")/bench-lib.sh"
shift || true
forms=("$@")
[ ${#forms[@]} -gt 0 ] || forms=(paper p0 sipg sipg-quadratic quadratic)
sizes=${SIZES:-8.72e-3,6.42e-3,4.15e-3}
table=$out/study-flux.md
{
  bench_stamp
  echo
  echo "| formulation | nu | points | reaction error | NRMSE | wall (s) |"
  echo "|---|---|---|---|---|---|"
} >"$table"
for name in "${forms[@]}"; do
  fpm_form "$name"
  for nu in 0.3 0.45 0.495; do
    fe=cases/fe/f3-extension-60
    [ "$nu" = 0.495 ] || fe=$fe-nu$nu
    dir=$out/$name-nu$nu
    "$bin" convergence --overwrite cases/fpm/f3-extension-60.yaml \
      --quiet "${form[@]}" --set materials.0.poisson_ratio="$nu" \
      --set output.every=1000000 --reference "fe:$fe" \
      --set-ladder discretization.mesh_size="$sizes" --out "$dir" \
      >"$dir.log" 2>&1 || true
    awk -F, -v f="$name" -v nu="$nu" '
      NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
      { printf "| %s | %s | %s | %s | %s | %s |\n", f, nu, $c["points"],
          ($c["status"] == "converged" ? sprintf("%+.2f%%", 100 * $c["reaction_error"]) : $c["status"]),
          $c["error"], $c["wall_seconds"] }' "$dir/convergence.csv" >>"$table"
  done
done
cat "$table"
