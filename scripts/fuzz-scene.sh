#!/usr/bin/env bash
# Fuzz the scene loader: scripts/fuzz.sh scene (see there).
#
#   scripts/fuzz-scene.sh [SECONDS | -runs=N] [LIBFUZZER OPTION]...
exec "$(dirname "$0")/fuzz.sh" scene "$@"
