#!/usr/bin/env bash
# The main job: installs what is needed, builds stereobench, generates the built-in scenes,
# validates every registered pipeline on the default scene against the built-in ground truth
# (records and images under out/validate, a table on the terminal) and prints a side-by-side
# timing table.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
jobs=$(nproc)

bash ci/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"

sb=./build/apps/stereobench
$sb scenes generate --all --out out/scenes
scene=bistro
resolution=960x540
# Every registered pipeline's right eye against the built-in ground truth (full ray tracing):
# metrics, hole statistics, images and one JSON record per pipeline under out/validate.
$sb validate --scene "$scene" --resolution "$resolution" --pipelines all --truth full --out out/validate
# Their timings side by side, medians over repetitions, speed-ups against plain-raster.
$sb bench --scene "$scene" --resolution "$resolution" --baseline plain-raster --repetitions 3 --warmup 1 \
  --json out/validate/bench.json
