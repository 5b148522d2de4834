#!/bin/bash
# What crash-safe output costs: each frame is its own synced HDF5 file and
# the index and XDMF are rewritten after it; a checkpoint is the whole state
# in one synced file.  Measured within one run per scene (F2 by FPM at the
# paper's coarse resolution, the shock tube by MPM at the paper's size), on
# every core, as seconds per frame and per checkpoint beside the seconds per
# step, and as the fraction of step time at the scene's own output.every
# and at a checkpoint every 1000 steps.
# usage: benchmarks/bench-output.sh [BUILD_DIR]   (STEPS: steps per run, 2000;
#        EVERY: frames and checkpoints every EVERY steps in the run, 100)
bench_name=output bench_env="STEPS EVERY"
source "$(dirname "$0")/bench-lib.sh"
steps=${STEPS:-2000}
every=${EVERY:-100}
printf '%-32s %9s %6s %6s %6s %11s %11s %11s %12s %12s\n' case points steps \
  frames ckpts "s/step" "s/frame" "s/ckpt" "frames(%)" "ckpt/1000(%)"
for scene in cases/fpm/f2-unconstrained-compression.yaml \
  cases/mpm/m2-shock-tube.yaml; do
  name=$(basename "$(dirname "$scene")")-$(basename "$scene" .yaml)
  dir="$out/$name"
  bench_run "$dir" "$scene" --set time.max_steps="$steps" \
    --set output.every="$every" --set output.checkpoint.every="$every" || true
  s="$dir/summary.json"
  scene_every=$(sed -n 's/^output: {every: \([0-9]*\).*/\1/p' "$scene")
  $py - "$s" "$name" "$(json "$s" stage_seconds output)" \
    "$(json "$s" stage_seconds checkpoint)" "${scene_every:-100}" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
name, out_s, ck_s, scene_every = sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5])
steps, frames = s["steps"], s["frames"]
per_step = s["step_seconds"] / steps
n_ck = s["checkpoints"]
per_frame = out_s / frames
per_ck = ck_s / max(1, n_ck)
print("%-32s %9d %6d %6d %6d %11.3e %11.3e %11.3e %12.2f %12.3f" % (
    name, s["points"], steps, frames, n_ck, per_step, per_frame, per_ck,
    100 * per_frame / (scene_every * per_step),
    100 * per_ck / (1000 * per_step)))
EOF
done
echo "frames(%): one frame's cost over the step time between two frames at the"
echo "scene's output.every; ckpt/1000(%): a checkpoint every 1000 steps, likewise."
