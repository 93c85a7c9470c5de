#!/usr/bin/env bash
# Installs the Debian packages animorder needs to build, test and benchmark. Idempotent: packages
# already present are skipped, and apt is only asked when something is missing.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libtbb-dev                               # parallel node scoring
  libcli11-dev nlohmann-json3-dev          # the tool: options, JSON report
  libstb-dev                               # PNG heatmaps
  libgtest-dev libgmock-dev                # tests
  libbenchmark-dev                         # benchmarks
  libmeshoptimizer-dev                     # independent reference in tests and benchmarks
  libegl-dev libopengl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri  # OpenGL reference (llvmpipe)
  libtinygltf-dev                          # reading ../shared/data characters in tests
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}" >&2
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
