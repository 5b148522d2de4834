#!/usr/bin/env bash
# Write the seeds of fuzz harness TARGET (tests/fuzz/fuzz_TARGET.c) into
# folder DIR, from the project's files of that kind; POINTMECH (the
# program) runs a short case for the checkpoint and results seeds.
#
#   tests/fuzz/seeds.sh TARGET DIR [POINTMECH]
set -euo pipefail
target=$1 dir=$2 prog=${3:-}
here=$(cd "$(dirname "$0")/../.." && pwd)
shared=/work/shared/data

# A scene, a NUL byte, then KEY=VALUE lines (fuzz_scene.c reads them so).
scene_seed() { # NAME SCENE OVERRIDE...
  local name=$1 scene=$2
  shift 2
  {
    cat "$here/$scene"
    printf '\0'
    printf '%s\n' "$@"
  } >"$dir/$name"
}

# Four little-endian bytes of $1.
le32() {
  printf "\\x$(printf %02x $(($1 & 255)))\\x$(printf %02x $(($1 >> 8 & 255)))"
  printf "\\x$(printf %02x $(($1 >> 16 & 255)))\\x$(printf %02x $(($1 >> 24 & 255)))"
}

# A results folder and a checkpoint from three steps of a small case.
short_run() {
  local out=$dir/.run
  [ -d "$out" ] && return
  [ -n "$prog" ] || {
    echo "seeds.sh: $target seeds need the pointmech program" >&2
    exit 1
  }
  ASAN_OPTIONS=detect_leaks=0 "$prog" run --quiet \
    "$here/tests/data/scenes/minimal-2d.yaml" -o "$out" \
    --set time.max_steps=3 --set output.every=1 \
    --set output.checkpoint.every=1 >/dev/null
}

case $target in
scene)
  find "$here/cases" "$here/tests/data/scenes" -name '*.yaml' \
    -exec cp {} "$dir"/ \;
  scene_seed set-f2 tests/data/scenes/f2-unconstrained-compression.yaml \
    discretization.mesh_size=8.02e-3 time.dt=1e-3 \
    boundary.3.displacement.z=-0.06 time.quasi_static.tolerance=1e-9 \
    "output.fields=[force, jacobian]" materials.0.poisson_ratio=0.3
  scene_seed set-grow tests/data/scenes/minimal-2d.yaml \
    time.quasi_static.method=damping "fpm.penalty=50" \
    'bodies=[{material: rubber, region: "x - 0.5"}]' "boundary=[]" \
    boundary.0.on=xmax "boundary.0.velocity.x=100*t" \
    "reference.displacement.x=0.1*x"
  scene_seed set-expr tests/data/scenes/f2-unconstrained-compression.yaml \
    "boundary.3.displacement.z=-0.02*sin(2*pi*t)*exp(-t)" \
    "reference.displacement.x=0.1*x^2-abs(y)" "boundary.4.traction.x=1/(t+1)"
  scene_seed set-mpm cases/mpm/m2-sod.yaml "mpm.flip=0.5" "time.end=1e-4" \
    "gravity=[0, 0, -9.81]"
  ;;
tiff)
  find "$here/cases" "$here/tests/data" -iname '*.tif*' -exec cp {} "$dir"/ \;
  ;;
raw)
  # nx ny nz bits, then the voxels.
  { printf '\x04\x03\x02\x08' && head -c 24 /dev/zero | tr '\0' '\7'; } \
    >"$dir/u8-4x3x2"
  { printf '\x02\x02\x01\x10' && printf '\x01\x00\xff\xff\x00\x01\x10\x20'; } \
    >"$dir/u16-2x2x1"
  printf '\x03\x01\x01\x08\x00\x80\xff' >"$dir/u8-3x1x1"
  ;;
points)
  [ -f $shared/vesselslice25_512.pts ] &&
    head -n 40 $shared/vesselslice25_512.pts >"$dir/vessel-head.pts"
  find "$here/tests/data" -name '*.pts' -exec sh -c \
    'head -n 40 "$1" >"$2/$(basename "$1")"' _ {} "$dir" \;
  printf 'x,y,z,area\n0,0,0,1e-12\n1e-6,0,0,1e-12\n0,1e-6,2e-6,1e-12\n' \
    >"$dir/cloud-area.csv"
  printf '# voxel centres\n0.5 0.5\n1.5 0.5 1.5\n15.5 15.5 3.5\n' \
    >"$dir/centres.xyz"
  ;;
table)
  find "$here/cases" "$here/tests/data" -name '*.csv' -size -8k \
    -exec sh -c 'cp "$1" "$2/$(echo "$1" | tr / _)"' _ {} "$dir" \;
  printf 'time,step,wall_seconds\n0,0,0.1\n1e-3,1,0.2\n2e-3,2,0.3\n' \
    >"$dir/history.csv"
  ;;
gmsh)
  find "$here/tests/data" "$here/cases" -name '*.msh' -size -16k \
    -exec cp {} "$dir"/ \;
  ;;
checkpoint)
  short_run
  cp "$dir/.run/checkpoint.h5" "$dir/checkpoint.h5"
  ;;
index)
  short_run
  sep=$'\n--pm-fuzz-file--\n'
  n=$(grep -o '"points": *[0-9]*' "$dir/.run/summary.json" | grep -o '[0-9]*$')
  for keep in 0 1; do
    {
      le32 "$n"
      cat "$dir/.run/results.h5"
      printf '%s' "$sep"
      cat "$dir/.run/results/mesh.h5"
      if [ $keep = 1 ]; then
        printf '%s' "$sep"
        cat "$dir/.run/results/frame_000000.h5"
      fi
    } >"$dir/results-keep$keep"
  done
  ;;
pipe)
  /usr/bin/python3 "$here/tests/fuzz/pipe_seeds.py" "$dir"
  ;;
*)
  echo "seeds.sh: no target $target" >&2
  exit 1
  ;;
esac
rm -rf "$dir/.run"
