#!/usr/bin/env bash
# Installs what the tests need, builds stereobench, runs the whole test suite, then rebuilds the
# loader and renderer tests (scene loading, rig, animation) and the libraries they use with
# AddressSanitizer + UndefinedBehaviorSanitizer and runs them again. Those rooms start no
# `stereobench` (tests/CMakeLists.txt: SB_LIBRARY_ROOMS), so the sanitizer build leaves out the
# command-line tool and the validation layer: 3.3 min of two cores instead of 7.9. The command
# line's own handling of broken scenes (tests/cli/bad_scene_cli_test.cpp) runs unsanitized.
# Each phase prints its wall time.
# Usage: ci/test.sh            (from anywhere; builds into build/ and build-sanitize/)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
jobs=$(nproc)
phase_start=$SECONDS
# Prints how long the phase that just ended took, and starts the next one's clock.
phase_done() {
  local took=$((SECONDS - phase_start))
  printf '== %s took %dm %02ds\n' "$1" $((took / 60)) $((took % 60))
  phase_start=$SECONDS
}

# The ground-truth provider tests run Blender and POV-Ray, the metric tests scikit-image, the report
# test Chromium.
bash ci/install-deps.sh validator blender povray skimage chromium slurm
phase_done "installing"

echo "== build (Release, warnings as errors)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DSB_WERROR=ON >/dev/null
cmake --build build -j"$jobs"
phase_done "build"

echo "== tests"
ctest --test-dir build -j"$jobs" --output-on-failure --timeout 900
phase_done "tests"

echo "== sanitizer build (address + undefined): loader and renderer tests"
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug -DSB_SANITIZE=ON -DSB_WERROR=ON -DSB_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-sanitize -j"$jobs" --target sb_loader_tests sb_renderer_tests
phase_done "sanitizer build"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-sanitize -j"$jobs" --output-on-failure -L 'loader|renderer' --timeout 900
phase_done "sanitizer tests"
