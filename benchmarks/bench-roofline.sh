#!/bin/bash
# The explicit kernels' roofline: the machine's roofs (roofline-peak.c,
# built for the build's -march and for the machine's own, timed by CPU
# time), each kernel's instructions per point-step (callgrind, one thread:
# the count of a run of S2 steps less that of S1 steps, over the points and
# S2 - S1), its share of the step, its flops and bytes per point-step (the
# kernel read line by line: the table below) and their ratio, and the rate
# the step attains against the roof, from runs on 1 and 2 threads timed by
# CPU time (user + system: what the machine's other processes take is not
# counted) and by the wall clock.  Cases: FPM F2 at 1851 points (the
# paper's formulation, Table 1), the MPM 3-D quadratic block (110592
# particles) and the shock tube (20000 particles).
# usage: benchmarks/bench-roofline.sh [BUILD_DIR]   (CASES="f2 block tube":
#        the cases to run; STEPS: the timed runs' steps, 400 (block 40);
#        NO_CALLGRIND=1 skips the counts)
bench_name=roofline bench_env="CASES STEPS NO_CALLGRIND"
source "$(dirname "$0")/bench-lib.sh"
cases=${CASES:-f2 block tube}
steps=${STEPS:-400}
arch=$(sed -n 's/^PM_ARCH:STRING=//p' "$build/CMakeCache.txt" 2>/dev/null)
arch=${arch:-x86-64-v2}
echo "load: $(uptime)"

# ---- roofs --------------------------------------------------------------
# the build's roof (its -march, no fused multiply-add, as the build) and the
# machine's (its own widest vectors and fused multiply-adds)
for m in "$arch -ffp-contract=off" "native -ffp-contract=fast"; do
  # shellcheck disable=SC2086
  cc -O3 -march=$m -fopenmp benchmarks/roofline-peak.c -o "$out/peak"
  echo "roofs, -march=$m (CPU time):"
  "$out/peak"
done

# ---- instruction counts -------------------------------------------------
# case -> scene, the function whose calls are counted, the two step counts
spec() {
  case $1 in
  f2) echo "cases/fpm/f2-unconstrained-compression.yaml fpm_run 20 120" ;;
  block) echo "cases/mpm/bench-block.yaml mpm_step 2 4" ;;
  tube) echo "cases/mpm/m2-shock-tube.yaml mpm_step 10 30" ;;
  esac
}
count() { # case steps: callgrind's counts of the case at that many steps
  local c=$1 s=$2 scene tog
  read -r scene tog _ _ <<<"$(spec "$c")"
  OMP_NUM_THREADS=1 POINTMECH_WAIT_POLICY=default valgrind --tool=callgrind \
    --toggle-collect="$tog" --callgrind-out-file="$out/cg-$c-$s.out" \
    "$bin" run --overwrite "$scene" --out "$out/cg-$c-$s" --quiet \
    --set time.max_steps="$s" --set output.every=1000000 >"$out/cg-$c-$s.log" 2>&1 || true
  callgrind_annotate --inclusive=yes --threshold=100 "$out/cg-$c-$s.out" \
    >"$out/cg-$c-$s.txt"
}
if [ -z "${NO_CALLGRIND:-}" ]; then
  for c in $cases; do
    read -r _ _ s1 s2 <<<"$(spec "$c")"
    count "$c" "$s1"
    count "$c" "$s2"
  done
fi

# ---- timings ------------------------------------------------------------
timed() { # case threads: CPU seconds (user + system) of runs of n and 2n steps
  local c=$1 t=$2 scene n=$steps k
  read -r scene _ _ _ <<<"$(spec "$c")"
  [ "$c" = block ] && n=$((steps / 10))
  for k in 1 2; do
    OMP_NUM_THREADS=$t /usr/bin/time -f "%U %S" -o "$out/time-$c-t$t-$k" \
      "$bin" run --overwrite "$scene" --out "$out/run-$c-t$t-$k" --quiet \
      --set time.max_steps=$((k * n)) --set output.every=1000000 >/dev/null 2>&1 || true
  done
}
for c in $cases; do
  for t in 1 2; do timed "$c" "$t"; done
done

$py - "$out" "$cases" <<'PY'
import json, re, sys
out, cases = sys.argv[1], sys.argv[2].split()
# Kernels: callgrind's inclusive count of the functions matching each
# pattern (one thread: the parallel regions' outlined functions).
KERNELS = {
  'f2': [('stress: gradient, P(F)', r'stress_pass\._omp'),
         ('flux', r'flux_pass\._omp|fpm_stream_flux\._omp'),
         ('gather', r'gather_pass\._omp|fpm_stream_gather\._omp'),
         ('boundary', r'boundary_pass\._omp'),
         ('update and sums', r'fpm_run\._omp')],
  'block': [('p2g', r'mpm_stage_p2g$'), ('grid update', r'mpm_stage_grid_update$'),
            ('g2p', r'mpm_stage_g2p$'), ('remap', r'mpm_stage_remap$'),
            ('stress', r'^solid_stress$'), ('move', r'mpm_stage_move$'),
            ('stable step', r'mpm_stage_time_step$')],
}
KERNELS['tube'] = [(n, p.replace('solid', 'fluid')) for n, p in KERNELS['block']]
# Flops and bytes per point-step, counted in the source (docs/validation.md,
# "Explicit kernels: roofline and cuts", says how): flops per support
# entry, flops per point, bytes per entry, bytes per point (FPM: per
# entry times the mean entries a point; MPM: per particle).
COUNTS = {
    # F2's entries streamed in padded blocks of four (fpm_stream.c, 13.4
    # padded entries a point for 11.79): bytes a real entry are the
    # stream's per padded entry times 13.4 / 11.79 (gradient 28, flux 156,
    # gather 28 a padded entry).
    'f2': {'stress: gradient, P(F)': (21, 130, 32, 200),
           'flux': (175, 111, 177, 368), 'gather': (18, 18, 32, 144),
           'boundary': (0, 10, 0, 40), 'update and sums': (0, 75, 0, 214)},
    'block': {'p2g': (0, 920, 0, 136), 'grid update': (0, 15, 0, 70),
              'g2p': (0, 520, 0, 100), 'remap': (0, 290, 0, 56),
              'stress': (0, 900, 0, 260), 'move': (0, 3, 0, 72),
              'stable step': (0, 0, 0, 0)},
    'tube': {'p2g': (0, 275, 0, 136), 'grid update': (0, 3, 0, 16),
             'g2p': (0, 165, 0, 96), 'remap': (0, 86, 0, 56),
             'stress': (0, 330, 0, 150), 'move': (0, 3, 0, 72),
             'stable step': (0, 0, 0, 0)},
}
SPEC = {'f2': (20, 120), 'block': (2, 4), 'tube': (10, 30)}

def inclusive(path):
    rows = []
    for line in open(path):
        m = re.match(r'\s*([\d,]+) \([^)]*\)\s+\S*?:?([^\s:]+) \[', line)
        if m:
            rows.append((int(m.group(1).replace(',', '')), m.group(2)))
    return rows

def per_kernel(c, s):
    rows = inclusive(f'{out}/cg-{c}-{s}.txt')
    total = max(r[0] for r in rows)
    got = {name: sum(v for v, f in rows if re.search(pat, f))
           for name, pat in KERNELS[c]}
    return total, got

def summary(path):
    try:
        return json.load(open(path))
    except OSError:
        return None

for c in cases:
    s1, s2 = SPEC[c]
    try:
        (t1, k1), (t2, k2) = per_kernel(c, s1), per_kernel(c, s2)
    except (OSError, ValueError):
        print(f'{c}: no callgrind counts (run without NO_CALLGRIND)')
        continue
    sm = summary(f'{out}/cg-{c}-{s2}/summary.json')
    pts = sm['points']
    ent = 2 * sm.get('interfaces', 0) / pts if c == 'f2' else 0
    ps = pts * (s2 - s1)
    total = (t2 - t1) / ps
    print(f'\n{c}: {pts} points, {ent:.2f} support entries a point' if ent
          else f'\n{c}: {pts} particles')
    print(f'{"kernel":24s} {"instr/pt-step":>13s} {"share":>6s} {"flops":>7s} '
          f'{"bytes":>7s} {"flop/B":>7s}')
    fl_sum = by_sum = 0
    for name, _ in KERNELS[c]:
        ir = (k2[name] - k1[name]) / ps
        fe, fp, be, bp = COUNTS[c][name]
        fl, by = fe * ent + fp, be * ent + bp
        fl_sum += fl
        by_sum += by
        ai = f'{fl / by:7.2f}' if by else '      -'
        print(f'{name:24s} {ir:13.0f} {ir / total:6.1%} {fl:7.0f} {by:7.0f} {ai}')
    other = total - sum((k2[n] - k1[n]) / ps for n, _ in KERNELS[c])
    print(f'{"other (serial, runtime)":24s} {other:13.0f} {other / total:6.1%}')
    print(f'{"step":24s} {total:13.0f} {1:6.1%} {fl_sum:7.0f} {by_sum:7.0f} '
          f'{fl_sum / by_sum:7.2f}')
    cpu1 = None
    for t in (1, 2):
        r1 = summary(f'{out}/run-{c}-t{t}-1/summary.json')
        r2 = summary(f'{out}/run-{c}-t{t}-2/summary.json')
        if not r1 or not r2:
            continue
        cpu = [sum(map(float, open(f'{out}/time-{c}-t{t}-{k}').read().split()))
               for k in (1, 2)]
        n = r1['points'] * (r2['steps'] - r1['steps'])
        dcpu = cpu[1] - cpu[0]  # the CPU seconds of the extra steps
        dwall = r2['step_seconds'] - r1['step_seconds']
        cpu1 = cpu1 or dcpu
        # (a loaded machine can make the longer run's steps the faster)
        wall = f'{n / dwall:.3g}' if dwall > 0 else 'n/a'
        print(f'  {t} thread(s): {wall} point-steps/s by the wall '
              f'clock, {n / dcpu:.3g} per CPU second (CPU-time '
              f'efficiency {cpu1 / dcpu:.0%}): '
              f'{fl_sum * n / dcpu / 1e9:.2f} GFLOP/s, '
              f'{by_sum * n / dcpu / 1e9:.2f} GB/s, '
              f'{total * n / dcpu / 1e9:.2f} G instructions/s a core')
PY
