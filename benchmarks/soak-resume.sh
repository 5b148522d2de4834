#!/bin/bash
# The soak: one run (the MPM shock tube, reduced) interrupted INTERRUPTIONS
# times at points drawn from SEED, by SIGTERM and SIGKILL mixed, resumed
# after each, and compared bit for bit with the straight run
# (tests/verification/soak.sh, which ctest runs with 10).  Prints the
# interruptions by signal and the checks.
# usage: benchmarks/soak-resume.sh [BUILD_DIR]   (INTERRUPTIONS: 50; SEED:
#        the draw, 1; TMPDIR: where the runs go, the system's)
bench_name=soak bench_env="INTERRUPTIONS SEED TMPDIR"
source "$(dirname "$0")/bench-lib.sh"
rmdir "$out" 2>/dev/null || true
bash tests/verification/soak.sh "$bin" . "${INTERRUPTIONS:-50}" "${SEED:-1}"
