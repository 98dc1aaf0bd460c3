#!/usr/bin/env bash
# Installs what the tests need, builds stereobench, runs the whole test suite, then rebuilds the
# loader and rig tests with AddressSanitizer + UndefinedBehaviorSanitizer and runs them again.
# Usage: ci/test.sh            (from anywhere; builds into build/ and build-sanitize/)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
jobs=$(nproc)

# The ground-truth provider tests run Blender and POV-Ray, the metric tests scikit-image, the report
# test Chromium.
bash ci/install-deps.sh validator blender povray skimage chromium slurm

echo "== build (Release, warnings as errors)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DSB_WERROR=ON >/dev/null
cmake --build build -j"$jobs"

echo "== tests"
ctest --test-dir build -j"$jobs" --output-on-failure --timeout 900

echo "== sanitizer build (address + undefined): loader and rig tests"
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug -DSB_SANITIZE=ON -DSB_WERROR=ON -DSB_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-sanitize -j"$jobs" --target stereobench sb_loader_tests sb_renderer_tests
ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-sanitize -j"$jobs" --output-on-failure -L 'loader|renderer' --timeout 900
