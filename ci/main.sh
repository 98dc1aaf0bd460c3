#!/usr/bin/env bash
# The main job: installs what is needed, builds stereobench, runs the smoke sweep (every registered
# pipeline on a built-in scene against the built-in ground truth), writes its HTML report, runs the
# quality gate and prints the report's path.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
jobs=$(nproc)

bash ci/install-deps.sh report
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
# Only the tool: the tests and benchmarks are built by ci/test.sh.
cmake --build build -j"$jobs" --target stereobench

sb=./build/apps/stereobench
out=out/main
# The smoke sweep (ci/smoke.toml): every registered pipeline on a built-in scene, validated against
# the built-in ground truth (full ray tracing) and timed side by side. It starts afresh each time
# (it takes seconds): resumed, a finished sweep would run nothing, and the gate would judge the
# cells an earlier build measured.
rm -rf "$out"
$sb sweep run ci/smoke.toml --out "$out"
# The HTML report of the sweep (tables, charts, an image viewer per cell), readable offline.
$sb report "$out/results.jsonl" --out "$out/report"
# The quality gate against ci/gate.toml, with a JUnit file for CI systems. A warning (exit 1) is
# reported but does not stop the job; a failure (exit 2) does.
gate=0
$sb gate --config ci/gate.toml --results "$out/results.jsonl" --junit "$out/junit.xml" || gate=$?
echo
echo "report: $root/$out/report/index.html"
[[ $gate -le 1 ]] || exit "$gate"
