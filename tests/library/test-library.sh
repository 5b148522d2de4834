#!/usr/bin/env bash
# pointmech as a library, as a user meets it: `cmake --install` to a fresh
# prefix; examples/ configured and built out of tree against it through
# find_package(pointmech); its F2 run (coarse) against the installed
# program's `pointmech run` of the same scene and overrides: the same step
# count, top reaction and displacements to round-off; and a C program built
# by pkg-config alone (and the same file as C++: the header's extern "C").
#   test-library.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$1 build=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix

cmake --install "$build" --prefix "$prefix" >/dev/null
cmake -S "$src/examples" -B "$tmp/example" -DCMAKE_PREFIX_PATH="$prefix" \
  >/dev/null
cmake --build "$tmp/example" >/dev/null

scene=$src/cases/fpm/f2-unconstrained-compression.yaml
sets=(discretization.mesh_size=2.5e-2 time.end=2
  time.quasi_static.tolerance=1e-6)
"$tmp/example/f2-library" "$scene" "${sets[@]}" >"$tmp/library.txt"
cat "$tmp/library.txt"
args=()
for s in "${sets[@]}"; do args+=(--set "$s"); done
"$prefix/bin/pointmech" run "$scene" "${args[@]}" --out "$tmp/run" --quiet

/usr/bin/python3 - "$tmp/library.txt" "$tmp/run" <<'PY'
import json, sys
import h5py, numpy as np
lib = {}
for line in open(sys.argv[1]):
    k, _, v = line.partition(" ")
    lib[k] = v.split()
run = json.load(open(sys.argv[2] + "/summary.json"))
with h5py.File(sys.argv[2] + "/results.h5", "r") as f:
    frames = f["frames"]
    u = frames[sorted(frames)[-1]]["displacement"][()]
def same(what, a, b):
    a, b = float(a), float(b)
    ok = abs(a - b) <= 1e-12 * max(abs(a), abs(b), 1e-300)
    print(f"{what}: library {a!r}, pointmech run {b!r}", "" if ok else "DIFFER")
    return ok
ok = lib["status"][0] == run["status"] == "converged"
print("status:", lib["status"][0], run["status"])
ok &= same("steps", lib["steps"][0], run["steps"])
ok &= same("top reaction z", lib["reaction_zmax"][2], run["reactions"]["zmax"][2])
ok &= same("largest u_x", lib["u_x_max"][0], u[:, 0].max())
ok &= same("smallest u_z", lib["u_z_min"][0], u[:, 2].min())
sys.exit(0 if ok else 1)
PY

# pkg-config alone: the flags it gives, and the loader told where the
# library is (the prefix is not on its path).
pc=$(dirname "$(find "$prefix" -name pointmech.pc)")
flags=$(PKG_CONFIG_PATH=$pc pkg-config --cflags --libs pointmech)
cc -std=c11 -Wall -Werror "$src/examples/pkgconfig/scene_check.c" $flags \
  -o "$tmp/scene-check"
c++ -x c++ -Wall -Werror "$src/examples/pkgconfig/scene_check.c" $flags \
  -o "$tmp/scene-check-cxx"
libdir=$(PKG_CONFIG_PATH=$pc pkg-config --variable=libdir pointmech)
LD_LIBRARY_PATH=$libdir "$tmp/scene-check"
LD_LIBRARY_PATH=$libdir "$tmp/scene-check-cxx" >/dev/null
