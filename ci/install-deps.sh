#!/usr/bin/env bash
# Installs the Debian (and npm) packages stereobench needs; safe to run again.
#
# Usage: ci/install-deps.sh [GROUP...]
#   core      compilers, libraries and test frameworks needed to build and test (always installed)
#   validator the Khronos glTF validator (npm gltf-validator) used by the scene tests
#   blender   Blender, for the Cycles ground-truth provider
#   povray    POV-Ray, for the POV-Ray ground-truth provider
#   skimage   python3-skimage, the SSIM oracle in the metric tests
#   chromium  headless Chromium, for the report test
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
      libgtest-dev libgmock-dev libbenchmark-dev)

declare -A group_pkgs=(
  [validator]=""
  [blender]="blender"
  [povray]="povray"
  [skimage]="python3-skimage python3-numpy"
  [chromium]="chromium fonts-dejavu-core"
  [slurm]="slurm-wlm munge"
)

groups=("$@")
if [[ " ${groups[*]-} " == *" all "* ]]; then
  groups=(validator blender povray skimage chromium slurm)
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
if [[ " ${groups[*]-} " == *" validator "* ]]; then
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
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The glTF validator comes from npm, pinned in ci/package.json, installed into ci/node_modules.
for g in "${groups[@]}"; do
  if [[ "$g" == validator ]]; then
    if [[ ! -x "$here/node_modules/.bin/gltf-validator" && ! -f "$here/node_modules/gltf-validator/package.json" ]]; then
      echo "install-deps: installing gltf-validator from npm"
      (cd "$here" && npm ci --no-audit --no-fund --loglevel=error)
    fi
  fi
done
echo "install-deps: ok"
