#!/bin/bash
# A step's particle migration on 2 ranks, two ways (tools/bench_migration.c):
# PETSc's DMSwarm (DMSwarmMigrate on the ranks' field) against the
# exchange of records src/mpm/mpm_par does (neighbour collectives, the
# arrivals merged in one-process order), for 10 000 particles a rank (the
# shock tube's) and 88 000 (the full oocyte's), 0 to 10 000 of them leaving
# a step; each line the median and fastest seconds of a step over STEPS
# steps (200).
# usage: benchmarks/bench-migration.sh [BUILD_DIR]
bench_name=migration bench_env=STEPS
source "$(dirname "$0")/bench-lib.sh"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
tool=$(dirname "$bin")/bench-migration
steps=${STEPS:-200}
for n in 10000 88000; do
  OMP_NUM_THREADS=1 mpirun -np 2 --bind-to core "$tool" "$n" "$steps" \
    0 10 100 1000 5000 | { [ $n = 10000 ] && cat || tail -n +2; }
done
