#!/usr/bin/env bash
# The main job: installs what is needed, builds stereobench, generates the built-in scenes and
# describes each of them.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
jobs=$(nproc)

bash ci/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"

./build/apps/stereobench scenes generate --all --out out/scenes
for f in out/scenes/*.glb out/scenes/*.gltf; do
  [ -e "$f" ] || continue
  ./build/apps/stereobench scenes info "$f"
done
