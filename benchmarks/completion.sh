#!/bin/bash
# The hard block cases' completion matrix: F3 at 60, 100 and 200% and F4
# at 20, 40 and 60% (the clamped scenes, cases/fpm/), each by static
# solves and by dynamic relaxation, at the budgets of 1851, 4036 and 13762
# points (mesh_size 8.72e-3, 6.42e-3, 4.15e-3; the scenes' own clouds and
# formulation, the defaults), one run a cell in turn, each stopped by
# SIGTERM after TIMEOUT seconds of wall (default 3600).  One line a run:
# the outcome, the points, the load reached, the top face's reaction and its
# error against the FE referee (cases/fe/README.md: F3 against C3D20R
# N = 20; F4 20% and 40% against the Richardson limits of their graded
# C3D20 ladders, 40% uncertain by 5.3%; F4 60% has no converged referee),
# CPU and wall seconds, peak memory, and the solver's counts.
#   CASES="f3-extension-200 f4-compression-40"   the cases (default: all six)
#   SOLVERS="static"                             static, dynamic-relaxation
#   SIZES="6.42e-3"                              mesh_size budgets
#   OMP_NUM_THREADS                              default 1
# usage: benchmarks/completion.sh [BUILD_DIR]   (hours for the whole matrix)
bench_name=completion
bench_env="CASES SOLVERS SIZES TIMEOUT OMP_NUM_THREADS"
source "$(dirname "$0")/bench-lib.sh"
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
cases=${CASES:-f3-extension-60 f3-extension-100 f3-extension-200 \
f4-compression-20 f4-compression-40 f4-compression-60}
solvers=${SOLVERS:-static dynamic-relaxation}
sizes=${SIZES:-8.72e-3 6.42e-3 4.15e-3}
printf '| case | mesh_size | solver | points | outcome | load reached | '
printf 'top reaction (N) | against FE | CPU s | wall s | peak MiB | counts |\n'
printf '|---|---|---|---|---|---|---|---|---|---|---|---|\n'
for c in $cases; do
  for h in $sizes; do
    for q in $solvers; do
      d=$out/$c-$h-$q
      rm -rf "$d"
      set +e
      timeout -s TERM "${TIMEOUT:-3600}" /usr/bin/time -f "%U %S %e %M" \
        -o "$d.time" "$bin" run "cases/fpm/$c.yaml" --out "$d" --quiet \
        --set discretization.mesh_size="$h" \
        --set time.quasi_static.method="$q" --set output.every=100000 \
        >"$d.log" 2>&1
      rc=$?
      set -e
      $py - "$c" "$h" "$q" "$d" "$rc" <<'PY'
import json, os, sys
c, h, q, d, rc = sys.argv[1:6]
# The referees' figures (cases/fe/README.md), top face's z reaction.
ref = {"f3-extension-60": 14.16684, "f3-extension-100": 19.9714,
       "f3-extension-200": 31.3785, "f4-compression-20": -9.056931,
       "f4-compression-40": -20.28253}
s = {}
if os.path.exists(d + "/summary.json"):
    try:
        s = json.load(open(d + "/summary.json"))
    except ValueError:
        s = {}
# /usr/bin/time's last line (a failed run's first says its status)
t = []
if os.path.exists(d + ".time"):
    lines = [l for l in open(d + ".time").read().splitlines() if l.strip()]
    t = lines[-1].split() if lines else []
cpu = f"{float(t[0]) + float(t[1]):.0f}" if len(t) >= 4 else ""
wall = f"{float(t[2]):.0f}" if len(t) >= 4 else ""
peak = f"{int(t[3]) / 1024:.0f}" if len(t) >= 4 else ""
outcome = {"124": "timed out"}.get(rc, s.get("status", f"exit {rc}"))
r = s.get("reactions", {}).get("zmax", [None] * 3)[2]
err = f"{100 * (r / ref[c] - 1):+.2f}%" if r is not None and c in ref else ""
if q == "static":
    reached = s.get("time", "")
    counts = (f"{s.get('static_load_steps', '')} steps, "
              f"{s.get('static_cuts', '')} cuts, "
              f"{s.get('static_newton_iterations', '')} Newton, "
              f"{s.get('static_linear_iterations', '')} linear")
else:
    ramp = 1.0
    reached = min(1.0, s.get("time", 0) / ramp) if s else ""
    counts = (f"{s.get('steps', '')} steps, energy balance "
              f"{s.get('energy_balance_error', 0):.2g}, smallest J "
              f"{s.get('min_jacobian', 0):.3g}")
rs = f"{r:.5f}" if r is not None else ""
rd = f"{reached:.4g}" if isinstance(reached, float) else str(reached)
print(f"| {c} | {h} | {q} | {s.get('points', '')} | {outcome} | {rd} | "
      f"{rs} | {err} | {cpu} | {wall} | {peak} | {counts} |")
PY
    done
  done
done
