#!/usr/bin/env bash
# Installs the Debian (and npm) packages stereobench needs; safe to run again.
#
# Usage: ci/install-deps.sh [GROUP...]
#   core      compilers, libraries and test frameworks needed to build and test (always installed)
#   validator the Khronos glTF validator (npm gltf-validator) used by the scene tests
#   blender   Blender, for the Cycles ground-truth provider
#   povray    POV-Ray, for the POV-Ray ground-truth provider
#   skimage   python3-skimage, the SSIM oracle in the metric tests
#   report    Node.js and the npm package the HTML report bundles (Chart.js; ci/package.json)
#   chromium  headless Chromium, plus the npm packages of the HTML report and its test (Chart.js,
#             playwright-core; pinned in ci/package.json)
#   slurm     slurm-wlm and munge, for the Slurm executor test
#   all       every group above
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(dirname "$here")

core=(cmake make g++ pkg-config git ca-certificates
      libembree-dev libtbb-dev
      libopenimageio-dev openimageio-tools libopenexr-dev
      libopencv-dev libssl-dev
      libtinygltf-dev nlohmann-json3-dev libstb-dev
      libcli11-dev libfmt-dev libtomlplusplus-dev libglm-dev
      libgtest-dev libgmock-dev libbenchmark-dev libxml2-utils)

declare -A group_pkgs=(
  [validator]=""
  [report]=""
  [blender]="blender"
  [povray]="povray"
  [skimage]="python3-skimage python3-numpy"
  [chromium]="chromium fonts-dejavu-core"
  [slurm]="slurm-wlm munge"
)

groups=("$@")
if [[ " ${groups[*]-} " == *" all "* ]]; then
  groups=(validator report blender povray skimage chromium slurm)
fi

pkgs=("${core[@]}")
for g in "${groups[@]}"; do
  [[ -z "$g" ]] && continue
  if [[ -z "${group_pkgs[$g]+x}" ]]; then
    echo "install-deps: unknown group '$g' (known: core ${!group_pkgs[*]} all)" >&2
    exit 3
  fi
  read -r -a extra <<< "${group_pkgs[$g]}"
  pkgs+=("${extra[@]}")
done

# Node.js may come with its own npm (from another Debian-compatible repository);
# only ask Debian for node and npm when either command is absent.
if [[ " ${groups[*]-} " =~ " "(validator|report|chromium)" " ]]; then
  command -v node >/dev/null 2>&1 || pkgs+=(nodejs)
  command -v npm >/dev/null 2>&1 || pkgs+=(npm)
fi

# Only call apt when something is missing, so repeated runs are quick.
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

sudo=""
[[ $(id -u) -ne 0 ]] && sudo="sudo"
if [[ ${#missing[@]} -gt 0 ]]; then
  echo "install-deps: installing ${missing[*]}"
  $sudo apt-get -o DPkg::Lock::Timeout=300 update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get -o DPkg::Lock::Timeout=300 install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# npm packages, pinned in ci/package.json, installed into ci/node_modules: the glTF validator
# (group validator), Chart.js and playwright-core (group chromium; playwright-core drives Debian's
# chromium and never downloads a browser).
npm_needed=()
for g in "${groups[@]}"; do
  case "$g" in
    validator) npm_needed+=(gltf-validator) ;;
    report) npm_needed+=(chart.js) ;;
    chromium) npm_needed+=(chart.js playwright-core) ;;
  esac
done
for m in "${npm_needed[@]}"; do
  if [[ ! -f "$here/node_modules/$m/package.json" ]]; then
    echo "install-deps: installing the npm packages of ci/package.json (${npm_needed[*]})"
    (cd "$here" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error)
    break
  fi
done
echo "install-deps: ok"
