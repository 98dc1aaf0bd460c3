#!/usr/bin/env bash
# The main job: installs what is needed, builds stereobench, generates the built-in scenes,
# renders the default scene with every registered pipeline (images under out/render) and prints
# a side-by-side timing table.
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
for p in $($sb pipelines | awk '/^[a-z]/ {print $1}'); do
  $sb render --scene "$scene" --pipeline "$p" --resolution "$resolution" --out out/render >/dev/null
  echo "rendered $p -> out/render/${scene}_${p}_*.png"
done
$sb bench --scene "$scene" --resolution "$resolution" --baseline plain-raster --repetitions 3 --warmup 1 \
  --json out/render/bench.json
