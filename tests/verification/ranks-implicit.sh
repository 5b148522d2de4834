#!/usr/bin/env bash
# Newton across MPI ranks: the shared Newton layer (ranks_newton: a chain
# of nonlinear springs against its exact solution and one process's, for
# every linear solver) and the implicit MPM across ranks against the same
# runs on one process.
# Usage: ranks-implicit.sh POINTMECH SOURCE_DIR RANKS_NEWTON
set -u
bin=$1
src=$2
newton=$3
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/ranks-lib.sh"

for n in 2 3; do
  ranks $n "$newton" >"$work/out" 2>"$work/err"
  rc=$?
  sed "s/^/newton on $n ranks: /" "$work/out"
  check "newton on $n ranks: every check holds (exit $rc)" test $rc -eq 0
done

# Case I2's loading on a window of its image (tests/data/scenes/
# i2-window.yaml: the paper's slice, one particle per pixel, 16 384 of
# them; the whole slice's 262 144 made the I2 runs below 40 of the test's
# 57 s) at 64^2 cells, on 2 ranks with GMRES + GAMG against one process,
# to round-off (measured 5e-14: the ranks' sums come in another order; the
# Newton iterates are the same; GMRES takes other iteration counts on
# other ranks, a column held to no bound).  (3 ranks: the resumed runs
# below; LU across ranks: ranks_newton and ranks_fpm.)
i2=$src/cases/mpm/i2-vessel-slice.yaml
window=$src/tests/data/scenes/i2-window.yaml
bounds="linear_iterations=inf" across i2-gamg "$window" 2 \
  --set discretization.mesh_size=2.1e-6 \
  --set time.quasi_static.linear_solver=gmres-gamg \
  --set 'time.quasi_static.solver_options=-pm_ksp_rtol 1e-10'
# summary.json's shares: every particle and every unknown on exactly one
# rank, the ghosts those of the one face the ranks share (65 nodes of the
# cut's x, 2 unknowns each, less the prescribed ones at the grips)
check "I2 on 2 ranks: the ranks' particles and unknowns add up" $py -c "
import json, sys
s = json.load(open(sys.argv[1]))
r = s['ranks']
assert r['count'] == 2 and sum(r['particles']) == s['points'], r
assert sum(r['unknowns']) == s['unknowns'], (r, s['unknowns'])
assert all(0 < g <= 2 * 65 for g in r['ghost_unknowns']), r
assert r['halo_bytes_per_product'] == 8 * sum(r['ghost_unknowns']) / 2, r
" "$work/i2-gamg-2/summary.json"

# Interrupted on 2 ranks and resumed (the window at 32^2 cells, CG +
# Jacobi, whose iterates repeat bit for bit across ranks: LU (MUMPS) and
# GAMG across ranks schedule their work as messages arrive, so their runs
# repeat to round-off only): on 2 ranks bit for bit the run not
# interrupted, on one process and on 3 ranks to round-off.  In 6 load
# steps, not the scene's 10: the interruption still comes after about the
# third, and the straight run and the three resumed ones each have 4 load
# steps fewer to make.
jacobi="--set time.quasi_static.linear_solver=cg-jacobi
  --set time.quasi_static.load_steps=6"
ranks 2 "$bin" run "$window" --out "$work/j-2" --quiet $jacobi >/dev/null 2>&1
interrupt 2 "$work/cut" "$window" $jacobi
echo "I2 interrupted on 2 ranks after $(($(wc -l <"$work/cut/history.csv") - 1)) load steps"
resume_on "$work/cut" 1 2 3
check "I2 interrupted on 2 ranks, resumed on 2: the run of 2 ranks, bit for bit" \
  $same "$work/j-2" "$work/cut-2"
# (CG on other ranks may take an iteration more or less: a count, held to
# no bound; so is the residual at convergence, some 1e-13 of the
# reactions, round-off itself, as for the slab below)
for n in 1 3; do
  bounds="linear_iterations=inf residual=inf" roundoff \
    "I2 interrupted on 2 ranks, resumed on $n" "$work/j-2" "$work/cut-$n"
done

# Frames and checkpoints in pieces (output.ranks: auto; the runs above
# too): no rank holds the whole model.  A small slab (1600 particles,
# tests/data/scenes/implicit-slab-2d.yaml) in 40 load steps on 2 and 3
# ranks against one process, read in one-process order, with its
# summary's figures; gathered (output.ranks: gather) against in pieces;
# interrupted on 2 ranks (a checkpoint in pieces) and resumed on 1, 2 and
# 3; interrupted on one process (a whole checkpoint) and resumed in pieces
# on 2.  (The residual at convergence, some 1e-13 of the reactions, is
# round-off itself: held to no bound, as CG's iteration counts; so are the
# places of the smallest J and the largest stress, which particles equal
# but for round-off share.)
slab=$src/tests/data/scenes/implicit-slab-2d.yaml
long="--set time.quasi_static.load_steps=40 --set output.every=4"
export bounds="linear_iterations=inf residual=inf"
across slab "$slab" 2 $long
across slab "$slab" 3 $long
check "slab on 2 ranks: a piece a rank a frame" \
  test "$(ls "$work/slab-2/results" | grep -c '\.piece_')" -eq \
  $((2 * $(ls "$work/slab-2/results" | grep -c '^frame_[0-9]*\.h5$')))
for n in 2 3; do
  check "slab on $n ranks: the mesh and the summary's figures" \
    $py "$src/tests/verification/same_figures.py" "$work/slab-1" \
    "$work/slab-$n" points,particles,grid_nodes,groups,steps,load_steps,unknowns \
    strain_energy,mean_strain_energy_density,max_von_mises,end_min_jacobian,min_jacobian,load_reached 1
done
ranks 2 "$bin" run "$slab" --out "$work/slabg-2" --quiet $long \
  --set output.ranks=gather >/dev/null 2>&1
check "slab on 2 ranks gathered: frames whole" \
  test ! -e "$work/slabg-2/results/frame_000001.piece_0000.h5"
roundoff "slab on 2 ranks, gathered against in pieces" "$work/slabg-2" \
  "$work/slab-2"
interrupt 2 "$work/scut" "$slab" $long
check "slab interrupted on 2 ranks: its checkpoint in pieces" \
  compgen -G "$work/scut/checkpoint.pieces/*.piece_0001.h5"
resume_on "$work/scut" 1 2 3
check "slab interrupted on 2 ranks, resumed on 2: bit for bit" \
  $same "$work/slab-2" "$work/scut-2"
for n in 1 3; do
  roundoff "slab interrupted on 2 ranks, resumed on $n" "$work/slab-2" \
    "$work/scut-$n"
done
interrupt 1 "$work/scut1" "$slab" $long
resume_on "$work/scut1" 2
roundoff "slab interrupted on one process, resumed on 2 ranks" \
  "$work/slab-1" "$work/scut1-2"
unset bounds

# What runs on one process only is refused, naming the key, before
# anything is written; plan prints the decomposition.
for kv in "mpm.implicit.grid=reset:mpm.implicit.grid" \
  "mpm.implicit.operator=matrix-free:mpm.implicit.operator" \
  "mpm.fbar=cell:mpm.fbar"; do
  set_kv=${kv%%:*} key=${kv#*:}
  refused "I2 with $set_kv on 2 ranks" "$key" "$work/refused" \
    ranks 2 "$bin" run "$i2" --out "$work/refused" --set "$set_kv"
done
ranks 2 "$bin" plan "$i2" >"$work/plan" 2>&1
check "plan on 2 ranks: the decomposition" grep -q "^ranks        2:" \
  "$work/plan"
check "plan on 2 ranks: each rank's share" grep -qE "^ +1 +131072 " \
  "$work/plan"

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
