#!/usr/bin/env bash
# The Python scripts of tools/ that read a run's HDF5 files (fold-over,
# normal-angles, nrmse-map, plot-membrane-2d, plot-points,
# plot-vessel-stress, render-membrane) read them through python/pointmech, which has the
# program vet each file before h5py opens it: each draws or prints its
# figures from short runs of the kinds it is for, and refuses a run whose
# mesh is a damaged HDF5 file (a string of 4 GB announced, which h5py would
# allocate) with the file's name and HDF5's reason, exit 1, no traceback; a
# damaged frame and a truncated one too.
set -u
bin=$1
src=$2
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
export POINTMECH=$bin # the program that vets the files
py=/usr/bin/python3
tools=$src/tools
damaged=$src/tests/fuzz/upstream/checkpoint/hdf5-string-of-4gb
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"

# Short runs: a 2-D membrane (M5), a 3-D one (M4 reduced), a 2-D block
# pulled on ymax, and a coarse F2 block beside a CalculiX referee of 2
# elements a side (what nrmse-map's --fe-run reads).
{
  cat "$src/tests/data/scenes/minimal-2d.yaml"
  echo "boundary: [{on: ymin, velocity: {x: 0, y: 0}}, {on: ymax, velocity: {x: 0, y: 0.01}}]"
  echo "output: {every: 20}"
} >"$work/pull.yaml"
run() { # name, scene, options...
  local name=$1 scene=$2
  shift 2
  "$bin" run "$scene" "$@" --out "$work/$name" --quiet >/dev/null \
    2>"$work/err"
  check "$name runs" test $? -eq 0
}
run m5 "$src/cases/mpm/m5-gas-circle.yaml" --set time.end=0.01 \
  --set output.every=100
run m4 "$src/cases/mpm/m4-oocyte-reduced.yaml" --set time.end=3e-7 \
  --set output.every=10
run pull "$work/pull.yaml" --set time.end=0.01
f2=$src/cases/fpm/f2-unconstrained-compression.yaml
run f2 "$f2" --set discretization.mesh_size=0.02
"$bin" convergence "$f2" --set-ladder discretization.mesh_size=0.02 \
  --reference "fe:$src/cases/fe/f2-unconstrained-compression" \
  --out "$work/conv" >/dev/null 2>"$work/err"
check "coarse F2 against its referee" test -s "$work/conv/level-1/fe-errors.csv"
$py "$tools/fe-referee.py" f2-unconstrained-compression --run --ladder 2 \
  --keep --work "$work/fe" --out "$work/fe-out" >/dev/null 2>"$work/err"
check "the referee of 2 elements a side is kept" \
  test -d "$work/fe/f2-unconstrained-compression-N2-C3D20R"

# A script refusing a damaged file: exit 1, the message (a regular
# expression) on stderr, no traceback.
reason='HDF5 cannot read attribute format of / \(memory allocation failed'
refused() { # what, message, script and arguments...
  local what=$1 message=$2 rc
  shift 2
  (cd "$tools" && $py "$@") >/dev/null 2>"$work/refused"
  rc=$?
  check "$what refused (exit $rc)" test $rc -eq 1
  check "$what: named, with the reason" grep -qE "$message" "$work/refused"
  check "$what: no traceback" bash -c "! grep -q Traceback '$work/refused'"
}

# Each script's command on a run folder (RUN), as a user types it.
tool() { # key, run folder
  local r=$2
  case $1 in
  fold-over) echo fold-over.py "$r" --travel 0.04 ;;
  normal-angles) echo normal-angles.py "$r" ;;
  nrmse-map) echo nrmse-map.py "$r/fe-errors.csv" --fe-run "$work/fe" \
    --case f2-unconstrained-compression --n 2 ;;
  plot-membrane-2d) echo plot-membrane-2d.py --times 0,0.005 \
    --out "$work/out.png" "A=$r" ;;
  plot-points) echo plot-points.py "$r" --out "$work/out.png" ;;
  plot-vessel-stress) echo plot-vessel-stress.py "$work/out.png" "$r" \
    --voxel 0.05 ;;
  render-membrane) echo render-membrane.py "$r" -o "$work/out.png" ;;
  esac
}
declare -A runs=([fold-over]=f2 [normal-angles]=m5 [nrmse-map]=conv/level-1
  [plot-membrane-2d]=m5 [plot-points]=pull [plot-vessel-stress]=pull
  [render-membrane]=m4)
declare -A says=([fold-over]='points; top face at z = 0\.06: 0 past it'
  [normal-angles]='^0\.01 +91 '
  [nrmse-map]='^\| linear MLS'
  [plot-membrane-2d]='wrote' [plot-points]='out\.png'
  [plot-vessel-stress]='^pull +[0-9]' [render-membrane]='^wrote')
for t in fold-over normal-angles nrmse-map plot-membrane-2d plot-points \
  plot-vessel-stress render-membrane; do
  # shellcheck disable=SC2046 # the command's words, none with a space
  (cd "$tools" && $py $(tool "$t" "$work/${runs[$t]}")) >"$work/good" \
    2>"$work/err"
  check "$t: reads a good run (exit 0)" test $? -eq 0
  check "$t: prints its figures" grep -qE "${says[$t]}" "$work/good"

  # The same run, its mesh a damaged HDF5 file.
  bad=$work/bad-$t
  rm -rf "$bad"
  cp -r "$work/${runs[$t]}" "$bad"
  cp "$damaged" "$bad/results/mesh.h5"
  # shellcheck disable=SC2046
  refused "$t: a damaged mesh" "^$t: $bad/results/mesh.h5: $reason" \
    $(tool "$t" "$bad")
done

# A damaged last frame, and a truncated one (HDF5 cannot open it, so the
# vetting passes it; h5py's refusal is named the same way).
bad=$work/bad-frame
cp -r "$work/pull" "$bad"
frames=("$bad"/results/frame_*.h5)
last=${frames[-1]}
cp "$damaged" "$last"
refused "plot-points: a damaged frame" "^plot-points: $last: $reason" \
  plot-points.py "$bad" --out "$work/out.png"
head -c 3000 "$work/pull/results/${last##*/}" >"$last"
refused "plot-vessel-stress: a truncated frame" \
  "^plot-vessel-stress: $last: HDF5 cannot read it: Unable to open file \(truncated file" \
  plot-vessel-stress.py "$work/out.png" "$bad"

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
